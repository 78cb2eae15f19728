//! Shaping a profile that arrives in pieces: the streaming form of [`Shaper::apply`](crate::shaper::Shaper::apply).
//!
//! [`ShaperStream`] takes one axis's motion as consecutive [`Profile`](crate::Profile) chunks on a common
//! clock (each chunk starts where the previous one ended, in any state: moving,
//! accelerating) and gives back the shaped motion over any interval the input already
//! determines. It keeps the input of the last `T_N` seconds (the shaper's duration) as
//! history, so memory does not grow with the length of the motion. The output is the same
//! convolution as [`Shaper::apply`](crate::shaper::Shaper::apply), `q(t) = sum_i w_i p(t - tau_i)`, with the same
//! extension of the input (constant velocity before its first and after its last
//! instant) and the same segment construction (one segment per interval between shifted
//! input breakpoints, its jerk and acceleration read at the interval's middle), so the
//! concatenated output equals `Shaper::apply` of the whole profile up to rounding (see
//! `planner/tests/all/shaper_stream.rs`).
//!
//! **Alignment.** [`Alignment::Causal`] uses the impulse times as given (`tau_i = T_i`,
//! the first at 0: the shaped motion lags by the shaper's centroid `c = sum w_i T_i`), as
//! [`Shaper::apply`](crate::shaper::Shaper::apply) does. [`Alignment::Centred`] shifts them to `tau_i = T_i - c`, so that
//! constant-velocity motion is left unchanged and axes shaped differently stay in step:
//! Klipper does this (`shift_pulses` in klippy/chelper/kin_shaper.c), and Marlin's
//! FT_MOTION delays every axis by the largest centroid minus its own
//! (`Marlin/src/module/ft_motion/shaping.h`), which is the centred form delayed by a
//! constant. Centred output needs input `c` seconds ahead, so it lags the input by `c`.
//!
//! **Changing the shaper** ([`ShaperStream::set_shaper`]) at time `T` (the end of the input
//! so far) splits the input into the motion up to `T`, continued at its velocity at `T`,
//! and the rest: `p = p_old + p_new`. The old shaper keeps shaping `p_old` and the new
//! one shapes `p_new`, so the output stays continuous in position and velocity and no
//! motion is shaped twice or lost. At a standstill (where firmwares change their
//! shapers) this is simply "the old shaper finishes what came before, the new one shapes
//! what comes after". Between shapers of different centroids a change while moving at
//! `v` leaves a position offset `v (c_new - c_old)` (the shaped motion's delay changes);
//! centred shapers have no such offset.

mod alignment;
mod axes;
mod cut;
mod history;
mod regime;
mod single;

pub use alignment::Alignment;
pub use axes::AxesShaper;
pub use cut::cut;
pub use single::ShaperStream;
