//! File-name wildcards as Klipper's `[include ...]` expands them: Python's `glob.glob`
//! (non-recursive) with `fnmatch` patterns, case-sensitive as on Linux: `*` any run of
//! characters, `?` one character, `[abc]`, `[a-z]`, `[!a-z]` one character of (not of)
//! a set, an unclosed `[` itself. Wildcards may stand in any path component; names
//! starting with `.` match only a pattern starting with `.`. The caller sorts the result
//! (Klipper does, `klippy/configfile.py` `_resolve_include`).

use std::path::{Component, Path, PathBuf};

/// Whether `text` holds a wildcard (Python's `glob.has_magic`).
pub(crate) fn has_magic(text: &str) -> bool {
    text.contains(['*', '?', '['])
}

/// The existing paths matching `pattern` (unsorted). A pattern without wildcards gives
/// itself if it exists.
pub(crate) fn glob(pattern: &Path) -> Vec<PathBuf> {
    let parts: Vec<Component> = pattern.components().collect();
    let mut current = vec![PathBuf::new()];
    for (i, part) in parts.iter().enumerate() {
        let last = i + 1 == parts.len();
        let text = part.as_os_str().to_string_lossy();
        let mut next = Vec::new();
        for prefix in &current {
            if !matches!(part, Component::Normal(_)) || !has_magic(&text) {
                let p = prefix.join(part.as_os_str());
                if std::fs::symlink_metadata(&p).is_ok() {
                    next.push(p);
                }
                continue;
            }
            let dir = if prefix.as_os_str().is_empty() {
                Path::new(".")
            } else {
                prefix.as_path()
            };
            let Ok(entries) = std::fs::read_dir(dir) else {
                continue;
            };
            let pat: Vec<char> = text.chars().collect();
            for entry in entries.flatten() {
                let name = entry.file_name();
                let Some(name) = name.to_str() else { continue };
                if name.starts_with('.') && !text.starts_with('.') {
                    continue;
                }
                let chars: Vec<char> = name.chars().collect();
                if !fnmatch(&chars, &pat) {
                    continue;
                }
                let p = prefix.join(name);
                if last || p.is_dir() {
                    next.push(p);
                }
            }
        }
        current = next;
    }
    current
}

/// A `[...]` set at the start of `pat` (after the `[`): its content and the rest of the
/// pattern, or `None` when it is not closed.
fn class(pat: &[char]) -> Option<(&[char], &[char])> {
    let mut j = 0;
    if pat.first() == Some(&'!') {
        j += 1;
    }
    if pat.get(j) == Some(&']') {
        j += 1;
    }
    let close = j + pat[j.min(pat.len())..].iter().position(|&c| c == ']')?;
    Some((&pat[..close], &pat[close + 1..]))
}

fn in_class(set: &[char], c: char) -> bool {
    let (negate, set) = match set.split_first() {
        Some(('!', rest)) => (true, rest),
        _ => (false, set),
    };
    let mut i = 0;
    let mut found = false;
    while i < set.len() {
        if i + 2 < set.len() && set[i + 1] == '-' {
            found |= (set[i]..=set[i + 2]).contains(&c);
            i += 3;
        } else {
            found |= set[i] == c;
            i += 1;
        }
    }
    found != negate
}

/// Python's `fnmatch.fnmatchcase`.
pub(crate) fn fnmatch(name: &[char], pat: &[char]) -> bool {
    match pat.split_first() {
        None => name.is_empty(),
        Some(('*', rest)) => (0..=name.len()).any(|i| fnmatch(&name[i..], rest)),
        Some(('?', rest)) => !name.is_empty() && fnmatch(&name[1..], rest),
        Some(('[', rest)) => match class(rest) {
            Some((set, after)) => {
                name.first().is_some_and(|&c| in_class(set, c)) && fnmatch(&name[1..], after)
            }
            None => name.first() == Some(&'[') && fnmatch(&name[1..], rest),
        },
        Some((c, rest)) => name.first() == Some(c) && fnmatch(&name[1..], rest),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn m(name: &str, pat: &str) -> bool {
        let n: Vec<char> = name.chars().collect();
        let p: Vec<char> = pat.chars().collect();
        fnmatch(&n, &p)
    }

    #[test]
    fn fnmatch_patterns() {
        assert!(m("macros.cfg", "*.cfg"));
        assert!(!m("macros.cfg.bak", "*.cfg"));
        assert!(m("a1.cfg", "a?.cfg"));
        assert!(m("b.cfg", "[abc].cfg") && !m("d.cfg", "[abc].cfg"));
        assert!(m("q.cfg", "[a-z].cfg") && !m("Q.cfg", "[a-z].cfg"));
        assert!(m("Q.cfg", "[!a-z].cfg") && !m("q.cfg", "[!a-z].cfg"));
        assert!(m("].cfg", "[]].cfg"));
        assert!(m("[x", "[x") && !m("x", "[x"));
        assert!(m("", "*") && !m("", "?"));
    }

    #[test]
    fn globs_in_directories() {
        let dir = tempfile::tempdir().expect("temp dir");
        let d = dir.path();
        for f in [
            "conf/b.cfg",
            "conf/a.cfg",
            "conf/.hidden.cfg",
            "conf/x.txt",
            "more/c.cfg",
        ] {
            let p = d.join(f);
            std::fs::create_dir_all(p.parent().expect("has parent")).expect("mkdir");
            std::fs::write(p, "").expect("write");
        }
        let mut got = glob(&d.join("conf/*.cfg"));
        got.sort();
        assert_eq!(got, [d.join("conf/a.cfg"), d.join("conf/b.cfg")]);
        let mut got = glob(&d.join("*/[bc].cfg"));
        got.sort();
        assert_eq!(got, [d.join("conf/b.cfg"), d.join("more/c.cfg")]);
        assert_eq!(glob(&d.join("conf/.h*")), [d.join("conf/.hidden.cfg")]);
        assert_eq!(glob(&d.join("conf/a.cfg")), [d.join("conf/a.cfg")]);
        assert!(glob(&d.join("conf/none.cfg")).is_empty());
        assert!(glob(&d.join("none/*.cfg")).is_empty());
    }
}
