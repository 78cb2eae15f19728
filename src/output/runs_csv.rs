//! `runs.csv`: one row per run, its parameters then its metrics, then the columns of its
//! studies (in registration order, `crate::studies::STUDIES`). Written with the `csv` crate
//! (`crate::input::runs_table::record`): numbers in Rust's shortest round-trip form, free
//! text (a failed run's reason) quoted where it holds a comma or a quote.
//!
//! The columns are a function of the sweep's runs alone, never of their results, so that a
//! row formed on its own (the sweep journal stores each run's row as it finishes) belongs
//! under the header of the whole sweep.

use settle_planner::ProfileKind;

use crate::input::runs_table::record;
use crate::measure::metrics::Metrics;
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;
use crate::studies::Study;

/// A band as it appears in column names (`10um`).
pub fn band_label(b: f64) -> String {
    format!("{b}um")
}

/// A time that may be "not settled": `inf` when not settled.
fn time_cell(t: Option<f64>) -> String {
    t.map_or_else(|| "inf".to_string(), |x| x.to_string())
}

/// The columns of a sweep's runs.csv, fixed from its runs.
#[derive(Debug, Clone)]
pub struct RunsCsv {
    header: Vec<String>,
    bands_um: Vec<f64>,
    axis_names: Vec<String>,
    studies: Vec<(&'static dyn Study, usize)>,
}

impl RunsCsv {
    /// The columns of the sweep `runs`.
    pub fn new(runs: &dyn RunList) -> Self {
        let bands_um = runs.first().map(|r| r.bands_um.clone()).unwrap_or_default();
        // The modes form's modes: axis x's as `mode<i>_*`, another axis's as
        // `<axis>_mode<i>_*`.
        let mode_axes: Vec<(String, usize)> = runs.first().map_or(Vec::new(), |r| {
            r.machine
                .modes()
                .iter()
                .map(|a| (a.axis.clone(), a.modes.len()))
                .collect()
        });
        let mut header: Vec<String> = [
            "run",
            "profile",
            "start_mm",
            "distance_mm",
            "vmax_mm_s",
            "amax_mm_s2",
            "jmax_mm_s3",
        ]
        .map(String::from)
        .to_vec();
        for (axis, n) in &mode_axes {
            let p = if axis == "x" {
                String::new()
            } else {
                format!("{axis}_")
            };
            for i in 0..*n {
                header.extend([
                    format!("{p}mode{i}_frequency_hz"),
                    format!("{p}mode{i}_damping_ratio"),
                    format!("{p}mode{i}_weight"),
                ]);
            }
        }
        header.extend(
            [
                "machine",
                "axis",
                "driver",
                "backend",
                "status",
                "lost_steps",
                "reason",
                "move_time_s",
                "residual_peak_um",
                "residual_rms_um",
            ]
            .map(String::from),
        );
        for b in &bands_um {
            header.push(format!("settle_time_s_{}", band_label(*b)));
        }
        for b in &bands_um {
            header.push(format!("move_and_settle_s_{}", band_label(*b)));
        }
        header.extend(["overshoot_um", "max_following_error_um"].map(String::from));
        // Per-axis metrics for physical machines and modes forms of several axes (one axis:
        // the above). A swept preset can change the axes: the union, in first-seen order.
        let mut axis_names: Vec<String> = Vec::new();
        if mode_axes.len() > 1 {
            axis_names = mode_axes.iter().map(|(a, _)| a.clone()).collect();
        }
        if runs.first().is_some_and(|r| r.machine.physical().is_some()) {
            for r in runs.iter() {
                for a in r.machine.physical().iter().flat_map(|m| &m.axes) {
                    if !axis_names.contains(&a.name) {
                        axis_names.push(a.name.clone());
                    }
                }
            }
        }
        for a in &axis_names {
            header.push(format!("{a}_residual_peak_um"));
            header.push(format!("{a}_residual_rms_um"));
            for b in &bands_um {
                header.push(format!("{a}_settle_time_s_{}", band_label(*b)));
            }
            header.push(format!("{a}_max_following_error_um"));
            header.push(format!("{a}_max_load_angle_deg"));
        }
        let mut studies = Vec::new();
        for k in crate::studies::all() {
            let cols = k.columns(runs);
            if !cols.is_empty() {
                studies.push((*k, cols.len()));
                header.extend(cols);
            }
        }
        Self {
            header,
            bands_um,
            axis_names,
            studies,
        }
    }

    /// The column names.
    pub fn columns(&self) -> &[String] {
        &self.header
    }

    /// The header line (with its newline).
    pub fn header(&self) -> String {
        record(&self.header)
    }

    /// The cells of run `r` with metrics `m`. A run that failed (lost steps, a fault) has
    /// no settling result: its metric cells stay empty so that nothing downstream averages
    /// them.
    pub fn cells(&self, r: &RunSpec, m: &Metrics) -> Vec<String> {
        let mut c: Vec<String> = Vec::with_capacity(self.header.len());
        c.extend([
            r.id.to_string(),
            profile_name(r.profile),
            r.start_mm.to_string(),
            r.distance_mm.to_string(),
            r.vmax_mm_s.to_string(),
            r.amax_mm_s2.to_string(),
            r.jmax_mm_s3.map_or(String::new(), |j| j.to_string()),
        ]);
        for md in r.machine.modes().iter().flat_map(|a| &a.modes) {
            c.extend([
                md.frequency_hz.to_string(),
                md.damping_ratio.to_string(),
                md.weight.to_string(),
            ]);
        }
        c.extend([
            r.machine_name.clone(),
            r.axis.clone(),
            r.driver.to_string(),
            r.backend.to_string(),
            m.status.name().to_string(),
            m.status.lost_steps().to_string(),
            // One line: a journal row is one line of text.
            m.status.reason().replace(['\n', '\r'], " "),
        ]);
        let n_bands = self.bands_um.len();
        if m.is_ok() {
            c.extend([
                m.move_time_s.to_string(),
                m.residual_peak_um.to_string(),
                m.residual_rms_um.to_string(),
            ]);
            c.extend(m.settle_time_s.iter().map(|t| time_cell(*t)));
            c.extend((0..m.settle_time_s.len()).map(|i| time_cell(m.move_and_settle_s(i))));
            c.extend([
                m.overshoot_um.to_string(),
                m.max_following_error_um.to_string(),
            ]);
            for name in &self.axis_names {
                let Some(a) = m.axes.iter().find(|a| &a.name == name) else {
                    // The run's machine has no such axis (swept presets).
                    c.extend(std::iter::repeat_n(String::new(), 4 + n_bands));
                    continue;
                };
                c.extend([
                    a.residual_peak_um.to_string(),
                    a.residual_rms_um.to_string(),
                ]);
                c.extend(a.settle_time_s.iter().map(|t| time_cell(*t)));
                c.extend([
                    a.max_following_error_um.to_string(),
                    a.max_load_angle_deg
                        .map_or(String::new(), |d| d.to_string()),
                ]);
            }
        } else {
            let empty = 5 + 2 * m.settle_time_s.len() + self.axis_names.len() * (4 + n_bands);
            c.extend(std::iter::repeat_n(String::new(), empty));
        }
        for (k, n) in &self.studies {
            let mut cells = k.cells(r, m);
            cells.resize(*n, String::new());
            c.extend(cells);
        }
        c
    }

    /// The row of run `r` with metrics `m` (with its newline).
    pub fn row(&self, r: &RunSpec, m: &Metrics) -> String {
        record(&self.cells(r, m))
    }
}

fn profile_name(k: ProfileKind) -> String {
    k.to_string()
}

/// The whole runs.csv of `runs` with their `metrics` (in the same order).
pub fn runs_csv(runs: &dyn RunList, metrics: &[Metrics]) -> String {
    let layout = RunsCsv::new(runs);
    let mut out = layout.header();
    for (r, m) in runs.iter().zip(metrics) {
        out.push_str(&layout.row(&r, m));
    }
    out
}
