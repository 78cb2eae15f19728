//! Shared checks.

use settle_identify::AxisIdentification;

use crate::synth::Truth;

/// Acceptance: every true mode found within 0.5 % (frequency) and 15 % (damping), the
/// reported 2-sigma intervals covering the truth, and as many modes as the truth.
pub fn check_modes(id: &AxisIdentification, truth: &[Truth], weights: bool) {
    let failures = mode_failures(id, truth, weights);
    assert!(
        failures.is_empty(),
        "{}\n{:#?}\n{:?}",
        failures.join("; "),
        id.modes,
        id.diagnostics
    );
}

/// What [`check_modes`] would reject, one entry per failed check (empty: accepted).
pub fn mode_failures(id: &AxisIdentification, truth: &[Truth], weights: bool) -> Vec<String> {
    if id.modes.len() != truth.len() {
        return vec![format!("{} modes, not {}", id.modes.len(), truth.len())];
    }
    let mut out = Vec::new();
    for (m, &(f, z, w)) in id.modes.iter().zip(truth) {
        let fe = &m.frequency_hz;
        let ze = &m.damping_ratio;
        if (fe.value - f).abs() > 0.005 * f {
            out.push(format!("frequency {f}: {}", fe.value));
        }
        if (ze.value - z).abs() > 0.15 * z {
            out.push(format!("damping {z}: {}", ze.value));
        }
        if !fe.covers(f, 2.0) {
            out.push(format!("frequency 2 sigma {f}: {fe:?}"));
        }
        if !ze.covers(z, 2.0) {
            out.push(format!("damping 2 sigma {z}: {ze:?}"));
        }
        if weights {
            match m.weight {
                Some(we) if we.covers(w, 2.0) => {}
                other => out.push(format!("weight 2 sigma {w}: {other:?}")),
            }
        }
    }
    out
}
