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
            let path: Vec<String> = base.into_iter().chain(segs).collect();
            // a group (`crate::band::{ResponseTable, spread}`) names each of its items
            let after = &code[start + rest.len()..];
            match after.strip_prefix('{').and_then(group_items) {
                Some(items) => out.extend(items.into_iter().map(|i| path.iter().cloned().chain(i).collect())),
                None => out.push(path),
            }
        }
    }
    out
}

/// The items of a `use` group whose text starts after its `{`: each item's path (`self` left out),
/// up to the group's `}`; None when it does not close.
fn group_items(text: &str) -> Option<Vec<Vec<String>>> {
    let (mut depth, mut end) = (0usize, None);
    for (k, c) in text.char_indices() {
        match c {
            '{' => depth += 1,
            '}' if depth == 0 => {
                end = Some(k);
                break;
            }
            '}' => depth -= 1,
            _ => {}
        }
    }
    let inside = &text[..end?];
    Some(
        inside
            .split(',')
            .map(|item| {
                let head: String = item
                    .trim()
                    .chars()
                    .take_while(|c| c.is_ascii_alphanumeric() || *c == '_' || *c == ':')
                    .collect();
                head.split("::")
                    .filter(|s| !s.is_empty() && *s != "self")
                    .map(String::from)
                    .collect()
            })
            .collect(),
    )
}

/// The circles among modules (module path -> the modules it names): each a list of modules, found by
/// following names between modules of which neither is inside the other.
fn circles(edges: &BTreeMap<Vec<String>, BTreeSet<Vec<String>>>) -> Vec<Vec<String>> {
    let related = |a: &[String], b: &[String]| a.starts_with(b) || b.starts_with(a);
    // a module is on a circle when it reaches itself; each circle reported once, by its members
    let mut found: BTreeSet<Vec<String>> = BTreeSet::new();
    for start in edges.keys() {
        let mut seen = BTreeSet::new();
        let mut stack = vec![(start.clone(), vec![start.join("::")])];
        while let Some((m, path)) = stack.pop() {
            for t in edges.get(&m).into_iter().flatten().filter(|t| !related(&m, t)) {
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

/// Whether a source defines an item `name` (a struct, enum, function, constant, type, trait or module).
fn defines(text: &str, name: &str) -> bool {
    [
        "struct ", "enum ", "fn ", "const ", "static ", "type ", "trait ", "mod ", "union ",
    ]
    .iter()
    .any(|kind| {
        let pat = format!("{kind}{name}");
        text.match_indices(&pat).any(|(k, _)| {
            let before = text[..k].chars().next_back();
            let after = text[k + pat.len()..].chars().next();
            before.is_none_or(|c| !(c.is_alphanumeric() || c == '_'))
                && after.is_none_or(|c| !(c.is_alphanumeric() || c == '_'))
        })
    })
}

/// The sources by module path (comments left out), and the module each named path leads to, through
/// the `pub use` re-exports on the way to the file that defines the item.
struct Modules(BTreeMap<Vec<String>, String>);

impl Modules {
    /// The longest prefix of `path` that is a module.
    fn module_of(&self, path: &[String]) -> Option<Vec<String>> {
        (0..=path.len())
            .rev()
            .map(|k| path[..k].to_vec())
            .find(|p| self.0.contains_key(p))
    }

    /// The module a `pub use` path written in module `m` starts from, joined with the rest of it.
    fn absolute(m: &[String], segs: &[String]) -> Vec<String> {
        match segs.first().map(String::as_str) {
            Some("crate") => segs[1..].to_vec(),
            Some("self") => m.iter().chain(&segs[1..]).cloned().collect(),
            Some("super") => {
                let mut base = m.to_vec();
                let mut rest = segs;
                while rest.first().is_some_and(|s| s == "super") {
                    base.pop();
                    rest = &rest[1..];
                }
                base.into_iter().chain(rest.iter().cloned()).collect()
            }
            _ => m.iter().chain(segs).cloned().collect(),
        }
    }

    /// The module that defines `name` as module `m` exports it.
    fn follow(&self, m: Vec<String>, name: &str, depth: usize) -> Vec<String> {
        let text = &self.0[&m];
        if depth > 8 || defines(text, name) {
            return m;
        }
        for stmt in text.split("pub use ").skip(1).filter_map(|s| s.split(';').next()) {
            let stmt: String = stmt.split_whitespace().collect::<Vec<_>>().join(" ");
            let (path, items) = match stmt.split_once("::{") {
                Some((p, list)) => (p.to_string(), list.trim_end_matches('}').to_string()),
                None => match stmt.rsplit_once("::") {
                    Some((p, item)) => (p.to_string(), item.to_string()),
                    None => continue,
                },
            };
            let segs: Vec<String> = path.split("::").map(String::from).collect();
            let Some(from) = self.module_of(&Self::absolute(&m, &segs)) else {
                continue;
            };
            let names: Vec<&str> = items
                .split(',')
                .map(|i| i.split(" as ").next().unwrap_or("").trim())
                .collect();
            let exported = names.contains(&name) || (names.contains(&"*") && defines(&self.0[&from], name));
            if exported && from != m {
                return self.follow(from, name, depth + 1);
            }
        }
        m
    }

    /// The module a named path (from the crate's root) leads to.
    fn resolve(&self, path: &[String]) -> Option<Vec<String>> {
        let m = self.module_of(path)?;
        match path.get(m.len()) {
            Some(name) => Some(self.follow(m, name, 0)),
            None => Some(m),
        }
    }
}

/// The module graph of a set of sources (path under `src/`, text): the modules each names.
fn graph(sources: &[(PathBuf, String)]) -> BTreeMap<Vec<String>, BTreeSet<Vec<String>>> {
    let strip = |text: &str| -> String {
        text.lines()
            .map(|l| l.split("//").next().unwrap_or(""))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let modules = Modules(
        sources
            .iter()
            .map(|(rel, text)| (module_path(rel), strip(text)))
            .collect(),
    );
    sources
        .iter()
        .map(|(rel, _)| {
            let m = module_path(rel);
            let is_bin = rel.starts_with("cli") || rel == Path::new("main.rs");
            let named = named_modules(&modules.0[&m], &m, is_bin)
                .iter()
                .filter_map(|p| modules.resolve(p))
                .filter(|t| !t.is_empty() && *t != m)
                .collect();
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
    // through a parent's re-export: a names b's item by its folder, b names a
    let through = [
        src("a.rs", "use crate::b::Z;"),
        src("b/mod.rs", "mod z;\npub use z::*;"),
        src("b/z.rs", "pub struct Z;\nfn f() { crate::a::g(); }"),
    ];
    assert_eq!(
        circles(&graph(&through)),
        vec![vec!["a".to_string(), "b::z".to_string()]]
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
