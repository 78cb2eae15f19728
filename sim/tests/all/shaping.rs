//! Input shaping against the physics: by linearity, the residual envelope after a shaped
//! move equals the unshaped move's envelope times the shaper's remaining vibration
//! `V(f, zeta)` (Klipper's estimate), evaluated with the independent closed form.

use settle_planner::shaper::{Shaper, ShaperType};
use settle_planner::{Limits, ProfileKind};
use settle_sim::Mode;
use settle_sim::closed_form::residual_envelope;

#[test]
fn shaped_residual_is_the_remaining_vibration_times_the_unshaped_one() {
    let lim = Limits::new(0.3, 5.0, Some(200.0)).expect("limits");
    for kind in [ProfileKind::Trapezoid, ProfileKind::SCurve] {
        for distance in [0.001, 0.013, 0.1] {
            let p = kind.rest_to_rest(0.0, distance, &lim).expect("plan");
            for (f_mode, z_mode) in [(40.0, 0.05), (55.0, 0.1), (38.0, 0.02)] {
                let mode = Mode::new(f_mode, z_mode, 1.0).expect("mode");
                let unshaped = residual_envelope(&p, &mode);
                for sk in ShaperType::ALL {
                    // Tuned slightly off the mode, as in practice.
                    let s = Shaper::new(sk, 42.0, 0.1).expect("shaper");
                    let q = s.apply(&p).expect("shaped");
                    let got = residual_envelope(&q, &mode);
                    let expect = unshaped * s.remaining_vibration(f_mode, z_mode);
                    assert!(
                        (got - expect).abs() <= 1e-9 * unshaped.max(1e-12),
                        "{kind} {distance} m, mode {f_mode} Hz: shaped {got}, expected {expect}"
                    );
                }
            }
        }
    }
}
