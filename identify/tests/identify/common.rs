//! Shared checks.

use settle_identify::AxisIdentification;

use crate::synth::Truth;

/// Acceptance: every true mode found within 0.5 % (frequency) and 15 % (damping), the
/// reported 2-sigma intervals covering the truth, and as many modes as the truth.
pub fn check_modes(id: &AxisIdentification, truth: &[Truth], weights: bool) {
    let report = format!("{:#?}\n{:?}", id.modes, id.diagnostics);
    assert_eq!(id.modes.len(), truth.len(), "mode count\n{report}");
    for (m, &(f, z, w)) in id.modes.iter().zip(truth) {
        let fe = &m.frequency_hz;
        let ze = &m.damping_ratio;
        assert!((fe.value - f).abs() <= 0.005 * f, "frequency {f}: {report}");
        assert!((ze.value - z).abs() <= 0.15 * z, "damping {z}: {report}");
        assert!(fe.covers(f, 2.0), "frequency 2 sigma {f}: {report}");
        assert!(ze.covers(z, 2.0), "damping 2 sigma {z}: {report}");
        if weights {
            let we = m.weight.expect("weight");
            assert!(we.covers(w, 2.0), "weight 2 sigma {w}: {report}");
        }
    }
}
