//! Map between TOML key paths and line numbers, for error messages that name the file,
//! line and key. Works on the raw text so that it also serves values that parsed fine but
//! failed validation (a negative limit, an unknown profile kind).

/// One `key = value` line of a TOML document.
#[derive(Debug, Clone, PartialEq)]
struct KeyLine {
    /// Full dotted path (table header + key).
    path: String,
    /// 1-based line number.
    line: usize,
    /// 1-based column of the key.
    column: usize,
}

/// An index of the keys of a TOML text, by line.
#[derive(Debug, Clone)]
pub struct KeyIndex {
    keys: Vec<KeyLine>,
    line_starts: Vec<usize>,
}

fn unquote(s: &str) -> String {
    let s = s.trim();
    if s.len() >= 2
        && ((s.starts_with('"') && s.ends_with('"')) || (s.starts_with('\'') && s.ends_with('\'')))
    {
        s[1..s.len() - 1].to_string()
    } else {
        s.to_string()
    }
}

/// Split a dotted key into parts, keeping quoted parts (which may contain dots) whole.
fn key_parts(s: &str) -> Vec<String> {
    let mut parts = Vec::new();
    let mut cur = String::new();
    let mut quote: Option<char> = None;
    for c in s.chars() {
        match (quote, c) {
            (None, '"' | '\'') => {
                quote = Some(c);
                cur.push(c);
            }
            (Some(q), c) if c == q => {
                quote = None;
                cur.push(c);
            }
            (None, '.') => parts.push(unquote(&std::mem::take(&mut cur))),
            _ => cur.push(c),
        }
    }
    parts.push(unquote(&cur));
    parts
}

impl KeyIndex {
    /// Index `text`.
    pub fn new(text: &str) -> Self {
        let mut keys = Vec::new();
        let mut table = String::new();
        let mut line_starts = vec![0];
        for (i, b) in text.bytes().enumerate() {
            if b == b'\n' {
                line_starts.push(i + 1);
            }
        }
        for (n, raw) in text.lines().enumerate() {
            let trimmed = raw.trim_start();
            let indent = raw.len() - trimmed.len();
            if trimmed.starts_with('#') || trimmed.is_empty() {
                continue;
            }
            if let Some(rest) = trimmed.strip_prefix('[') {
                let inner = rest.trim_start_matches('[');
                if let Some(end) = inner.find(']') {
                    table = key_parts(&inner[..end]).join(".");
                    keys.push(KeyLine {
                        path: table.clone(),
                        line: n + 1,
                        column: indent + 1,
                    });
                    continue;
                }
            }
            if let Some(eq) = find_eq(trimmed) {
                let key = key_parts(trimmed[..eq].trim()).join(".");
                let path = if table.is_empty() {
                    key
                } else {
                    format!("{table}.{key}")
                };
                keys.push(KeyLine {
                    path,
                    line: n + 1,
                    column: indent + 1,
                });
            }
        }
        Self { keys, line_starts }
    }

    /// Line and column (1-based) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let line = self.line_starts.partition_point(|&s| s <= offset);
        let start = self.line_starts[line.saturating_sub(1)];
        (line.max(1), offset - start + 1)
    }

    /// The line and column where `path` is set, or failing that its closest parent.
    pub fn find(&self, path: &str) -> Option<(usize, usize)> {
        let mut p = path;
        loop {
            if let Some(k) = self.keys.iter().find(|k| k.path == p) {
                return Some((k.line, k.column));
            }
            p = &p[..p.rfind('.')?];
        }
    }

    /// The table (dotted path, empty for the top level) whose header is the last at or
    /// before byte `offset` of `text`: where a value spanning from `offset` belongs.
    pub fn table_at(&self, offset: usize, text: &str) -> String {
        let (line, _) = self.line_col(offset);
        let header = |l: usize| {
            text.lines()
                .nth(l - 1)
                .is_some_and(|t| t.trim_start().starts_with('['))
        };
        self.keys
            .iter()
            .rev()
            .find(|k| k.line <= line && header(k.line))
            .map_or_else(String::new, |k| k.path.clone())
    }

    /// The key set on `line` (1-based), if that line holds one.
    pub fn key_at_line(&self, line: usize) -> Option<&str> {
        self.keys
            .iter()
            .rev()
            .find(|k| k.line <= line)
            .map(|k| k.path.as_str())
    }
}

/// Position of the `=` of a `key = value` line, skipping quoted keys.
fn find_eq(s: &str) -> Option<usize> {
    let mut quote: Option<char> = None;
    for (i, c) in s.char_indices() {
        match (quote, c) {
            (None, '"' | '\'') => quote = Some(c),
            (Some(q), c) if c == q => quote = None,
            (None, '=') => return Some(i),
            (None, '[' | '{') => return None,
            _ => {}
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_keys_in_tables_and_quoted_keys() {
        let text = "name = \"x\"\n\n[limits]\nvmax_mm_s = 1\n  amax_mm_s2 = 2\n[sweep]\n\"move.distance_mm\" = [1, 2]\n";
        let idx = KeyIndex::new(text);
        assert_eq!(idx.find("name"), Some((1, 1)));
        assert_eq!(idx.find("limits.vmax_mm_s"), Some((4, 1)));
        assert_eq!(idx.find("limits.amax_mm_s2"), Some((5, 3)));
        assert_eq!(idx.find("sweep.move.distance_mm"), Some((7, 1)));
        assert_eq!(idx.key_at_line(5), Some("limits.amax_mm_s2"));
        assert_eq!(idx.line_col(text.find("amax").expect("present")), (5, 3));
    }
}
