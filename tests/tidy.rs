//! House rules that keep the code readable, checked on the source text (ARCHITECTURE.md,
//! "Invariants"): no function in `src/` runs past [`MAX_FUNCTION_LINES`] lines, and no two files name
//! each other, directly or round a circle (a module and the files of its own folder aside: a parent
//! re-exports its children, and they use its items). The folder rule (the core names no shell module
//! and no forbidden crate) is `core_purity`.

use crate::util::repo;
use std::collections::{BTreeMap, BTreeSet};
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

/// A source's module path from its path under `src/` (`engine/mod.rs` and `engine.rs` are `engine`;
/// `lib.rs` is the library's root; the binary's root `main.rs` is `main`, its `cli` module under
/// `src/cli`).
fn module_path(rel: &Path) -> Vec<String> {
    let mut parts: Vec<String> = rel
        .with_extension("")
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    if parts.last().is_some_and(|p| p == "mod") {
        parts.pop();
    }
    if parts == ["lib"] {
        parts.clear();
    }
    parts
}

/// The modules a source names by `crate::`, `shipcast::` or `super::` paths (comments left out), as
/// module paths; `is_bin`: a file of the binary, where `shipcast::` is the library.
fn named_modules(text: &str, module: &[String], is_bin: bool) -> Vec<Vec<String>> {
    let code: String = text
        .lines()
        .map(|l| l.split("//").next().unwrap_or(""))
        .collect::<Vec<_>>()
        .join("\n");
    let mut out = vec![];
    let bytes = code.as_bytes();
    for head in ["crate::", "shipcast::", "super::"] {
        let mut from = 0;
        while let Some(k) = code[from..].find(head) {
            let start = from + k;
            from = start + head.len();
            let boundary = start == 0
                || !(bytes[start - 1].is_ascii_alphanumeric() || bytes[start - 1] == b'_' || bytes[start - 1] == b':');
            if !boundary || (head == "shipcast::" && !is_bin) {
                continue;
            }
            let rest: String = code[start..]
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == ':')
                .collect();
            let mut segs: Vec<String> = rest.split("::").filter(|s| !s.is_empty()).map(String::from).collect();
            let base: Vec<String> = match segs.first().map(String::as_str) {
                Some("super") => {
                    let mut b = module.to_vec();
                    while segs.first().is_some_and(|s| s == "super") {
                        segs.remove(0);
                        b.pop();
                    }
                    b
                }
                _ => {
                    segs.remove(0);
                    vec![]
                }
            };
            out.push(base.into_iter().chain(segs).collect());
        }
    }
    out
}

/// The circles among `files` (module path -> the module paths it names): each a list of modules,
/// found by following names between modules of which neither is inside the other.
fn circles(files: &BTreeMap<Vec<String>, Vec<Vec<String>>>) -> Vec<Vec<String>> {
    let file_of = |path: &[String]| -> Option<Vec<String>> {
        (1..=path.len())
            .rev()
            .map(|k| path[..k].to_vec())
            .find(|p| files.contains_key(p))
    };
    let related = |a: &[String], b: &[String]| a.starts_with(b) || b.starts_with(a);
    let mut edges: BTreeMap<Vec<String>, BTreeSet<Vec<String>>> = BTreeMap::new();
    for (m, named) in files {
        let to = named
            .iter()
            .filter_map(|n| file_of(n))
            .filter(|t| !related(m, t))
            .collect();
        edges.insert(m.clone(), to);
    }
    // a module is on a circle when it reaches itself; each circle reported once, by its members
    let mut found: BTreeSet<Vec<String>> = BTreeSet::new();
    for start in edges.keys() {
        let mut seen = BTreeSet::new();
        let mut stack = vec![(start.clone(), vec![start.join("::")])];
        while let Some((m, path)) = stack.pop() {
            for t in edges.get(&m).into_iter().flatten() {
                if t == start {
                    let mut members = path.clone();
                    members.sort();
                    found.insert(members);
                } else if seen.insert(t.clone()) {
                    let mut p = path.clone();
                    p.push(t.join("::"));
                    stack.push((t.clone(), p));
                }
            }
        }
    }
    found.into_iter().collect()
}

/// The module graph of a set of sources (path under `src/`, text).
fn graph(sources: &[(PathBuf, String)]) -> BTreeMap<Vec<String>, Vec<Vec<String>>> {
    sources
        .iter()
        .map(|(rel, text)| {
            let m = module_path(rel);
            let is_bin = rel.starts_with("cli") || rel == Path::new("main.rs");
            let named = named_modules(text, &m, is_bin);
            (m, named)
        })
        .collect()
}

#[test]
fn the_circle_check_finds_two_files_that_name_each_other() {
    let src = |p: &str, t: &str| (PathBuf::from(p), t.to_string());
    let two = [
        src("a/mod.rs", "pub mod x;\npub mod y;\npub use x::X;"),
        src(
            "a/x.rs",
            "use super::*;\nuse crate::a::y::Y; // crate::b::z in a comment",
        ),
        src("a/y.rs", "pub struct Y;\nfn f() { let _ = super::x::g(); }"),
        src("b/z.rs", "use crate::a::X;"),
    ];
    assert_eq!(
        circles(&graph(&two)),
        vec![vec!["a::x".to_string(), "a::y".to_string()]]
    );
    // a parent and its children name each other freely; a one-way name is no circle
    let none = [
        src("a/mod.rs", "pub use x::X;"),
        src("a/x.rs", "use super::*; use crate::b::Z;"),
        src("b.rs", ""),
    ];
    assert!(circles(&graph(&none)).is_empty());
}

#[test]
fn no_two_files_in_src_name_each_other() {
    let mut files = vec![];
    let root = repo("src");
    rust_files(&root, &mut files);
    let sources: Vec<(PathBuf, String)> = files
        .iter()
        .map(|f| {
            (
                f.strip_prefix(&root).unwrap().to_path_buf(),
                std::fs::read_to_string(f).unwrap(),
            )
        })
        .collect();
    let found = circles(&graph(&sources));
    assert!(
        found.is_empty(),
        "modules that name each other round a circle: {found:?}"
    );
}
