//! settle-identify: a machine's vibration modes from the accelerometer data users already
//! have.
//!
//! A printer builder runs Klipper's `TEST_RESONANCES` / `SHAPER_CALIBRATE`, Shake&Tune or
//! RepRapFirmware's M956 and gets files; this crate reads them ([`read`]) and returns the
//! modes of the excited axis ([`identify_recording`], [`identify_spectrum`]): frequency,
//! damping ratio and participation weight, each with a standard deviation, in settle's
//! modal convention (settle-sim's `Mode`), plus the sensor direction that carried the
//! motion, the method, fit diagnostics and the data for a figure
//! ([`AxisIdentification`]).
//!
//! Methods: a resonance sweep is identified by fitting its Welch PSD (computed exactly as
//! Klipper does, [`welch`]) with the modal model's `|T|^2` times the sweep's own spectrum
//! ([`excitation`], [`fit::sweep`]); a free decay by fitting damped sinusoids in the time
//! domain ([`fit::ringdown`]).

pub mod direction;
pub mod energy_spectrum;
mod error;
pub mod excitation;
pub mod fit;
mod identify;
pub mod read;
pub mod result;
mod trust;
pub mod welch;

pub use direction::Direction;
pub use error::IdentifyError;
pub use excitation::SweepTest;
pub use identify::{MethodChoice, Options, SpectrumColumn, identify_recording, identify_spectrum};
pub use read::{FileData, Recording, RecordingFormat, read_file};
pub use result::{
    AxisIdentification, Diagnostics, Estimate, Figure, IdentifiedMode, Method, RejectedPeak,
    WeightBasis,
};

/// Identify every axis recording in a file (a `.stdata` file may hold several
/// measurements; other files hold one recording or one spectrum).
pub fn identify_file(
    path: &std::path::Path,
    opts: &Options,
) -> Result<Vec<AxisIdentification>, IdentifyError> {
    match read_file(path)? {
        FileData::Recordings(recs) => recs.iter().map(|r| identify_recording(r, opts)).collect(),
        FileData::Spectrum(psd) => Ok(vec![identify_spectrum(&psd, opts)?]),
    }
}
