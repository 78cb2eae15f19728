//! `ModalPlant::step_samples` against `step` then `positions` per sample, bit for bit:
//! a moving command (one piece of an S-curve), a held command, an idle axis, state sizes
//! 2 to 8, chunk lengths 1 to 300, and the contract's stops (a state that is not finite,
//! a blow-up past the limit).

use settle_planner::{Sample, State};
use settle_sim::{
    AxisModel, ModalPlant, ModalState, Mode, Observation, Plant, SimError, advance_sample,
};

const DT: f64 = 1e-4;
const BLOWUP_M: f64 = 0.1;

fn plant(modes_per_axis: &[usize]) -> ModalPlant {
    let axes = modes_per_axis
        .iter()
        .enumerate()
        .map(|(a, &n)| {
            let modes: Vec<Mode> = (0..n)
                .map(|i| {
                    Mode::new(35.0 + 40.0 * i as f64 + a as f64, 0.04, 0.6 / n as f64)
                        .expect("mode")
                })
                .collect();
            AxisModel::from_modes(&format!("a{a}"), &modes).expect("axis")
        })
        .collect();
    ModalPlant::new(axes, DT).expect("plant")
}

/// What `step_samples` returns.
type Done = Result<Option<usize>, (usize, SimError)>;

/// `step_samples`' result and outputs, computed one sample at a time.
fn one_by_one(p: &ModalPlant, st: &mut ModalState, cmds: &[Sample]) -> (Done, Vec<f64>, Vec<f64>) {
    let na = p.axes();
    let (mut c, mut h) = (vec![0.0; cmds.len()], vec![0.0; cmds.len()]);
    for (i, cmd) in cmds.chunks_exact(na).enumerate() {
        if let Err(e) = p.step(st, cmd, DT) {
            return (Err((i, e)), c, h);
        }
        let (ci, hi) = (&mut c[i * na..(i + 1) * na], &mut h[i * na..(i + 1) * na]);
        let ok = p.positions(st, ci, hi)
            && ci
                .iter()
                .zip(hi.iter())
                .all(|(c, h)| (h - c).abs() <= BLOWUP_M);
        if !ok {
            return (Ok(Some(i + 1)), c, h);
        }
    }
    (Ok(Some(cmds.len() / na)), c, h)
}

fn bits(v: &[f64]) -> Vec<u64> {
    v.iter().map(|x| x.to_bits()).collect()
}

fn observed(p: &ModalPlant, st: &ModalState) -> String {
    let mut o = vec![Observation::default(); p.axes()];
    p.observe(st, &mut o);
    format!("{o:?} t={:?}", st.t_s)
}

/// The commands of `n` steps from `c0`, one axis moving with constant jerk from `start`,
/// the others holding.
fn commands(na: usize, moving: Option<usize>, c0: Sample, n: usize, start: usize) -> Vec<Sample> {
    let mut out = Vec::with_capacity(n * na);
    for i in 0..n {
        for a in 0..na {
            out.push(if Some(a) == moving {
                advance_sample(&c0, (start + i) as f64 * DT)
            } else {
                Sample {
                    p: 0.003 * a as f64,
                    ..Sample::default()
                }
            });
        }
    }
    out
}

#[test]
fn step_samples_equals_step_and_positions_bit_for_bit() {
    for modes in [vec![1usize], vec![2, 3], vec![4, 1], vec![3, 3]] {
        let p = plant(&modes);
        let na = p.axes();
        let starts: Vec<State> = (0..na)
            .map(|a| State {
                p: 0.003 * a as f64,
                ..State::default()
            })
            .collect();
        let (mut a, mut b) = (
            p.initial_state(&starts).expect("state"),
            p.initial_state(&starts).expect("state"),
        );
        let ramp = Sample {
            p: 0.0,
            v: 0.0,
            a: 0.0,
            j: 4000.0,
        };
        let mut k = 0;
        // A ramp on axis 0 (others idle), then everything held.
        for (len, moving) in [
            (1, Some(0)),
            (37, Some(0)),
            (256, Some(0)),
            (300, None),
            (5, None),
        ] {
            let c0 = if moving.is_some() {
                ramp
            } else {
                // Held where the ramp got to.
                let s = advance_sample(&ramp, k as f64 * DT);
                Sample {
                    p: s.p,
                    ..Sample::default()
                }
            };
            let cmds = commands(na, moving, c0, len, if moving.is_some() { k } else { 0 });
            let (want, wc, wh) = one_by_one(&p, &mut b, &cmds);
            let (mut gc, mut gh) = (vec![0.0; cmds.len()], vec![0.0; cmds.len()]);
            let got = p.step_samples(&mut a, &cmds, DT, BLOWUP_M, &mut gc, &mut gh);
            assert_eq!(
                format!("{want:?}"),
                format!("{got:?}"),
                "{modes:?} len {len}"
            );
            assert_eq!(bits(&wc), bits(&gc));
            assert_eq!(bits(&wh), bits(&gh));
            assert_eq!(observed(&p, &a), observed(&p, &b));
            k += len;
        }
        assert!(
            a.axes[0].r().iter().any(|r| *r != 0.0),
            "the ramp deflected the axis"
        );
    }
}

#[test]
fn step_samples_stops_where_step_and_positions_would() {
    let p = plant(&[3, 2]);
    let starts = [State::default(); 2];
    let held = [Sample::default(); 2];
    let cmds: Vec<Sample> = std::iter::repeat_n(held, 100).flatten().collect();
    // A blow-up: 0.5 m of deflection on axis 1's first mode passes the limit at once.
    // A NaN deflection: the first step fails.
    for (axis, value) in [(1, 0.5), (1, f64::NAN), (0, f64::INFINITY), (0, 0.05)] {
        let (mut a, mut b) = (
            p.initial_state(&starts).expect("state"),
            p.initial_state(&starts).expect("state"),
        );
        a.axes[axis].set_r(0, value);
        b.axes[axis].set_r(0, value);
        let (want, wc, wh) = one_by_one(&p, &mut b, &cmds);
        let (mut gc, mut gh) = (vec![0.0; cmds.len()], vec![0.0; cmds.len()]);
        let got = p.step_samples(&mut a, &cmds, DT, BLOWUP_M, &mut gc, &mut gh);
        assert_eq!(
            format!("{want:?}"),
            format!("{got:?}"),
            "{value} on axis {axis}"
        );
        if let Ok(Some(k)) = want {
            let k = k * 2;
            assert_eq!(bits(&wc[..k]), bits(&gc[..k]));
            assert_eq!(bits(&wh[..k]), bits(&gh[..k]));
            assert_eq!(observed(&p, &a), observed(&p, &b));
        }
        match value {
            0.05 => assert_eq!(got.as_ref().ok(), Some(&Some(100)), "in bounds"),
            0.5 => assert_eq!(got.as_ref().ok(), Some(&Some(1)), "blow-up at once"),
            _ => assert!(matches!(got, Err((0, _))), "{got:?}"),
        }
    }
}

#[test]
fn a_standing_state_below_the_normal_numbers_is_set_to_rest_the_same_on_both_paths() {
    let p = plant(&[3, 2]);
    let starts = [State::default(); 2];
    let held = [Sample::default(); 2];
    let deflected = |r: f64| {
        let mut s = p.initial_state(&starts).expect("state");
        s.axes[0].set_r(0, r);
        s
    };
    // One step: a subnormal deflection goes to rest; the least normal one does not.
    for (r, rests) in [(1e-310, true), (f64::MIN_POSITIVE, false), (1e-300, false)] {
        let mut s = deflected(r);
        p.step(&mut s, &held, DT).expect("step");
        let zero = s.axes[0].r().iter().all(|v| v.to_bits() == 0);
        assert_eq!(zero, rests, "{r:e}");
    }
    // Standing from just above the least normal number (2.2e-308): the mode decays by
    // e^(-zeta w t), about 8.8/s, so it passes below within 0.3 s; both paths set it to rest
    // at the same sample and agree bit for bit throughout.
    let (mut a, mut b) = (deflected(3e-308), deflected(3e-308));
    let cmds: Vec<Sample> = std::iter::repeat_n(held, 3000).flatten().collect();
    let (want, wc, wh) = one_by_one(&p, &mut b, &cmds);
    let (mut gc, mut gh) = (vec![0.0; cmds.len()], vec![0.0; cmds.len()]);
    let got = p.step_samples(&mut a, &cmds, DT, BLOWUP_M, &mut gc, &mut gh);
    assert_eq!(format!("{want:?}"), format!("{got:?}"));
    assert_eq!(bits(&wc), bits(&gc));
    assert_eq!(bits(&wh), bits(&gh));
    assert_eq!(observed(&p, &a), observed(&p, &b));
    for s in [&a, &b] {
        assert!(
            s.axes[0]
                .r()
                .iter()
                .chain(s.axes[0].rd())
                .all(|v| v.to_bits() == 0)
        );
    }
}
