//! settle-identify's tests: readers, Klipper's PSD, and identification of synthetic
//! recordings of settle's own plant in every file format.

mod common;
mod ringdown;
mod sweep;
mod synth;
