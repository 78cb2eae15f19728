//! The streaming shaper (settle_planner::shaper::stream) against whole-profile shaping
//! (`Shaper::apply`): the concatenated chunks must equal it to 1e-12 of the motion's
//! scale wherever the chunks are cut, including inside the impulse spacing and inside a
//! velocity-jump bridge; centred alignment is the causal output advanced by the centroid;
//! a shaper change splits the motion between the two shapers.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use settle_planner::firmware::klipper::{KlipperConfig, KlipperPlanner};
use settle_planner::firmware::profiles::{ProfileOptions, ProfileStream};
use settle_planner::firmware::{FirmwarePlanner, LinearMove};
use settle_planner::shaper::stream::{Alignment, AxesShaper, ShaperStream, cut};
use settle_planner::shaper::{Shaper, ShaperType};
use settle_planner::{Profile, Sample, Segment, State, Trajectory};

/// The part of `p` between `t0` and `t1` (s) as a profile starting at `t0`.
fn slice(p: &Profile, t0: f64, t1: f64) -> Profile {
    cut(p, t0, t1).expect("slice")
}

/// One axis: an S-curve ramp, a cruise, a 100 µs velocity-jump bridge (two constant
/// accelerations, as `ProfileStream` writes a corner), a trapezoid ramp down to rest, a
/// pause, and a short move: zero acceleration at both ends.
fn test_profile() -> Profile {
    let j = |d: f64, jerk: f64| Segment::Jerk {
        duration_s: d,
        jerk,
    };
    let a = |d: f64, accel: f64| Segment::Accel {
        duration_s: d,
        accel,
    };
    Profile::new(
        State {
            p: 0.012,
            v: 0.0,
            a: 0.0,
        },
        vec![
            j(0.01, 300.0),
            j(0.02, 0.0),
            j(0.01, -300.0),
            a(0.0, 0.0),
            a(0.0137, 0.0),
            a(50e-6, -40.0),
            a(50e-6, -20.0),
            a(0.0, 0.0),
            a(0.021, 0.0),
            a(0.029, -3.0),
            a(0.0251, 0.0),
            a(0.004, 2.5),
            a(0.004, -2.5),
            a(0.0, 0.0),
            a(0.003, 0.0),
        ],
    )
    .expect("profile")
}

/// Largest magnitudes of position, velocity and acceleration over `p` (sampled).
fn scale(p: &Profile) -> [f64; 3] {
    let n = 2000;
    (0..=n).fold([0.0; 3], |m, k| {
        let s = p.state_at(p.duration_s() * k as f64 / n as f64);
        [
            m[0].max(s.p.abs()),
            m[1].max(s.v.abs()),
            m[2].max(s.a.abs()),
        ]
    })
}

/// Shape `p` as chunks cut at `cuts` (s, increasing, inside the profile), emitting after
/// each chunk as far as the input allows; the chunks with their start times.
fn stream(shaper: &Shaper, align: Alignment, p: &Profile, cuts: &[f64]) -> Vec<(f64, Profile)> {
    let mut st = ShaperStream::new(Some(shaper), align);
    let mut out = Vec::new();
    let mut edges = vec![0.0];
    edges.extend_from_slice(cuts);
    edges.push(p.duration_s());
    for w in edges.windows(2) {
        st.push(w[0], &slice(p, w[0], w[1])).expect("push");
        let until = st.available_until_s();
        out.push(st.emit(until).expect("emit"));
    }
    st.finish();
    let end = st.end_s().expect("end");
    out.push(st.emit(end).expect("emit tail"));
    out
}

/// The chunked output at `t`: the chunk whose span holds `t` (the later one at a cut).
fn chunked_at(chunks: &[(f64, Profile)], t: f64) -> Sample {
    let i = chunks.partition_point(|(t0, _)| *t0 <= t).max(1) - 1;
    let (t0, p) = &chunks[i];
    p.state_at(t - t0)
}

/// Assert `chunks` equal `reference(t)` to `1e-12` of the scales at many instants,
/// among them just either side of every chunk boundary.
fn assert_equal(
    what: &str,
    chunks: &[(f64, Profile)],
    reference: impl Fn(f64) -> Sample,
    span: (f64, f64),
    sc: [f64; 3],
) {
    let mut ts: Vec<f64> = (0..=4000)
        .map(|k| span.0 + (span.1 - span.0) * k as f64 / 4000.0)
        .collect();
    for (t0, p) in chunks {
        for t in [*t0, t0 + 1e-9, t0 + p.duration_s() - 1e-9] {
            if t >= span.0 && t <= span.1 {
                ts.push(t);
            }
        }
    }
    for t in ts {
        let (got, want) = (chunked_at(chunks, t), reference(t));
        // Where the reference's acceleration jumps at `t`, rounding of `t` decides which
        // side it reports: either one-sided limit (read a nanosecond away) is right.
        let (left, right) = (reference(t - 1e-9), reference(t + 1e-9));
        let a_err = [want.a, left.a + left.j * 1e-9, right.a - right.j * 1e-9]
            .iter()
            .map(|a| (got.a - a).abs() / sc[2])
            .fold(f64::INFINITY, f64::min);
        let err = [
            (got.p - want.p).abs() / sc[0],
            (got.v - want.v).abs() / sc[1],
            a_err,
        ];
        assert!(
            err.iter().all(|e| *e <= 1e-12),
            "{what}: t = {t}: got {got:?}, want {want:?} (relative errors {err:?})"
        );
    }
    // The chunks tile the span without gaps.
    for w in chunks.windows(2) {
        assert!(
            (w[0].0 + w[0].1.duration_s() - w[1].0).abs() < 1e-12,
            "{what}: gap"
        );
    }
}

fn shapers() -> Vec<Shaper> {
    vec![
        Shaper::new(ShaperType::MZV, 50.0, 0.1).expect("mzv"),
        Shaper::new(ShaperType::ThreeHumpEi, 61.7, 0.12).expect("3hump_ei"),
        Shaper::new(ShaperType::parse("marlin:zvdd").expect("name"), 43.0, 0.1).expect("zvdd"),
        Shaper::new(ShaperType::parse("rrf:ei2").expect("name"), 38.5, 0.07).expect("ei2"),
    ]
}

/// Cut lists: at segment boundaries, inside the 100 µs bridge (which starts at 0.0537 s),
/// several cuts closer than the impulse spacing, and seeded random ones
/// (`SHAPER_STREAM_CASES` lists, default 4).
fn cut_lists(d: f64) -> Vec<Vec<f64>> {
    let mut lists = vec![
        vec![0.01, 0.03, 0.04, 0.0537, 0.0538],
        vec![0.05372, 0.05376, 0.05381, 0.05389, 0.0539, 0.1],
        vec![0.02, 0.0201, 0.0203, 0.0209, 0.021, 0.06, 0.0601, 0.13],
        vec![0.001],
        vec![],
    ];
    let n: usize = std::env::var("SHAPER_STREAM_CASES")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(4);
    let mut rng = ChaCha8Rng::seed_from_u64(20_240_611);
    for _ in 0..n {
        let k = rng.random_range(1..12);
        let mut cuts: Vec<f64> = (0..k).map(|_| rng.random_range(1e-4..d - 1e-4)).collect();
        cuts.sort_by(f64::total_cmp);
        cuts.dedup();
        lists.push(cuts);
    }
    lists
}

#[test]
fn causal_chunks_equal_whole_profile_shaping() {
    let p = test_profile();
    let d = p.duration_s();
    let sc = scale(&p);
    for shaper in shapers() {
        let whole = shaper.apply(&p).expect("apply");
        for cuts in cut_lists(d) {
            let chunks = stream(&shaper, Alignment::Causal, &p, &cuts);
            let what = format!("{} cut at {cuts:?}", shaper.shaper_type());
            assert_eq!(chunks[0].0, 0.0, "{what}");
            let end = chunks
                .last()
                .map(|(t, c)| t + c.duration_s())
                .expect("some");
            assert!((end - whole.duration_s()).abs() < 1e-12, "{what}: {end}");
            assert_equal(&what, &chunks, |t| whole.state_at(t), (0.0, end), sc);
        }
    }
}

#[test]
fn centred_chunks_are_the_causal_output_advanced_by_the_centroid() {
    let p = test_profile();
    let sc = scale(&p);
    for shaper in shapers() {
        let c: f64 = shaper
            .weights()
            .zip(shaper.times_s())
            .map(|(w, t)| w * t)
            .sum();
        assert!(c > 0.0);
        let whole = shaper.apply(&p).expect("apply");
        let chunks = stream(&shaper, Alignment::Centred, &p, &[0.02, 0.0538, 0.09]);
        assert!((chunks[0].0 + c).abs() < 1e-15, "starts c early");
        let end = chunks
            .last()
            .map(|(t, c)| t + c.duration_s())
            .expect("some");
        assert_equal("centred", &chunks, |t| whole.state_at(t + c), (-c, end), sc);
    }
}

/// `Shaper::apply`'s output `q` at `t`, continued outside its span as the convolution
/// continues it: at its start velocity before (`q(0)` already holds the shaper's delay of
/// the input's straight-line start), at its end velocity after.
fn extended(q: &Profile, t: f64) -> Sample {
    let (s, e, d) = (q.start(), q.end(), q.duration_s());
    let line = |p: f64, v: f64, dt: f64| Sample {
        p: p + v * dt,
        v,
        a: 0.0,
        j: 0.0,
    };
    if t < 0.0 {
        line(s.p, s.v, t)
    } else if t >= d {
        line(e.p, e.v, t - d)
    } else {
        q.state_at(t)
    }
}

#[test]
fn a_shaper_change_splits_the_motion_between_the_shapers() {
    let p = test_profile();
    let sc = scale(&p);
    let shapers = shapers();
    let (a, b) = (&shapers[0], &shapers[1]);
    // At rest (t = 0.11, in the pause) and while cruising (t = 0.047, v = const).
    for switch in [0.11, 0.047] {
        let mut st = ShaperStream::new(Some(a), Alignment::Causal);
        let mut chunks = Vec::new();
        for (t0, t1) in [
            (0.0, 0.03),
            (0.03, switch),
            (switch, 0.13),
            (0.13, p.duration_s()),
        ] {
            st.push(t0, &slice(&p, t0, t1)).expect("push");
            if t1 == switch {
                st.set_shaper(Some(b)).expect("switch");
            }
            let until = st.available_until_s();
            chunks.push(st.emit(until).expect("emit"));
        }
        st.finish();
        let end = st.end_s().expect("end");
        chunks.push(st.emit(end).expect("tail"));
        // Expected: A shapes the motion up to the switch (continued at its velocity
        // there), B the rest, minus the straight line both would otherwise share.
        let before = a.apply(&slice(&p, 0.0, switch)).expect("a");
        let after = b.apply(&slice(&p, switch, p.duration_s())).expect("b");
        let s = p.state_at(switch);
        assert_eq!(s.a, 0.0);
        let c_b: f64 = b.weights().zip(b.times_s()).map(|(w, t)| w * t).sum();
        let reference = |t: f64| {
            let x = extended(&before, t);
            let y = extended(&after, t - switch);
            Sample {
                p: x.p + y.p - (s.p + s.v * (t - switch - c_b)),
                v: x.v + y.v - s.v,
                a: x.a + y.a,
                j: x.j + y.j,
            }
        };
        assert_equal(
            &format!("switch at {switch}"),
            &chunks,
            reference,
            (0.0, end),
            sc,
        );
        // Whatever the switch, the motion ends where the input ends when the switch is at
        // rest; a switch while cruising moves the end by v (c_b - c_a).
        let last = chunks.last().expect("tail");
        let got_end = last.1.end().p;
        let c_a: f64 = a.weights().zip(a.times_s()).map(|(w, t)| w * t).sum();
        let want_end = p.end().p + s.v * (c_b - c_a);
        assert!(
            (got_end - want_end).abs() < 1e-12 * sc[0],
            "{got_end} vs {want_end}"
        );
    }
}

#[test]
fn a_firmware_corner_bridge_is_shaped_like_the_whole_move() {
    // Klipper's 90-degree corner at 5 mm/s: the ProfileStream bridges each axis's speed
    // jump over 100 µs. The profile chunks, and then the same motion re-cut inside the
    // bridge, shaped per axis with different shapers, equal whole-profile shaping.
    let mut k = KlipperPlanner::new(KlipperConfig::new(0.1, 3.0)).expect("config");
    let opts = ProfileOptions {
        max_chunk_s: 0.15,
        ..ProfileOptions::default()
    };
    let mut ps = ProfileStream::new(opts).expect("options");
    let moves = [
        LinearMove::new([0.0, 0.0, 0.0], [0.02, 0.0, 0.0], 0.0, 0.1),
        LinearMove::new([0.02, 0.0, 0.0], [0.02, 0.02, 0.0], 0.0, 0.1),
    ];
    let mut corner_t = 0.0;
    for m in &moves {
        k.push(m).expect("move");
    }
    k.finish();
    while let Some(pm) = k.pop() {
        if pm.seq == 1 {
            corner_t = pm.start_time_s;
        }
        ps.push(&pm).expect("push");
    }
    ps.finish().expect("finish");
    let chunks: Vec<_> = std::iter::from_fn(|| ps.pop()).collect();
    assert!(chunks.len() >= 2);
    let shapers = [
        Some(Shaper::new(ShaperType::MZV, 48.0, 0.1).expect("x")),
        Some(Shaper::new(ShaperType::Zvd, 36.0, 0.1).expect("y")),
        None,
        None,
    ];
    // Whole profile per axis: the chunks' segments one after the other.
    let t_start = chunks[0].start_time_s;
    let whole: Vec<Profile> = (0..4)
        .map(|i| {
            let segs = chunks
                .iter()
                .flat_map(|c| c.trajectory.axes()[i].segments().to_vec())
                .collect();
            Profile::new(chunks[0].trajectory.axes()[i].start(), segs).expect("whole")
        })
        .collect();
    let d = whole[0].duration_s();
    let w = opts.jump_window_s;
    let recut = [
        corner_t - t_start - 0.5 * w + 1e-6,
        corner_t - t_start,
        corner_t - t_start + 0.3 * w,
    ];
    for cuts in [None, Some(recut)] {
        let mut axes = AxesShaper::new(&shapers, Alignment::Causal);
        let mut out = Vec::new();
        match cuts {
            None => {
                for c in &chunks {
                    axes.push(c.start_time_s - t_start, &c.trajectory)
                        .expect("push");
                    let until = axes.available_until_s();
                    out.push(axes.emit(until).expect("emit"));
                }
            }
            Some(cuts) => {
                let mut edges = vec![0.0];
                edges.extend_from_slice(&cuts);
                edges.push(d);
                for e in edges.windows(2) {
                    let tr = Trajectory::new(whole.iter().map(|p| slice(p, e[0], e[1])).collect())
                        .expect("chunk");
                    axes.push(e[0], &tr).expect("push");
                    let until = axes.available_until_s();
                    out.push(axes.emit(until).expect("emit"));
                }
            }
        }
        axes.finish();
        let end = axes.end_s().expect("end");
        out.push(axes.emit(end).expect("tail"));
        for (i, s) in shapers.iter().enumerate() {
            let reference = match s {
                Some(s) => s.apply(&whole[i]).expect("apply"),
                None => whole[i].clone(),
            };
            let per_axis: Vec<(f64, Profile)> = out
                .iter()
                .map(|(t0, tr)| (*t0, tr.axes()[i].clone()))
                .collect();
            let sc = scale(&whole[i]).map(|x| x.max(1e-12));
            assert_equal(
                &format!("axis {i}, cuts {cuts:?}"),
                &per_axis,
                |t| reference.state_at(t),
                (0.0, end),
                sc,
            );
        }
    }
}

#[test]
fn misuse_is_refused() {
    let s = Shaper::new(ShaperType::Zv, 40.0, 0.1).expect("zv");
    let mut st = ShaperStream::new(Some(&s), Alignment::Causal);
    assert!(st.emit(0.0).is_err(), "emit before input");
    let p = test_profile();
    st.push(0.0, &slice(&p, 0.0, 0.05)).expect("push");
    assert!(st.emit(0.06).is_err(), "emit beyond the input");
    assert!(st.push(0.07, &slice(&p, 0.07, 0.08)).is_err(), "gap");
    st.finish();
    assert!(
        st.push(0.05, &slice(&p, 0.05, 0.08)).is_err(),
        "after finish"
    );
    assert!(st.set_shaper(None).is_err(), "change after finish");
}
