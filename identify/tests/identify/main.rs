//! settle-identify's tests: readers, Klipper's PSD, and identification of synthetic
//! recordings of settle's own plant in every file format.

mod common;
mod readers;
mod ringdown;
mod statistics;
mod sweep;
mod synth;
mod welch_klipper;
