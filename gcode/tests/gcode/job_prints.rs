//! The shipped prints through every firmware's job, whole and by layer range.

use std::collections::BTreeSet;

use settle_gcode::job::{Job, JobChunk, JobConfig, ShaperSetting};
use settle_gcode::{Reader, ReaderOptions};
use settle_planner::firmware::Firmware;
use settle_planner::shaper::ShaperType;

use crate::job_util::{MM, assert_contiguous, assert_rel, at};
use crate::print_path;

const PRINTS: [&str; 3] = ["cube_layer.gcode", "ringing_tower.gcode", "arc_part.gcode"];

/// The firmware's defaults, with input shapers on X and Y in its own family.
fn shaped(fw: Firmware) -> JobConfig {
    let mut c = JobConfig::defaults(fw).expect("defaults");
    let kinds = match fw {
        Firmware::Marlin => [
            ShaperType::parse("marlin:zvd").expect("name"),
            ShaperType::parse("marlin:mzv").expect("name"),
        ],
        Firmware::Rrf => [
            ShaperType::parse("rrf:zvd").expect("name"),
            ShaperType::parse("rrf:ei2").expect("name"),
        ],
        _ => [ShaperType::MZV, ShaperType::EI],
    };
    for (i, (kind, f)) in kinds.into_iter().zip([48.0, 41.0]).enumerate() {
        c.shapers[i] = Some(ShaperSetting {
            shaper_type: kind,
            frequency_hz: f,
            damping_ratio: 0.1,
        });
    }
    c
}

fn run_file(
    name: &str,
    cfg: JobConfig,
    layers: Option<(u32, u32)>,
) -> (Vec<JobChunk>, Job<settle_gcode::FileInput>) {
    let mut job = Job::open(print_path(name), cfg).expect("open");
    if let Some((a, b)) = layers {
        job = job.with_layers(a..=b).expect("layers");
    }
    let chunks = job.by_ref().collect::<Result<Vec<_>, _>>().expect("chunks");
    (chunks, job)
}

/// Where the reader leaves the toolhead (mm).
fn final_position(name: &str, cfg: &JobConfig) -> [f64; 3] {
    let mut r = Reader::open(print_path(name), ReaderOptions::new(cfg.dialect)).expect("open");
    for e in r.by_ref() {
        e.expect("event");
    }
    let p = r.position();
    [p.x_mm, p.y_mm, p.z_mm]
}

#[test]
fn every_print_through_every_firmware() {
    for name in PRINTS {
        for fw in Firmware::PRINTERS {
            let mut cfg = shaped(fw);
            if (name, fw) == ("arc_part.gcode", Firmware::Klipper) {
                // Klipper refuses R-form arcs; the job stops at the line that has one.
                let mut job = Job::open(print_path(name), cfg.clone()).expect("open");
                let err = job.by_ref().find_map(Result::err).expect("refused");
                assert_eq!(err.line(), Some(15), "{err}");
                // Read as Marlin G-code, it plans with Klipper's planner.
                cfg.dialect = settle_gcode::Dialect::Marlin;
            }
            let what = format!("{name} on {fw}");
            let end_mm = final_position(name, &cfg);
            let (chunks, mut job) = run_file(name, cfg, None);
            job.run_to_end().expect("end");
            let s = job.summary();
            assert!(s.complete && s.moves > 5, "{what}");
            assert_contiguous(&chunks);
            // The shaped motion ends at rest where the file ends.
            let last = chunks.last().expect("chunks");
            for (i, p) in last.trajectory.axes()[..3].iter().enumerate() {
                let e = p.end();
                assert!(
                    (e.p - end_mm[i] * MM).abs() < 1e-9,
                    "{what}: axis {i} ends at {}",
                    e.p
                );
                assert!(e.v.abs() < 1e-12, "{what}: axis {i} still moving");
            }
            // The print time is the planner's clock, and the layers divide it.
            let per_layer: f64 = s.layers.iter().map(|l| l.duration_s).sum();
            assert_rel(&what, per_layer, s.print_time_s, 1e-12);
            assert!(last.end_time_s() >= s.print_time_s, "{what}");
            // Every move is listed by some chunk, with its planned span inside the print.
            let listed: BTreeSet<u64> = chunks
                .iter()
                .flat_map(|c| c.moves.iter().map(|m| m.index))
                .collect();
            assert_eq!(listed.len() as u64, s.moves, "{what}");
            for c in &chunks {
                for m in &c.moves {
                    assert!(m.start_time_s <= c.end_time_s() && m.end_time_s() >= c.start_time_s);
                    assert!(m.end_time_s() <= s.print_time_s + 1e-9, "{what}");
                }
            }
        }
    }
}

#[test]
fn a_layer_range_is_the_whole_job_cut_at_its_moves() {
    // Layers 2 and 3 of the ringing tower: chunks from the start of layer 2's first move
    // to the start of layer 4's, equal to the whole job's motion there (the shapers see
    // the same input: the look-back covers their duration).
    for fw in Firmware::PRINTERS {
        let cfg = shaped(fw);
        let (whole, mut whole_job) = run_file("ringing_tower.gcode", cfg.clone(), None);
        whole_job.run_to_end().expect("end");
        let (part, mut part_job) = run_file("ringing_tower.gcode", cfg, Some((2, 3)));
        assert_contiguous(&part);
        let moves: Vec<_> = whole.iter().flat_map(|c| c.moves.iter().cloned()).collect();
        let t0 = moves
            .iter()
            .filter(|m| m.layer == 2)
            .map(|m| m.start_time_s)
            .fold(f64::INFINITY, f64::min);
        let t1 = moves
            .iter()
            .filter(|m| m.layer == 4)
            .map(|m| m.start_time_s)
            .fold(f64::INFINITY, f64::min);
        let first = part.first().expect("chunks");
        let last = part.last().expect("chunks");
        assert_eq!(first.start_time_s, t0, "{fw}");
        assert!(
            (last.end_time_s() - t1).abs() < 1e-12,
            "{fw}: {} vs {t1}",
            last.end_time_s()
        );
        assert!(
            part.iter()
                .all(|c| c.moves.iter().all(|m| m.layer >= 1 && m.layer <= 4))
        );
        for k in 0..=2000 {
            let t = t0 + (t1 - t0) * k as f64 / 2000.0;
            let (a, b) = (at(&part, t), at(&whole, t));
            for i in 0..3 {
                assert!(
                    (a[i].p - b[i].p).abs() < 1e-12 && (a[i].v - b[i].v).abs() < 1e-9,
                    "{fw} t {t} axis {i}: {:?} vs {:?}",
                    a[i],
                    b[i]
                );
            }
        }
        // The rest of the file still plans: the same print time and account.
        assert!(!part_job.summary().complete);
        part_job.run_to_end().expect("end");
        let (sp, sw) = (part_job.summary(), whole_job.summary());
        assert_eq!(sp.print_time_s, sw.print_time_s, "{fw}");
        assert_eq!(sp.layers, sw.layers, "{fw}");
    }
}

/// With a pre-roll the range's chunks start that long before its first move (layer 3 of
/// the ringing tower starts 6.8 s in, so 1.5 s fit), list the moves they carry, and are the
/// whole job's motion throughout; the pre-roll of the first layers is cut at the start
/// of the file.
#[test]
fn a_pre_roll_starts_the_range_earlier_with_the_whole_jobs_motion() {
    for fw in Firmware::PRINTERS {
        let cfg = shaped(fw);
        let (whole, _) = run_file("ringing_tower.gcode", cfg.clone(), None);
        let moves: Vec<_> = whole.iter().flat_map(|c| c.moves.iter().cloned()).collect();
        let start = |layer: u32| {
            moves
                .iter()
                .filter(|m| m.layer == layer)
                .map(|m| m.start_time_s)
                .fold(f64::INFINITY, f64::min)
        };
        let (t0, t1) = (start(3), start(4));
        let pre = 1.5;
        let mut job = Job::open(print_path("ringing_tower.gcode"), cfg.clone())
            .expect("open")
            .with_layers(3..=3)
            .and_then(|j| j.with_preroll_s(pre))
            .expect("range");
        let part = job.by_ref().collect::<Result<Vec<_>, _>>().expect("chunks");
        assert_contiguous(&part);
        let first = part.first().expect("chunks");
        assert!((first.start_time_s - (t0 - pre)).abs() < 1e-12, "{fw}");
        assert!((part.last().expect("chunks").end_time_s() - t1).abs() < 1e-12);
        assert!(first.moves.iter().any(|m| m.layer == 2), "{fw}");
        // The range's chunks start inside a stretch the whole job emits in one piece, so
        // positions are summed from another start: they differ by rounding, at most a few
        // pm over the 1.5 s (settle's planner); 1 nm is far above that and far below any
        // vibration measured on them.
        for k in 0..=2000 {
            let t = t0 - pre + (t1 - t0 + pre) * k as f64 / 2000.0;
            let (a, b) = (at(&part, t), at(&whole, t));
            for i in 0..3 {
                assert!(
                    (a[i].p - b[i].p).abs() < 1e-9 && (a[i].v - b[i].v).abs() < 1e-9,
                    "{fw} t {t} axis {i}: {:?} vs {:?}",
                    a[i],
                    b[i]
                );
            }
        }
        // Layer 1 starts earlier than 10 s: its pre-roll starts with the file.
        let (part, _) = {
            let mut job = Job::open(print_path("ringing_tower.gcode"), cfg)
                .expect("open")
                .with_preroll_s(10.0)
                .and_then(|j| j.with_layers(1..=1))
                .expect("range");
            let c = job.by_ref().collect::<Result<Vec<_>, _>>().expect("chunks");
            (c, job)
        };
        assert_eq!(
            part[0].start_time_s.to_bits(),
            whole[0].start_time_s.to_bits(),
            "{fw}"
        );
    }
}

#[test]
fn homing_after_motion_travels_home_continuously() {
    // G28 after moves: homing is not simulated, the toolhead travels to 0 on the homed
    // axes, so the motion stays continuous and the move count includes that travel.
    let text = "G1 X20 Y10 F6000\nG28 X\nG1 Y30\n";
    for fw in Firmware::PRINTERS {
        let (chunks, s) = crate::job_util::run(text, JobConfig::defaults(fw).expect("defaults"));
        assert_contiguous(&chunks);
        assert_eq!(s.moves, 3, "{fw}");
        let end = chunks.last().expect("chunks").trajectory.axes();
        assert!(end[0].end().p.abs() < 1e-12 && (end[1].end().p - 30.0 * MM).abs() < 1e-12);
        // No position jump anywhere: bridged over 100 µs it would take ~1e6 m/s^2; corners'
        // speed jumps (5-15 mm/s) take 50-150 m/s^2.
        let (t0, t1) = (
            chunks[0].start_time_s,
            chunks.last().expect("c").end_time_s(),
        );
        let n = ((t1 - t0) / 10e-6) as usize;
        for k in 0..n {
            let s = at(&chunks, t0 + k as f64 * 10e-6);
            assert!(s[..3].iter().all(|s| s.a.abs() < 1000.0), "{fw}: {s:?}");
        }
    }
}
