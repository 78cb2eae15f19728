//! Fuzz the scenario parser and sweep expansion: any text must give a scenario or an error
//! naming the file, never a panic.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

/// Expansion is skipped above this many runs (a valid file may ask for millions of runs;
/// building them is not the parser's robustness, only memory).
const MAX_EXPANDED: usize = 10_000;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let path = Path::new("fuzz.toml");
    match settle::input::scenario::parse(text, path) {
        Ok((sc, src)) => {
            if let Ok(axes) = settle::expand::axes(&sc, &src) {
                let runs = axes
                    .iter()
                    .try_fold(1usize, |n, a| n.checked_mul(a.values.len()));
                if runs.is_some_and(|n| n <= MAX_EXPANDED) {
                    let _ = settle::expand::expand(&sc, &src);
                }
            }
        }
        Err(e) => {
            // Every input error names the file.
            assert!(e.to_string().contains("fuzz.toml"), "{e}");
        }
    }
});
