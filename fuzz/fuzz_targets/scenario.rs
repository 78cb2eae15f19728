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
    match settle::expand::parse(text, path) {
        Ok((sc, src)) => {
            if settle::expand::sweep_of(&sc, &src).is_ok_and(|s| s.total <= MAX_EXPANDED) {
                let _ = settle::expand::expand(&sc, &src);
            }
        }
        Err(e) => {
            // Every input error names the file.
            assert!(e.to_string().contains("fuzz.toml"), "{e}");
        }
    }
});
