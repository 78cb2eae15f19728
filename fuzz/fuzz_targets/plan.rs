//! Fuzz `settle plan`'s input: every line gets exactly one JSON answer (a profile or an
//! error), never a panic.
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    for line in text.lines() {
        let out = settle::workflows::plan::answer(line);
        let v: serde_json_check::Value = serde_json_check::from_str(&out).expect("answer is JSON");
        assert!(v.get("error").is_some() || v.get("axes").is_some(), "{out}");
    }
});
