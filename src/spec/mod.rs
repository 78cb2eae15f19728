//! What one run is: [`run_spec::RunSpec`] (one point of a sweep, resolved) with the values
//! it was swept to ([`value::Value`]), the backend it runs on ([`backend::Backend`]) and
//! the states of its studies ([`run_spec::StudyState`], filled in by `crate::studies`).

pub mod backend;
pub mod groups;
pub mod machine;
pub mod run_spec;
pub mod runs;
pub mod value;

/// The largest |position| a move, a corner path or a scan may reach (mm): 100 m, as the G-code reader
/// takes coordinates. Positions are simulated in metres as f64, whose resolution at 100 m
/// (1.4e-14 m) is far below the 1e-10 m (1e-4 um) the metrics print; at 1e15 mm a 1 mm
/// move is not resolved at all.
pub const MAX_POSITION_MM: f64 = 1e5;

/// Why a position past [`MAX_POSITION_MM`] is refused: `what` (`the move starts`) at `x` mm.
pub fn beyond_positions(what: &str, x: f64) -> String {
    format!(
        "{what} at {x} mm; positions are limited to +-{MAX_POSITION_MM:e} mm (100 m: no machine is larger, and far out the simulation's numbers cannot resolve a move)"
    )
}
