//! The functional core stays pure: no async runtime, IPC, files, network or clocks in the numeric
//! modules (ARCHITECTURE.md, "Invariants"). A tidy test in the rust-analyzer manner, on a parse of the
//! source (syn), not its text: every `use` tree is expanded (`use std::{fs, io};` names `std::fs`),
//! every path in the code is checked whether or not a `use` brought it in
//! (`std::time::Instant::now()`), the bodies of macros called like functions (`format!`, `assert!`,
//! `vec!`) included, and a name bound to a part of a forbidden path (`use std as s;`) is followed.

use crate::util::repo;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use syn::punctuated::Punctuated;
use syn::visit::Visit;

/// The shell: the only sources that may name the forbidden crates and modules. Everything else under
/// `src/` is the functional core.
const SHELL: &[&str] = &["src/shell", "src/cli", "src/main.rs", "src/lib.rs"];

/// Forbidden paths: a path that starts with one of these (after `::` and `use` renames) is a violation.
const FORBIDDEN: &[&[&str]] = &[
    &["tokio"],
    &["iceoryx2"],
    &["crossterm"],
    &["zenoh"],
    &["sd_notify"],
    &["nix"],
    &["mcap"],
    &["config"],
    &["tracing_subscriber"],
    &["std", "fs"],
    &["std", "net"],
    &["std", "time"],
    &["std", "env"],
    &["std", "process"],
    &["std", "thread"],
    // the shell itself: the core names none of it (nor what it re-exports)
    &["crate", "shell"],
];

/// Names forbidden anywhere in a path, however they were brought in.
const FORBIDDEN_NAMES: &[&str] = &["Instant", "SystemTime", "File"];

fn rust_files(p: &Path, out: &mut Vec<PathBuf>) {
    if p.is_file() && p.extension().is_some_and(|e| e == "rs") {
        out.push(p.to_path_buf());
    } else if p.is_dir() {
        for e in std::fs::read_dir(p).unwrap() {
            rust_files(&e.unwrap().path(), out);
        }
    }
}

/// The paths a source names, and the forbidden ones.
#[derive(Default)]
struct Scan {
    /// Local names bound by `use` to a part of a forbidden path (`use std as s;`): name -> full path.
    aliases: HashMap<String, Vec<String>>,
    violations: Vec<String>,
}

/// `path` starts with `prefix`.
fn starts_with(path: &[String], prefix: &[&str]) -> bool {
    path.len() >= prefix.len() && path.iter().zip(prefix).all(|(a, b)| a == b)
}

/// `path` is a part of a forbidden path, not a whole one (`std`).
fn leads_to_forbidden(path: &[String]) -> bool {
    FORBIDDEN
        .iter()
        .any(|f| path.len() < f.len() && path.iter().zip(f.iter()).all(|(a, b)| a == b))
}

impl Scan {
    fn check(&mut self, mut path: Vec<String>) {
        if path.first().is_some_and(|h| h.is_empty()) {
            path.remove(0); // `::tokio`
        }
        if let Some(full) = path.first().and_then(|h| self.aliases.get(h)) {
            path.splice(0..1, full.clone());
        }
        let bad_prefix = FORBIDDEN.iter().any(|f| starts_with(&path, f));
        let bad_name = path.iter().any(|s| FORBIDDEN_NAMES.contains(&s.as_str()));
        if bad_prefix || bad_name {
            self.violations.push(path.join("::"));
        }
    }

    /// Expands a `use` tree below `prefix`.
    fn use_tree(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(prefix, &p.tree);
                prefix.pop();
            }
            syn::UseTree::Name(n) => {
                let mut full = prefix.clone();
                if n.ident != "self" {
                    full.push(n.ident.to_string());
                }
                self.check(full);
            }
            syn::UseTree::Rename(r) => {
                let mut full = prefix.clone();
                if r.ident != "self" {
                    full.push(r.ident.to_string());
                }
                if leads_to_forbidden(&full) {
                    self.aliases.insert(r.rename.to_string(), full.clone());
                }
                self.check(full);
            }
            syn::UseTree::Glob(_) => {
                // a glob of a forbidden path's parent brings the forbidden module in
                if leads_to_forbidden(prefix) {
                    self.violations.push(format!("{}::*", prefix.join("::")));
                } else {
                    self.check(prefix.clone());
                }
            }
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(prefix, t);
                }
            }
        }
    }
}

/// A macro body's leading expression, the rest skipped (`vec![x; n]`, `matches!(v, pattern)`).
fn leading_expr(input: syn::parse::ParseStream) -> syn::Result<syn::Expr> {
    let e: syn::Expr = input.parse()?;
    input.step(|cursor| {
        let mut c = *cursor;
        while let Some((_, next)) = c.token_tree() {
            c = next;
        }
        Ok(((), c))
    })?;
    Ok(e)
}

impl<'ast> Visit<'ast> for Scan {
    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        let mut prefix = vec![];
        if u.leading_colon.is_some() {
            prefix.push(String::new());
        }
        self.use_tree(&mut prefix, &u.tree);
    }

    fn visit_item_extern_crate(&mut self, e: &'ast syn::ItemExternCrate) {
        self.check(vec![e.ident.to_string()]);
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        let mut segments: Vec<String> = p.segments.iter().map(|s| s.ident.to_string()).collect();
        if p.leading_colon.is_some() {
            segments.insert(0, String::new());
        }
        self.check(segments);
        syn::visit::visit_path(self, p);
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        // the arguments of function-like macros are expressions (format strings, values, `x = y`)
        if let Ok(args) = m.parse_body_with(Punctuated::<syn::Expr, syn::Token![,]>::parse_terminated) {
            for a in &args {
                self.visit_expr(a);
            }
        } else if let Ok(e) = m.parse_body_with(leading_expr) {
            self.visit_expr(&e);
        }
        syn::visit::visit_macro(self, m);
    }
}

/// Forbidden paths in a source text.
fn violations(text: &str) -> Result<Vec<String>, syn::Error> {
    let file = syn::parse_file(text)?;
    let mut scan = Scan::default();
    scan.visit_file(&file);
    Ok(scan.violations)
}

#[test]
fn the_scanner_finds_what_it_looks_for() {
    let found = |src: &str| violations(src).unwrap();
    assert_eq!(found("use std::{fs, io};"), vec!["std::fs".to_string()]);
    assert_eq!(found("use std::{io::{self, Write}, time::Instant};").len(), 1);
    assert!(found("// tokio in a comment is fine\nuse std::io::Write;").is_empty());
    assert!(found("fn f() { let _ = \"std::fs in a string\"; }").is_empty());
    assert!(!found("fn f() { let _ = std::fs::read(\"x\"); }").is_empty());
    assert!(!found("fn f() { println!(\"{:?}\", std::time::Instant::now()); }").is_empty());
    assert!(!found("fn f() { let v = vec![std::env::args(); 2]; }").is_empty());
    assert!(!found("use std::*;").is_empty());
    assert!(!found("use std as s;\nfn f() { s::fs::read(\"x\").ok(); }").is_empty());
    assert!(!found("use ::tokio::spawn;").is_empty());
    assert!(!found("extern crate iceoryx2;").is_empty());
    assert!(found("use std::io;\nfn f() -> io::Result<()> { Ok(()) }").is_empty());
    // the shell, and what it re-exports (`ipc::wire` re-exports the engine's messages, `config` the
    // settings)
    assert!(!found("use crate::shell::ipc::wire::ForecastHeader;").is_empty());
    assert!(!found("fn f() { let _ = crate::shell::daemon::wall_s(); }").is_empty());
    assert!(!found("use crate::shell::config::ShipcastConfig;").is_empty());
    assert!(!found("use crate::{rom, shell};").is_empty());
    assert!(found("use crate::settings::ShipcastConfig;").is_empty());
    assert!(found("use crate::engine::message::ForecastHeader;").is_empty());
}

#[test]
fn core_modules_do_no_io_and_read_no_clock() {
    let mut all = vec![];
    rust_files(&repo("src"), &mut all);
    let shell: Vec<PathBuf> = SHELL.iter().map(|s| repo(s)).collect();
    let files: Vec<PathBuf> = all
        .into_iter()
        .filter(|f| !shell.iter().any(|s| f.starts_with(s)))
        .collect();
    assert!(files.len() >= 40, "the core was found: {files:?}");
    let mut bad = vec![];
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        match violations(&text) {
            Ok(v) => bad.extend(v.into_iter().map(|what| format!("{}: `{what}`", f.display()))),
            Err(e) => bad.push(format!("{}: not parsed: {e}", f.display())),
        }
    }
    assert!(
        bad.is_empty(),
        "the functional core must stay pure:\n{}",
        bad.join("\n")
    );
}
