//! Two settings on the same file: `settle gcode --versus FIRMWARE[:SHAPER]` runs the
//! second setting too, draws the first setting's worst layer under both on one colour
//! scale (`compare-layer-<n>.svg/.png`) and tabulates print time and contour error of both
//! (`compare.md`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use settle_gcode::job::JobConfig;
use settle_planner::firmware::Firmware;

use super::report::map_panel;
use super::{GcodeOptions, GcodeOutcome, XyShapers, measure, parse_shapers};
use crate::error::Error;
use crate::output::atomic::write_atomic;
use crate::output::plot::ringing::{CONTOUR_ERROR, RingingMap};

/// The comparison table's file name in the output folder.
pub const FILE: &str = "compare.md";

/// A setting as written after `--versus`: `FIRMWARE` (unshaped) or `FIRMWARE:SHAPERS`
/// (`klipper:mzv@48`, `settle:none`, `klipper:x=mzv@52,y=ei@41`; [`XyShapers`]).
pub fn parse_setting(s: &str) -> Result<(Firmware, XyShapers), String> {
    let (fw, shapers) = match s.split_once(':') {
        Some((fw, sh)) => (fw, parse_shapers(sh).map_err(|e| format!("`{s}`: {e}"))?),
        None => (s, XyShapers::both(None)),
    };
    let firmware = settle_gcode::job::parse_firmware(fw).map_err(|e| format!("`{s}`: {e}"))?;
    Ok((firmware, shapers))
}

/// The options of `base` with another setting: the same firmware as a `--config` run
/// keeps the configuration's settings (and, on an axis the shapers do not name, its
/// shaper); another firmware starts from its defaults, unshaped. Both read the file's
/// layers alike (`--layer-source`).
pub fn versus(
    base: &GcodeOptions,
    firmware: Firmware,
    shapers: XyShapers,
) -> Result<GcodeOptions, Error> {
    let job = match &base.config {
        Some(c) if c.job.firmware() == firmware => c.job.clone(),
        _ => JobConfig::for_file(firmware, &base.file).map_err(super::gcode_error(&base.file))?,
    };
    let config = base.config.clone().filter(|c| c.job.firmware() == firmware);
    Ok(GcodeOptions {
        job,
        config,
        ..base.clone()
    }
    .with_shapers(shapers)
    .with_layer_mode(base.job.layer_mode))
}

/// The comparison table (Markdown) of outcomes.
pub fn table(outcomes: &[&GcodeOutcome]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| setting | print time (s) | worst contour error (um) | p95 (um) | worst smoothing (um) | worst vibration (um) | worst line |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|---:|---:|");
    for o in outcomes {
        let line = o
            .worst()
            .first()
            .map_or(String::new(), |w| w.line.to_string());
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {line} |",
            o.setting,
            o.print_time_s,
            o.worst_um,
            o.p95_um,
            o.streamed.split_worst.smoothing_um,
            o.streamed.split_worst.vibration_um
        );
    }
    s
}

/// Draw `a`'s worst layer under both settings (`a` and `b` measured with `a_opts` and
/// `b_opts`) and write the table into `dir`; returns the files written.
pub fn compare(
    (a, a_opts): (&GcodeOutcome, &GcodeOptions),
    (b, b_opts): (&GcodeOutcome, &GcodeOptions),
    dir: &Path,
) -> Result<Vec<PathBuf>, Error> {
    let mut files = Vec::new();
    if let Some(layer) = a.maps().first().map(|m| m.layer) {
        // The whole job again under each setting, keeping this layer's map: the layer as
        // printed after the layers before it (a layer range would start it at rest).
        let one = |o: &GcodeOptions| {
            measure(&GcodeOptions {
                map_layer: Some(layer),
                ..o.clone()
            })
        };
        let (ma, mb) = (one(a_opts)?, one(b_opts)?);
        let panels = [(&ma, a), (&mb, b)]
            .iter()
            .filter_map(|(m, o)| m.streamed.chosen.as_ref().map(|l| map_panel(l, &o.setting)))
            .collect();
        let stem = format!("compare-layer-{layer}");
        RingingMap {
            title: format!("Contour error, {}", a.file.display()),
            panels,
            quantity: CONTOUR_ERROR.into(),
        }
        .write(dir, &stem)?;
        files.push(dir.join(format!("{stem}.svg")));
        files.push(dir.join(format!("{stem}.png")));
    }
    let md = dir.join(FILE);
    let text = format!(
        "# {} on {}\n\n{}",
        a.file.display(),
        a.machine,
        table(&[a, b])
    );
    write_atomic(&md, text.as_bytes())?;
    files.push(md);
    Ok(files)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_parse() {
        let (f, s) = parse_setting("klipper:mzv@48").expect("setting");
        assert_eq!(f, Firmware::Klipper);
        let freq = |s: Option<Option<settle_gcode::job::ShaperSetting>>| {
            s.map(|s| s.map(|s| s.frequency_hz))
        };
        assert_eq!((freq(s.x), freq(s.y)), (Some(Some(48.0)), Some(Some(48.0))));
        let none = XyShapers::both(None);
        assert_eq!(parse_setting("settle:none"), Ok((Firmware::Settle, none)));
        assert_eq!(parse_setting("rrf"), Ok((Firmware::Rrf, none)));
        assert!(parse_setting("cnc").is_err());
        let (_, s) = parse_setting("klipper:x=mzv@52,y=ei@41/0.08").expect("per axis");
        assert_eq!((freq(s.x), freq(s.y)), (Some(Some(52.0)), Some(Some(41.0))));
        assert_eq!(s.y.flatten().map(|s| s.damping_ratio), Some(0.08));
        let (_, s) = parse_setting("klipper:y=none").expect("one axis");
        assert_eq!((s.x, s.y), (None, Some(None)));
        for bad in [
            "klipper:x=mzv@52,x=ei@41",
            "klipper:z=mzv@40",
            "klipper:x=mzv",
            "klipper:x",
        ] {
            assert!(parse_setting(bad).is_err(), "{bad}");
        }
    }
}
