//! Fuzz `settle plan`'s input: every line (UTF-8 or not) gets exactly one JSON answer (a
//! profile or an error), never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    for (i, line) in data.split(|b| *b == b'\n').enumerate() {
        let out = settle::workflows::plan::answer_bytes(i as u64 + 1, line);
        let v: serde_json_check::Value = serde_json_check::from_str(&out).expect("answer is JSON");
        assert!(v.get("error").is_some() || v.get("axes").is_some(), "{out}");
    }
});
