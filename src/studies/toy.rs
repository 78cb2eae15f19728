//! A toy study, compiled for the unit tests only: the recipe of [`crate::studies`]
//! followed to the letter (this file and one line in `STUDIES`), which
//! `crate::workflows::toy_pipeline` runs through the whole pipeline.
//!
//! `[toy] legs = N`: a shuttle, the point move done `N` times there and back (an odd `N`
//! ends at the far end). It measures the largest |toolhead - command| during the move from
//! the run's series (`toy_max_error_um`, which must equal the streaming
//! `max_following_error_um`), names two runs.csv columns and writes a summary section.

use std::fmt::Write as _;

use serde::Deserialize;
use settle_planner::{PlanError, Profile, Segment};

use crate::error::Error;
use crate::input::runs_columns::RunsColumns;
use crate::input::source::Source;
use crate::studies::{
    Motion, Study, StudyState, PlanContext, Planned, PlotColumn, Probe, Role, any_has, on_axis,
};
use crate::measure::metrics::Metrics;
use crate::measure::series::Series;
use crate::spec::run_spec::RunSpec;
use crate::spec::runs::RunList;
use crate::spec::value::Value;

/// `[toy]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct ToyTable {
    legs: u32,
}

/// A run's shuttle.
#[derive(Debug, Clone, PartialEq)]
pub struct Shuttle {
    /// Moves there and back.
    pub legs: u32,
}

impl StudyState for Shuttle {
    fn table(&self) -> &'static str {
        "toy"
    }

    fn set(&mut self, key: &str, value: &Value) -> Result<(), String> {
        match (key, value.number()) {
            ("legs", Some(x)) if x.fract() == 0.0 && (0.0..=1000.0).contains(&x) => {
                self.legs = x as u32;
                Ok(())
            }
            ("legs", _) => Err("`toy.legs` takes whole numbers".into()),
            _ => Err(format!("`toy.{key}` cannot be swept; allowed: toy.legs")),
        }
    }
}

/// The toy study.
#[derive(Debug, Clone, Copy)]
pub struct Toy;

/// Measures the largest error during the move from the series' `error` channel.
#[derive(Debug)]
struct MaxError {
    move_end_s: f64,
}

impl Probe for MaxError {
    fn measure(&self, _run: &RunSpec, series: &Series, m: &mut Metrics) -> Result<(), Error> {
        let e = series.channel("error").map_or(f64::NAN, |c| {
            c.data
                .iter()
                .zip(&series.t_s)
                .filter(|(_, t)| **t <= self.move_end_s)
                .map(|(e, _)| e * 1e6)
                .fold(0.0, f64::max)
        });
        m.extra = vec![("toy_max_error_um".into(), e)];
        Ok(())
    }
}

impl Study for Toy {
    fn name(&self) -> &'static str {
        "toy shuttle"
    }

    fn table(&self) -> Option<&'static str> {
        Some("toy")
    }

    fn role(&self) -> Role {
        Role::Move
    }

    fn sweepable(&self) -> &'static str {
        "toy.legs"
    }

    fn parse(&self, src: &Source) -> Result<Option<Box<dyn StudyState>>, Error> {
        Ok(src
            .table::<ToyTable>("toy")?
            .map(|t| Box::new(Shuttle { legs: t.legs }) as Box<dyn StudyState>))
    }

    fn validate(&self, run: &RunSpec) -> Result<(), (String, String)> {
        match run.state::<Shuttle>() {
            Some(s) if s.legs == 0 => Err((run.blame("toy.legs"), "must be >= 1".into())),
            _ => Ok(()),
        }
    }

    fn plan(&self, run: &RunSpec, ctx: &PlanContext) -> Result<Planned, PlanError> {
        let legs = run.state::<Shuttle>().map_or(1, |s| s.legs);
        let limits = run.limits_si()?;
        let (p0, d) = (run.start_mm * 1e-3, run.distance_mm * 1e-3);
        let there = run.profile.rest_to_rest(p0, d, &limits)?;
        let back = run.profile.rest_to_rest(p0 + d, -d, &limits)?;
        let mut segments = Vec::new();
        for i in 0..legs {
            // Each leg starts at rest: a zero-length segment sets the acceleration to 0.
            segments.push(Segment::Accel {
                duration_s: 0.0,
                accel: 0.0,
            });
            let leg = if i % 2 == 0 { &there } else { &back };
            segments.extend_from_slice(leg.segments());
        }
        let shuttle = Profile::new(there.start(), segments)?;
        let move_end_s = shuttle.duration_s();
        Ok(Planned {
            motion: Motion::Whole(on_axis(ctx.axes, &run.axis, &shuttle)?),
            probe: Some(Box::new(MaxError { move_end_s })),
            linearise_at_m: None,
            step_at_m: None,
        })
    }

    fn columns(&self, runs: &dyn RunList) -> Vec<String> {
        if !any_has::<Shuttle>(runs) {
            return Vec::new();
        }
        vec!["toy_legs".into(), "toy_max_error_um".into()]
    }

    fn cells(&self, run: &RunSpec, m: &Metrics) -> Vec<String> {
        let Some(s) = run.state::<Shuttle>() else {
            return Vec::new();
        };
        let mut out = vec![s.legs.to_string()];
        if m.is_ok() {
            out.extend(m.extra.iter().map(|(_, x)| x.to_string()));
        }
        out
    }

    fn summary(
        &self,
        runs: &dyn RunList,
        table: &RunsColumns,
        _current: &dyn Fn(&RunSpec) -> bool,
    ) -> Option<String> {
        table.column("toy_max_error_um")?;
        let mut out =
            String::from("## Toy shuttle\n\n| run | legs | max error (um) |\n|---:|---:|---:|\n");
        for (i, r) in runs.iter().enumerate() {
            let _ = writeln!(
                out,
                "| {} | {} | {} |",
                r.id,
                table.cell(i, "toy_legs").unwrap_or("-".into()),
                table
                    .num(i, "toy_max_error_um")
                    .map_or("-".into(), |x| format!("{x:.2}"))
            );
        }
        Some(out)
    }

    fn figures(&self, _bands_um: &[f64]) -> Vec<PlotColumn> {
        vec![PlotColumn::new(
            "toy_max_error_um",
            "shuttle: largest error during the move",
            "|error|",
            "um",
            1.0,
            true,
        )]
    }
}
