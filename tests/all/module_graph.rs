//! No module cycles in any crate of the workspace: for every crate the root `Cargo.toml`
//! names (its `[workspace] members` and the root package), every `crate::`, `super::`,
//! `self::` and child-module path of its `src/` is resolved to the module (the file) that
//! defines what it names, through `pub use` re-exports, and the graph of those references
//! must have no cycle. A module using its own descendants is structure (it declares them and
//! dispatches to them), not a dependency; every other reference counts, a child using its
//! parent's items included. Comments and `#[cfg(test)] mod ... { }` blocks are left out (a
//! unit test may use anything). The root package's binary (`src/main.rs`) is a crate of its
//! own that uses the library by its name: its module is the library's root file's.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// A module path inside the crate (`[]` is the crate root).
type Module = Vec<String>;

/// The module graph of a crate: module -> the modules it refers to.
type Graph = BTreeMap<Module, BTreeSet<Module>>;

/// Every `.rs` file under `src` by module path (`lib.rs`, `main.rs` and `mod.rs` name
/// their folder's module; `src/main.rs` is left out beside a `src/lib.rs`).
fn read_sources(src: &Path) -> BTreeMap<Module, String> {
    fn walk(dir: &Path, prefix: &[String], out: &mut BTreeMap<Module, String>) {
        let mut entries: Vec<_> = std::fs::read_dir(dir)
            .expect("read src dir")
            .map(|e| e.expect("dir entry").path())
            .collect();
        entries.sort();
        for path in entries {
            let name = path
                .file_name()
                .expect("name")
                .to_string_lossy()
                .into_owned();
            let mut module = prefix.to_vec();
            if path.is_dir() {
                module.push(name);
                walk(&path, &module, out);
            } else if let Some(stem) = name.strip_suffix(".rs") {
                if prefix.is_empty() && stem == "main" && dir.join("lib.rs").exists() {
                    continue;
                }
                if !matches!(stem, "lib" | "main" | "mod") {
                    module.push(stem.to_string());
                }
                out.insert(module, std::fs::read_to_string(&path).expect("read source"));
            }
        }
    }
    let mut out = BTreeMap::new();
    walk(src, &[], &mut out);
    out
}

/// The text without comments and without `#[cfg(test)]` inline modules.
fn strip(text: &str) -> String {
    let mut out = String::new();
    let mut in_test_mod = false;
    let mut prev = "";
    for line in text.lines() {
        let code = line.find("//").map_or(line, |i| &line[..i]);
        if !in_test_mod && prev.trim() == "#[cfg(test)]" && code.starts_with("mod ") {
            in_test_mod = code.trim_end().ends_with('{');
        }
        if in_test_mod {
            in_test_mod = line != "}";
        } else {
            out.push_str(code);
            out.push('\n');
        }
        prev = code;
    }
    out
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The paths of the use tree (or plain path) that starts at byte `i` of `t`.
fn tree(t: &str, mut i: usize, prefix: &[String], out: &mut Vec<Vec<String>>) -> usize {
    let skip_ws = |mut i: usize| {
        while t[i..].starts_with(|c: char| c.is_whitespace() || c == ',') {
            i += 1;
        }
        i
    };
    i = skip_ws(i);
    if t[i..].starts_with('{') {
        i += 1;
        loop {
            i = skip_ws(i);
            if i >= t.len() || t[i..].starts_with('}') {
                return (i + 1).min(t.len());
            }
            let next = tree(t, i, prefix, out);
            // A token that is no path (a stray character) is stepped over.
            i = if next == i {
                i + t[i..].chars().next().map_or(1, char::len_utf8)
            } else {
                next
            };
        }
    }
    let len = t[i..]
        .find(|c: char| !is_ident(c) && c != '*')
        .unwrap_or(t.len() - i);
    if len == 0 {
        out.push(prefix.to_vec());
        return i;
    }
    let mut path = prefix.to_vec();
    path.push(t[i..i + len].to_string());
    i += len;
    if t[i..].starts_with("::") {
        return tree(t, i + 2, &path, out);
    }
    out.push(path);
    i
}

/// `path` (as written in module `here`) from the crate root.
fn absolute(path: &[String], here: &[String]) -> Module {
    if path.first().is_some_and(|s| s == "crate") {
        return path[1..].to_vec();
    }
    let mut base = here.to_vec();
    let mut rest = path;
    while let Some(first) = rest.first() {
        match first.as_str() {
            "super" => {
                base.pop();
            }
            "self" => {}
            _ => break,
        }
        rest = &rest[1..];
    }
    base.extend_from_slice(rest);
    base
}

/// The module graph of the sources.
fn graph(sources: &BTreeMap<Module, String>) -> Graph {
    let texts: BTreeMap<&Module, String> = sources.iter().map(|(m, t)| (m, strip(t))).collect();
    let mut refs: BTreeMap<&Module, Vec<Module>> = BTreeMap::new();
    let mut reexports: BTreeMap<&Module, BTreeMap<String, Module>> = BTreeMap::new();
    for (&m, t) in &texts {
        let children: Vec<&str> = sources
            .keys()
            .filter(|k| k.len() == m.len() + 1 && k.starts_with(m))
            .map(|k| k[m.len()].as_str())
            .collect();
        let starts =
            |word: &str| matches!(word, "crate" | "super" | "self") || children.contains(&word);
        let mut found = Vec::new();
        let mut i = 0;
        while let Some(off) = t[i..].find("::") {
            let end = i + off;
            let begin = t[..end]
                .char_indices()
                .rev()
                .find(|&(_, c)| !is_ident(c))
                .map_or(0, |(b, c)| b + c.len_utf8());
            let before = t[..begin].chars().next_back();
            let word = &t[begin..end];
            if !word.is_empty() && before != Some(':') && starts(word) {
                i = tree(t, begin, &[], &mut found);
            } else {
                i = end + 2;
            }
        }
        refs.insert(m, found.iter().map(|p| absolute(p, m)).collect());
        let mut exported = BTreeMap::new();
        for (pos, _) in t.match_indices("use ") {
            let head = t[..pos].trim_end();
            if !(head.ends_with("pub") || head.ends_with(')') && head.contains("pub(")) {
                continue;
            }
            let mut paths = Vec::new();
            tree(t, pos + 4, &[], &mut paths);
            for p in paths {
                if p.first().is_some_and(|w| starts(w)) {
                    let name = p.last().expect("path").clone();
                    exported.insert(name, absolute(&p, m));
                }
            }
        }
        reexports.insert(m, exported);
    }
    fn resolve(
        path: &[String],
        modules: &BTreeSet<&Module>,
        reexports: &BTreeMap<&Module, BTreeMap<String, Module>>,
        depth: usize,
    ) -> Module {
        for k in (0..=path.len()).rev() {
            let prefix = path[..k].to_vec();
            if modules.contains(&prefix) {
                if let Some(target) = path.get(k).and_then(|name| reexports[&prefix].get(name))
                    && depth < 20
                {
                    return resolve(target, modules, reexports, depth + 1);
                }
                return prefix;
            }
        }
        Vec::new()
    }
    let modules: BTreeSet<&Module> = sources.keys().collect();
    let mut g = Graph::new();
    for (&m, paths) in &refs {
        let out = g.entry(m.clone()).or_default();
        for p in paths {
            let target = resolve(p, &modules, &reexports, 0);
            // Itself, or one of its descendants: structure, not a dependency.
            if !target.starts_with(m) && !target.is_empty() {
                out.insert(target);
            }
        }
    }
    g
}

/// The cycles of `g`: its strongly connected components of more than one module (Tarjan),
/// each as sorted module names.
fn cycles(g: &Graph) -> Vec<Vec<String>> {
    struct Tarjan<'a> {
        g: &'a Graph,
        index: BTreeMap<&'a Module, usize>,
        stack: Vec<&'a Module>,
        out: Vec<Vec<String>>,
    }
    impl<'a> Tarjan<'a> {
        /// Visit `v`; its low-link.
        fn visit(&mut self, v: &'a Module) -> usize {
            let g = self.g;
            let n = self.index.len();
            self.index.insert(v, n);
            self.stack.push(v);
            let mut low = n;
            for w in &g[v] {
                low = low.min(match self.index.get(w) {
                    None => self.visit(w),
                    Some(&i) if self.stack.contains(&w) => i,
                    Some(_) => usize::MAX,
                });
            }
            if low == n {
                let at = self.stack.iter().position(|m| *m == v).expect("on stack");
                let scc: Vec<&Module> = self.stack.split_off(at);
                if scc.len() > 1 {
                    let mut names: Vec<String> = scc.iter().map(|m| m.join("::")).collect();
                    names.sort();
                    self.out.push(names);
                }
            }
            low
        }
    }
    let mut t = Tarjan {
        g,
        index: BTreeMap::new(),
        stack: Vec::new(),
        out: Vec::new(),
    };
    for v in g.keys() {
        if !t.index.contains_key(v) {
            t.visit(v);
        }
    }
    t.out
}

/// The `src/` folder of every crate of the workspace: the root package's and each
/// member's, from the root `Cargo.toml`.
fn crate_sources() -> Vec<std::path::PathBuf> {
    let root = Path::new(manifest_dir());
    let text = std::fs::read_to_string(root.join("Cargo.toml")).expect("read Cargo.toml");
    let manifest: toml::Table = text.parse().expect("Cargo.toml parses");
    let members = manifest["workspace"]["members"]
        .as_array()
        .expect("[workspace] members");
    let mut out = vec![root.join("src")];
    out.extend(
        members
            .iter()
            .map(|m| root.join(m.as_str().expect("a member path")).join("src")),
    );
    out
}

#[test]
fn no_module_cycles_in_any_crate() {
    let crates = crate_sources();
    // The root package and every member (planner, sim, gcode, identify, ...).
    assert!(crates.len() >= 5, "{crates:?}");
    let mut report = Vec::new();
    for src in &crates {
        let g = graph(&read_sources(src));
        // Every crate's graph is read: every module is in it, and many refer to others (at
        // least four, or a third of the modules of a crate of fewer than twelve: the
        // file-system crate's seven modules are three that use the others and four leaves).
        let referring = g.values().filter(|t| !t.is_empty()).count();
        assert!(
            g.len() > 5 && referring * 3 >= g.len().min(12),
            "{}: {} modules",
            src.display(),
            g.len()
        );
        for c in cycles(&g) {
            let edges: Vec<String> = c
                .iter()
                .map(|m| {
                    let from: Module = m.split("::").map(str::to_string).collect();
                    let to: Vec<String> = g[&from]
                        .iter()
                        .map(|t| t.join("::"))
                        .filter(|t| c.contains(t))
                        .collect();
                    format!("{m} -> {}", to.join(", "))
                })
                .collect();
            report.push(format!(
                "{}: cycle {{{}}}: {}",
                src.display(),
                c.join(", "),
                edges.join("; ")
            ));
        }
    }
    assert!(report.is_empty(), "{}", report.join("\n"));
}

#[test]
fn the_check_finds_cycles_and_follows_reexports() {
    let m = |s: &str| -> Module {
        s.split("::")
            .filter(|w| !w.is_empty())
            .map(str::to_string)
            .collect()
    };
    let src = |files: &[(&str, &str)]| -> BTreeMap<Module, String> {
        files.iter().map(|(p, t)| (m(p), t.to_string())).collect()
    };
    // a -> b through a nested use tree, b -> a through `super::`: a cycle.
    let g = graph(&src(&[
        ("", "mod a;\nmod b;\npub use a::A;\n"),
        ("a", "use crate::{b::{self, B}};\npub struct A(B);\n"),
        ("b", "pub struct B;\nfn f() -> super::a::A { todo!() }\n"),
    ]));
    assert_eq!(cycles(&g), vec![vec!["a".to_string(), "b".to_string()]]);
    // A facade re-exporting its child's item, used through the facade by a sibling: the
    // sibling depends on the child, not on the facade; the unit-test module and comments
    // are left out.
    let g = graph(&src(&[
        ("", "pub mod p;\n"),
        ("p", "mod q;\nmod r;\npub use q::T;\npub use r::go;\n"),
        ("p::q", "pub struct T;\n// crate::p::r::go()\n"),
        (
            "p::r",
            "use crate::p::T;\npub fn go() -> T { T }\n#[cfg(test)]\nmod tests {\n    use crate::p::go;\n}\n",
        ),
    ]));
    assert!(cycles(&g).is_empty(), "{g:?}");
    assert_eq!(g[&m("p::r")], BTreeSet::from([m("p::q")]));
    assert!(
        g[&m("p")].is_empty(),
        "a module's use of its children is structure"
    );
    assert!(g[&m("p::q")].is_empty());
    // A child using its parent's own item while the parent dispatches to the child: no
    // cycle; two children using each other: a cycle.
    let g = graph(&src(&[
        ("", "mod k;\n"),
        (
            "k",
            "mod a;\nmod b;\npub trait Study {}\npub fn all() { a::A; }\n",
        ),
        ("k::a", "pub struct A;\nimpl super::Study for A {}\n"),
        ("k::b", "use crate::k::a::A;\n"),
    ]));
    assert!(cycles(&g).is_empty(), "{g:?}");
    assert_eq!(g[&m("k::a")], BTreeSet::from([m("k")]));
    let g = graph(&src(&[
        ("", "mod k;\n"),
        ("k", "mod a;\nmod b;\n"),
        ("k::a", "pub struct A;\nfn f() -> super::b::B { todo!() }\n"),
        ("k::b", "pub struct B;\nuse crate::k::a::A;\n"),
    ]));
    assert_eq!(
        cycles(&g),
        vec![vec!["k::a".to_string(), "k::b".to_string()]]
    );
}

/// The package's directory: the `CARGO_MANIFEST_DIR` cargo sets when it runs this
/// binary, else the one it was compiled with. The run-time value is the one that is right
/// when a target directory is shared between clones at different paths: cargo reuses a
/// test binary whose sources are unchanged, with the other clone's path compiled in.
fn manifest_dir() -> &'static str {
    static DIR: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    DIR.get_or_init(|| {
        std::env::var("CARGO_MANIFEST_DIR")
            .unwrap_or_else(|_| env!("CARGO_MANIFEST_DIR").to_owned())
    })
}
