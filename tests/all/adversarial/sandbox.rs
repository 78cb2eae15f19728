//! The files the cases read, in a temporary folder: a small scenario, a recording, a
//! printer.cfg with an include, a G-code print, and the hostile ones (a FIFO, links to
//! devices and out of the folder, sparse files past each size limit, a decompression bomb,
//! a file with a secret).

use std::path::Path;

use crate::support::root;

/// A sandbox of fixtures; every path a case names is relative to [`Sandbox::root`].
#[derive(Debug)]
pub struct Sandbox {
    dir: tempfile::TempDir,
    device: String,
}

/// A scenario of two quick modal runs (a 40 Hz mode).
pub const SCENARIO: &str = r#"name = "adv"
[machine]
modes = [{ frequency_hz = 40.0, damping_ratio = 0.05 }]
[move]
distance_mm = 5.0
profile = "scurve"
[limits]
vmax_mm_s = 300.0
amax_mm_s2 = 3000.0
jmax_mm_s3 = 100000.0
[observe]
window_s = 0.2
sample_rate_hz = 2000
bands_um = [10.0]
[sweep]
profile = ["trapezoid", "scurve"]
"#;

/// A Klipper configuration that includes `inc/limits.cfg`.
const PRINTER_CFG: &str = "[printer]\nkinematics: cartesian\nmax_velocity: 300\n[include inc/limits.cfg]\n[stepper_x]\nrotation_distance: 40\nmicrosteps: 16\n[stepper_y]\nrotation_distance: 40\nmicrosteps: 16\n[input_shaper]\nshaper_type_x: mzv\nshaper_freq_x: 50\nshaper_type_y: ei\nshaper_freq_y: 40\n";

/// `settle gcode` on the sandbox's print, on printer_xy, into `o` (more options follow).
pub const GCODE: &str = "gcode print.gcode --machine printer_xy --out o";

/// The marker of a file whose content must never be repeated.
pub const SECRET: &str = "ZQXSECRET";

/// A Shake&Tune-looking `.stdata` that decompresses to `bytes` of `a`: one zstd frame of
/// RLE blocks (a 3-byte header and one byte per 128 KiB), which no compressor is needed
/// to write (RFC 8878, sections 3.1.1 and 3.1.1.2).
pub fn zstd_bomb(bytes: u64) -> Vec<u8> {
    const BLOCK: u64 = 128 * 1024;
    let mut out = vec![0x28, 0xb5, 0x2f, 0xfd];
    // Frame header: no content size, not single-segment, no checksum, no dictionary;
    // window 2^(10 + 7) = 128 KiB.
    out.push(0x00);
    out.push(7 << 3);
    let blocks = bytes.div_ceil(BLOCK);
    for i in 0..blocks {
        let size = BLOCK.min(bytes - i * BLOCK);
        let last = u64::from(i + 1 == blocks);
        // Block_Size << 3 | Block_Type (1: RLE) << 1 | Last_Block.
        let header = (size << 3) | (1 << 1) | last;
        out.extend_from_slice(&header.to_le_bytes()[..3]);
        out.push(b'a');
    }
    out
}

impl Sandbox {
    /// Every fixture, made.
    pub fn new() -> Self {
        let dir = tempfile::tempdir().expect("tempdir");
        let d = dir.path();
        let w = |name: &str, text: &[u8]| {
            let p = d.join(name);
            if let Some(parent) = p.parent() {
                std::fs::create_dir_all(parent).expect("mkdir");
            }
            std::fs::write(p, text).expect("writes");
        };
        w("sc.toml", SCENARIO.as_bytes());
        let copy = |from: &str, to: &str| {
            std::fs::copy(root().join(from), d.join(to)).expect("copies");
        };
        copy("examples/data/raw_data_x_example.csv", "rec_x.csv");
        copy("gcode/prints/cube_layer.gcode", "print.gcode");
        w("printer.cfg", PRINTER_CFG.as_bytes());
        w("inc/limits.cfg", b"[printer]\nmax_accel: 3000\n");
        w("secret.txt", format!("{SECRET}=do-not-print\n").as_bytes());
        w("bomb.stdata", &zstd_bomb(4 << 30));
        std::fs::create_dir_all(d.join("folder.d")).expect("mkdir");
        std::fs::create_dir_all(d.join("elsewhere")).expect("mkdir");
        // Sparse files one byte past each limit: no disk, no time to make.
        for (name, limit) in [
            ("big.toml", settle_files::limit::SETTINGS),
            ("big.cfg", settle_files::limit::FIRMWARE_CONFIG),
            ("big.gcode", settle_files::limit::GCODE),
            ("big_x.csv", settle_files::limit::RECORDING),
            ("big_runs.csv", settle_files::limit::RESULTS),
        ] {
            let f = std::fs::File::create(d.join(name)).expect("creates");
            f.set_len(limit.bytes + 1).expect("sparse");
        }
        // Without the right to make a device node, /dev/null (which an unprivileged
        // process cannot replace).
        let mut device = "/dev/null".to_string();
        #[cfg(unix)]
        {
            use std::os::unix::fs::symlink;
            symlink("/dev/zero", d.join("zero.csv")).expect("link");
            symlink("/dev/zero", d.join("zero.gcode")).expect("link");
            symlink("/dev/zero", d.join("zero.toml")).expect("link");
            symlink("/dev/zero", d.join("zero.cfg")).expect("link");
            symlink("rec_x.csv", d.join("link_x.csv")).expect("link");
            symlink("elsewhere", d.join("out_link")).expect("link");
            symlink(
                d.join("elsewhere/precious.txt"),
                d.join("precious_link.csv"),
            )
            .expect("link");
            w("elsewhere/precious.txt", b"keep me\n");
            // A null device of the sandbox's own where outputs must not go (as root: a
            // build that replaced a device would replace this one, never /dev/null).
            let made = std::process::Command::new("mknod")
                .arg(d.join("null.dev"))
                .args(["c", "1", "3"])
                .stderr(std::process::Stdio::null())
                .status()
                .is_ok_and(|s| s.success());
            if made {
                device = "null.dev".to_string();
            }
            for name in ["fifo.csv", "fifo.toml", "fifo.cfg", "fifo.gcode"] {
                let made = std::process::Command::new("mkfifo")
                    .arg(d.join(name))
                    .status()
                    .expect("mkfifo runs");
                assert!(made.success(), "mkfifo {name}");
            }
        }
        Self { dir, device }
    }

    /// A character device (the null device) to name as an output.
    pub fn device(&self) -> &str {
        &self.device
    }

    /// The folder every case runs in.
    pub fn root(&self) -> &Path {
        self.dir.path()
    }

    /// Write `text` as `name` in the sandbox (a fixture of one class).
    pub fn write(&self, name: &str, text: &str) {
        let p = self.root().join(name);
        if let Some(parent) = p.parent() {
            std::fs::create_dir_all(parent).expect("mkdir");
        }
        std::fs::write(p, text).expect("writes");
    }
}
