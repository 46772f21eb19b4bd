//! House rules that keep the code readable, checked on the source text: no function in `src/` runs
//! past [`MAX_FUNCTION_LINES`] lines (ARCHITECTURE.md, "Invariants"). The folder rule (the core names
//! no shell module and no forbidden crate) is `core_purity`.

use crate::util::repo;
use std::path::{Path, PathBuf};

/// The longest a function may be, lines from its `fn` line to its closing brace: the aim is 100; past
/// this a function has outgrown one concern and this test fails.
const MAX_FUNCTION_LINES: usize = 120;

fn rust_files(p: &Path, out: &mut Vec<PathBuf>) {
    if p.is_file() && p.extension().is_some_and(|e| e == "rs") {
        out.push(p.to_path_buf());
    } else if p.is_dir() {
        let mut entries: Vec<_> = std::fs::read_dir(p).unwrap().map(|e| e.unwrap().path()).collect();
        entries.sort();
        for e in entries {
            rust_files(&e, out);
        }
    }
}

/// The name of the function a line opens (`pub(crate) async fn name(`), if it opens one with a body.
fn opens_function(line: &str) -> Option<(&str, &str)> {
    let indent = &line[..line.len() - line.trim_start().len()];
    let mut rest = line.trim_start();
    for word in [
        "pub(crate) ",
        "pub(super) ",
        "pub ",
        "const ",
        "async ",
        "unsafe ",
        "extern \"C\" ",
    ] {
        rest = rest.strip_prefix(word).unwrap_or(rest);
    }
    for word in ["const ", "async ", "unsafe "] {
        rest = rest.strip_prefix(word).unwrap_or(rest);
    }
    let rest = rest.strip_prefix("fn ")?;
    if line.trim_end().ends_with(';') {
        return None; // a trait's declaration
    }
    let end = rest
        .find(|c: char| !(c.is_alphanumeric() || c == '_'))
        .unwrap_or(rest.len());
    Some((indent, &rest[..end]))
}

/// Functions of a source text longer than `max` lines: (name, first line 1-based, lines). A function
/// ends at the first line after its `fn` line that is its indentation followed by `}` (rustfmt's
/// layout).
fn long_functions(text: &str, max: usize) -> Vec<(String, usize, usize)> {
    let lines: Vec<&str> = text.lines().collect();
    let mut long = vec![];
    for (i, line) in lines.iter().enumerate() {
        let Some((indent, name)) = opens_function(line) else {
            continue;
        };
        let close = format!("{indent}}}");
        if line.trim_end().ends_with('}') {
            continue; // a one-line function
        }
        if let Some(j) = (i + 1..lines.len()).find(|&j| lines[j].trim_end() == close) {
            let n = j - i + 1;
            if n > max {
                long.push((name.to_string(), i + 1, n));
            }
        }
    }
    long
}

#[test]
fn the_length_check_finds_a_long_function() {
    let body = |n: usize| (0..n).map(|k| format!("    let _x{k} = {k};\n")).collect::<String>();
    let long = format!("pub fn long() {{\n{}}}\n\nfn short() {{\n{}}}\n", body(128), body(3));
    assert_eq!(
        long_functions(&long, MAX_FUNCTION_LINES),
        vec![("long".to_string(), 1, 130)]
    );
    let method = format!(
        "impl X {{\n    pub(crate) async fn m(&self) {{\n    {}    }}\n}}\n",
        body(125)
    );
    assert_eq!(long_functions(&method, MAX_FUNCTION_LINES).len(), 1);
    let fine = format!("fn f() {{\n{}}}\n", body(MAX_FUNCTION_LINES - 2));
    assert!(long_functions(&fine, MAX_FUNCTION_LINES).is_empty());
    assert!(long_functions("trait T {\n    fn f(&self);\n}\n", MAX_FUNCTION_LINES).is_empty());
}

#[test]
fn no_function_in_src_is_longer_than_the_limit() {
    let mut files = vec![];
    rust_files(&repo("src"), &mut files);
    assert!(files.len() > 20, "the sources were found: {}", files.len());
    let mut bad = vec![];
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        for (name, line, n) in long_functions(&text, MAX_FUNCTION_LINES) {
            bad.push(format!("{}:{line} `{name}`: {n} lines", f.display()));
        }
    }
    assert!(
        bad.is_empty(),
        "functions longer than {MAX_FUNCTION_LINES} lines (split them by concern):\n{}",
        bad.join("\n")
    );
}
