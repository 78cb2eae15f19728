//! Two settings on the same file: `settle gcode --versus FIRMWARE[:SHAPER]` runs the
//! second setting too, draws the first setting's worst layer under both on one colour
//! scale (`compare-layer-<n>.svg/.png`) and tabulates print time and contour error of both
//! (`compare.md`).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use settle_gcode::job::{Firmware, JobConfig, ShaperSetting};

use super::report::map_panel;
use super::{GcodeOptions, GcodeOutcome, measure, parse_shaper};
use crate::error::Error;
use crate::output::atomic::write_atomic;
use crate::output::plot::ringing::RingingMap;

/// A setting as written after `--versus`: `FIRMWARE` (its defaults, unshaped) or
/// `FIRMWARE:SHAPER` (`klipper:mzv@48`, `settle:none`).
pub fn parse_setting(s: &str) -> Result<(Firmware, Option<ShaperSetting>), String> {
    let (fw, shaper) = match s.split_once(':') {
        Some((fw, sh)) if sh.eq_ignore_ascii_case("none") => (fw, None),
        Some((fw, sh)) => (fw, Some(parse_shaper(sh)?)),
        None => (s, None),
    };
    let firmware = fw.parse::<Firmware>().map_err(|e| format!("`{s}`: {e}"))?;
    Ok((firmware, shaper))
}

/// The options of `base` with another firmware (its defaults) and shaper.
pub fn versus(
    base: &GcodeOptions,
    firmware: Firmware,
    shaper: Option<ShaperSetting>,
) -> Result<GcodeOptions, Error> {
    let job = JobConfig::defaults(firmware).map_err(super::gcode_error(&base.file))?;
    Ok(GcodeOptions {
        job,
        ..base.clone()
    }
    .with_shaper(shaper))
}

/// The comparison table (Markdown) of outcomes.
pub fn table(outcomes: &[&GcodeOutcome]) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "| setting | print time (s) | worst contour error (um) | p95 (um) | worst line |"
    );
    let _ = writeln!(s, "|---|---:|---:|---:|---:|");
    for o in outcomes {
        let line = o
            .worst()
            .first()
            .map_or(String::new(), |w| w.line.to_string());
        let _ = writeln!(
            s,
            "| {} | {:.2} | {:.2} | {:.2} | {line} |",
            o.setting, o.print_time_s, o.worst_um, o.p95_um
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
        }
        .write(dir, &stem)?;
        files.push(dir.join(format!("{stem}.svg")));
        files.push(dir.join(format!("{stem}.png")));
    }
    let md = dir.join("compare.md");
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
        assert_eq!(s.map(|s| s.frequency_hz), Some(48.0));
        assert_eq!(parse_setting("settle:none"), Ok((Firmware::Settle, None)));
        assert_eq!(parse_setting("rrf"), Ok((Firmware::Rrf, None)));
        assert!(parse_setting("cnc").is_err());
    }
}
