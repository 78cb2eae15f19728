//! Where a stream's impulses sit relative to its input (see the module doc of
//! [`crate::shaper::stream`]).

/// Where the impulses sit relative to the input (module doc).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Alignment {
    /// Impulse times as the shaper defines them, the first at 0 ([`Shaper::apply`](crate::shaper::Shaper::apply)).
    Causal,
    /// Impulse times shifted by the centroid (Klipper, Marlin FT_MOTION).
    #[default]
    Centred,
}
