//! settle-identify's tests: readers, Klipper's PSD, and identification of synthetic
//! recordings of settle's own plant in every file format.

mod bounds;
mod clipping;
mod common;
mod corpus;
mod damping_shaketune;
mod readers;
mod ringdown;
mod statistics;
mod sweep;
mod synth;
mod welch_klipper;
