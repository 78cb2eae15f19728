//! With the `mujoco` feature: check that libmujoco.so is where mujoco-rs will link it from
//! (a clear message pointing at scripts/setup-mujoco.sh when it is not) and embed that
//! folder as an rpath in the `settle` binary, its tests and benches, so they run without
//! LD_LIBRARY_PATH. Without the feature: nothing. (sim/build.rs does the same for sim.)

use std::path::PathBuf;

fn main() {
    println!("cargo::rerun-if-env-changed=MUJOCO_DYNAMIC_LINK_DIR");
    println!("cargo::rerun-if-changed=build.rs");
    if std::env::var_os("CARGO_FEATURE_MUJOCO").is_none() {
        return;
    }
    // .cargo/config.toml sets MUJOCO_DYNAMIC_LINK_DIR to <repo>/.deps/mujoco; the fallback
    // covers a build that bypasses that config.
    let dir = std::env::var_os("MUJOCO_DYNAMIC_LINK_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|| {
            PathBuf::from(std::env::var_os("CARGO_MANIFEST_DIR").expect("set by cargo"))
                .join(".deps/mujoco")
        });
    let lib = dir.join("libmujoco.so");
    println!("cargo::rerun-if-changed={}", lib.display());
    if !lib.is_file() {
        eprintln!(
            "error: the `mujoco` feature needs the MuJoCo 3.17.0 library, and {} does not \
             exist.\n       Run scripts/setup-mujoco.sh from the repository root (it fetches \
             libmujoco from the PyPI wheel into .deps/mujoco/), or set \
             MUJOCO_DYNAMIC_LINK_DIR to an absolute folder containing libmujoco.so 3.17.0.",
            lib.display()
        );
        std::process::exit(1);
    }
    let os = std::env::var("CARGO_CFG_TARGET_OS").unwrap_or_default();
    if os == "linux" || os == "macos" {
        let dir = dir.canonicalize().unwrap_or(dir);
        println!("cargo::rustc-link-arg=-Wl,-rpath,{}", dir.display());
    }
}
