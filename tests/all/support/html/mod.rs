//! The report page's test helpers: a headless browser and fixtures.

pub mod chromium;
pub mod fixture;
