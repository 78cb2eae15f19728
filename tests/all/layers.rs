//! The library's layers (the order in `src/lib.rs`'s documentation): every file of `src/`
//! may import only modules of its own layer and of the layers before it (that no crate's
//! module graph has a cycle is `module_graph`'s check).
//!
//! Read from the source text: every `crate::<path>` (in `use` trees, `{...}` groups
//! included, and in paths in code) and every `super::<path>` escape, comments left out.
//! A path names the deepest module file it reaches (`crate::studies::corner::Corner` ->
//! `studies::corner`). A module using its own descendants is structure (it declares them),
//! not an import; every other edge counts, a child using its parent's items included.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

/// The layers, first to last.
const LAYERS: [&str; 9] = [
    "error",
    "input",
    "spec",
    "measure",
    "studies",
    "expand",
    "execute",
    "output",
    "workflows",
];

fn rs_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .expect("src/ readable")
        .map(|e| e.expect("entry").path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rs_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// `src/a/b.rs` -> `a::b`, `src/a/mod.rs` -> `a`, `src/lib.rs` -> `` (the crate root).
fn module_of(src: &Path, file: &Path) -> String {
    let rel = file.strip_prefix(src).expect("under src");
    let mut parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().into_owned())
        .collect();
    let last = parts.pop().expect("a file");
    let stem = last.trim_end_matches(".rs");
    if stem != "mod" && stem != "lib" {
        parts.push(stem.to_string());
    }
    parts.join("::")
}

/// The text without `//` comments (line and doc comments) and string literals' contents.
fn code(text: &str) -> String {
    let mut out = String::new();
    for line in text.lines() {
        let mut in_str = false;
        let mut prev = ' ';
        let mut kept = String::new();
        let chars: Vec<char> = line.chars().collect();
        let mut i = 0;
        while i < chars.len() {
            let c = chars[i];
            if !in_str && c == '/' && chars.get(i + 1) == Some(&'/') {
                break;
            }
            if c == '"' && prev != '\\' && !(prev == '\'' && chars.get(i + 1) == Some(&'\'')) {
                in_str = !in_str;
            }
            if !in_str {
                kept.push(c);
            }
            prev = if prev == '\\' && c == '\\' { ' ' } else { c };
            i += 1;
        }
        out.push_str(&kept);
        out.push('\n');
    }
    out
}

/// The paths after each `prefix::` in `code`, `{...}` groups expanded
/// (`crate::{a::b, c}` -> `a::b`, `c`).
fn paths_after(code: &str, prefix: &str) -> Vec<String> {
    let mut out = Vec::new();
    let pat = format!("{prefix}::");
    let mut from = 0;
    while let Some(i) = code[from..].find(&pat).map(|i| from + i) {
        from = i + pat.len();
        let before = code[..i].chars().last();
        if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
            continue; // part of a longer path, e.g. the second `super::` of `super::super::`
        }
        expand_tree(&code[from..], "", &mut out);
    }
    out
}

/// Expand the use tree at the start of `s` with `base` before it into `out`.
fn expand_tree(s: &str, base: &str, out: &mut Vec<String>) {
    let s = s.trim_start();
    if let Some(inner) = s.strip_prefix('{') {
        let mut depth = 0;
        let mut start = 0;
        let bytes: Vec<char> = inner.chars().collect();
        for (i, c) in bytes.iter().enumerate() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => {
                    let item: String = bytes[start..i].iter().collect();
                    if !item.trim().is_empty() {
                        expand_tree(&item, base, out);
                    }
                    return;
                }
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    let item: String = bytes[start..i].iter().collect();
                    expand_tree(&item, base, out);
                    start = i + 1;
                }
                _ => {}
            }
        }
        return;
    }
    let ident: String = s
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect();
    let after = &s[ident.len()..];
    let path = if base.is_empty() {
        ident.clone()
    } else if ident.is_empty() {
        base.to_string()
    } else {
        format!("{base}::{ident}")
    };
    match after.strip_prefix("::") {
        Some(next) if next.trim_start().starts_with('*') => out.push(path),
        Some(next) => expand_tree(next, &path, out),
        None => out.push(path),
    }
}

/// The deepest known module that `path` (segments from the crate root) reaches.
fn resolve(path: &str, modules: &BTreeSet<String>) -> Option<String> {
    let segs: Vec<&str> = path.split("::").filter(|s| !s.is_empty()).collect();
    (1..=segs.len())
        .rev()
        .map(|n| segs[..n].join("::"))
        .find(|m| modules.contains(m))
}

fn parent(module: &str) -> String {
    module
        .rsplit_once("::")
        .map_or(String::new(), |(p, _)| p.to_string())
}

fn layer(module: &str) -> Option<usize> {
    let top = module.split("::").next()?;
    LAYERS.iter().position(|l| *l == top)
}

/// An import: `(from, to, how it was written)`.
type Edge = (String, String, String);

/// The modules of the files under `src`, every import edge between them, and the paths
/// that name no module.
fn graph(src: &Path) -> (BTreeSet<String>, Vec<Edge>, Vec<String>) {
    let mut files = Vec::new();
    rs_files(src, &mut files);
    let files: Vec<PathBuf> = files
        .into_iter()
        .filter(|f| f.file_name().is_some_and(|n| n != "main.rs"))
        .collect();
    let modules: BTreeSet<String> = files.iter().map(|f| module_of(src, f)).collect();
    let mut edges = Vec::new();
    let mut unknown = Vec::new();
    for f in &files {
        let from = module_of(src, f);
        if from.is_empty() {
            continue; // the crate root declares the layers and re-exports from them
        }
        let text = code(&std::fs::read_to_string(f).expect("readable"));
        let mut targets: Vec<(String, String)> = paths_after(&text, "crate")
            .into_iter()
            .map(|p| (p.clone(), format!("crate::{p}")))
            .collect();
        for p in paths_after(&text, "super") {
            // `use super::*` in an inline `mod tests` is the file itself.
            if p.is_empty() || p == "*" {
                continue;
            }
            // `super` of a file `a/b.rs` is `a`; of `a/b/mod.rs` (module `a::b`) also `a`.
            let mut base = parent(&from);
            let mut rest = p.as_str();
            while let Some(r) = rest.strip_prefix("super::") {
                base = parent(&base);
                rest = r;
            }
            let full = if base.is_empty() {
                rest.to_string()
            } else {
                format!("{base}::{rest}")
            };
            targets.push((full, format!("super::{p}")));
        }
        for (path, written) in targets {
            match resolve(&path, &modules) {
                Some(to) if to == from || to.starts_with(&format!("{from}::")) => {}
                Some(to) => edges.push((from.clone(), to, written)),
                None => unknown.push(format!("{}: {written}", f.display())),
            }
        }
    }
    (modules, edges, unknown)
}

#[test]
fn every_module_imports_only_earlier_layers() {
    let src = Path::new(crate::support::manifest_dir()).join("src");
    let (modules, edges, unknown) = graph(&src);
    assert!(modules.len() > 20, "{modules:?}");
    let mut problems: Vec<String> = unknown
        .into_iter()
        .map(|u| format!("{u}: no module of the crate (import from the module that defines it)"))
        .collect();
    for m in &modules {
        if !m.is_empty() && layer(m).is_none() {
            problems.push(format!("{m}: in no layer (layers: {})", LAYERS.join(", ")));
        }
    }
    for (from, to, written) in &edges {
        if let (Some(a), Some(b)) = (layer(from), layer(to))
            && b > a
        {
            problems.push(format!(
                "{from} (layer {}) imports {to} (layer {}, later) as `{written}`",
                LAYERS[a], LAYERS[b]
            ));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

#[test]
fn the_checker_sees_groups_escapes_and_later_layers() {
    let code_text = code(
        "use crate::{input::source::Source, studies::{self, Study}};\n\
         // use crate::workflows::sweep;\n\
         let x = \"crate::output\"; use super::super::spec::value::Value;\n",
    );
    let paths = paths_after(&code_text, "crate");
    assert_eq!(
        paths,
        ["input::source::Source", "studies::self", "studies::Study"],
        "comments and strings are not code"
    );
    assert_eq!(
        paths_after(&code_text, "super"),
        ["super::spec::value::Value"]
    );
    let modules: BTreeSet<String> = ["a", "a::b", "c"].map(String::from).into();
    assert_eq!(resolve("a::b::Item", &modules).as_deref(), Some("a::b"));
}
