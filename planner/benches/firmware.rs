//! Firmware planners: moves planned per second on a long synthetic print (random printing
//! moves with extrusion, travels, retractions and layer changes on a 100 mm bed), for
//! Klipper, Marlin (trapezoid and S-curve) and RepRapFirmware, and the same plans turned
//! into per-axis profile chunks.
//!
//! Peak memory for a job of N moves: run this binary with `FIRMWARE_RSS=klipper` (or
//! `marlin`, `rrf`) and `FIRMWARE_RSS_MOVES=N`; it streams the job through the planner and
//! the profile stream, taking every output as it comes, and prints the peak RSS.

use std::hint::black_box;

use criterion::{Criterion, Throughput, criterion_group};
use settle_planner::firmware::klipper::{KlipperConfig, KlipperPlanner};
use settle_planner::firmware::marlin::{MarlinConfig, MarlinPlanner};
use settle_planner::firmware::profiles::{ProfileOptions, ProfileStream};
use settle_planner::firmware::rrf::{RrfConfig, RrfPlanner};
use settle_planner::firmware::{FirmwarePlanner, LinearMove};

const MM: f64 = 1e-3;

/// Move `i` of the synthetic print (deterministic, computed on the fly).
struct Job {
    x: u64,
    pos: [f64; 3],
    i: usize,
}

impl Job {
    fn new() -> Self {
        Self {
            x: 42,
            pos: [50.0 * MM, 50.0 * MM, 0.2 * MM],
            i: 0,
        }
    }

    fn rand(&mut self) -> f64 {
        self.x = (6_364_136_223_846_793_005u64.wrapping_mul(self.x))
            .wrapping_add(1_442_695_040_888_963_407);
        (self.x >> 11) as f64 / (1u64 << 53) as f64
    }
}

impl Iterator for Job {
    type Item = LinearMove;
    fn next(&mut self) -> Option<LinearMove> {
        self.i += 1;
        let kind = self.rand();
        let start = self.pos;
        let mv = if kind < 0.05 {
            // Retract or unretract in place.
            LinearMove::new(
                start,
                start,
                if kind < 0.025 { -0.8 * MM } else { 0.8 * MM },
                40.0 * MM,
            )
        } else {
            // Short printing segments mostly, some long ones and travels.
            let len = if self.rand() < 0.8 {
                0.2 + 2.0 * self.rand()
            } else {
                5.0 + 20.0 * self.rand()
            } * MM;
            let ang = std::f64::consts::TAU * self.rand();
            let mut end = [
                (start[0] + len * ang.cos()).clamp(0.0, 0.1),
                (start[1] + len * ang.sin()).clamp(0.0, 0.1),
                start[2],
            ];
            if self.i.is_multiple_of(500) {
                end[2] += 0.2 * MM;
            }
            let travel = kind > 0.9;
            let d = ((end[0] - start[0]).powi(2) + (end[1] - start[1]).powi(2)).sqrt();
            let e = if travel { 0.0 } else { 0.033 * d };
            let speed = if travel {
                250.0
            } else {
                60.0 + 90.0 * self.rand()
            } * MM;
            LinearMove::new(start, end, e, speed)
        };
        self.pos = mv.end_m;
        Some(mv)
    }
}

fn klipper() -> Box<dyn FirmwarePlanner> {
    let mut c = KlipperConfig::new(0.3, 5.0);
    c.max_z_velocity_m_s = 0.015;
    c.max_z_accel_m_s2 = 0.1;
    Box::new(KlipperPlanner::new(c).expect("config"))
}

fn marlin(s_curve: bool) -> Box<dyn FirmwarePlanner> {
    let mut c = MarlinConfig::new();
    c.max_feedrate_m_s[2] = 0.015;
    c.s_curve = s_curve;
    Box::new(MarlinPlanner::new(c).expect("config"))
}

fn rrf() -> Box<dyn FirmwarePlanner> {
    let c = RrfConfig {
        max_feedrate_m_s: [0.3, 0.3, 0.015, 0.1],
        max_accel_m_s2: [5.0, 5.0, 0.2, 5.0],
        ..RrfConfig::new()
    };
    Box::new(RrfPlanner::new(c).expect("config"))
}

/// Plan `n` moves, taking every planned move as it comes; with `profiles`, also turn
/// them into profile chunks. Returns the print time.
fn run(mut p: Box<dyn FirmwarePlanner>, n: usize, profiles: bool) -> f64 {
    let mut stream = ProfileStream::new(ProfileOptions::default()).expect("options");
    let mut segments = 0usize;
    let mut drain = |p: &mut dyn FirmwarePlanner, stream: &mut ProfileStream| {
        while let Some(m) = p.pop() {
            if profiles {
                stream.push(&m).expect("profile");
                while let Some(c) = stream.pop() {
                    segments += c.trajectory.axes()[0].segments().len();
                }
            }
        }
    };
    for m in Job::new().take(n) {
        p.push(&m).expect("move");
        drain(p.as_mut(), &mut stream);
    }
    p.finish();
    drain(p.as_mut(), &mut stream);
    black_box(segments);
    p.print_time_s()
}

fn bench(c: &mut Criterion) {
    const N: usize = 20_000;
    let mut g = c.benchmark_group("firmware_plan_20000_moves");
    g.throughput(Throughput::Elements(N as u64));
    g.sample_size(10);
    g.bench_function("klipper", |b| b.iter(|| run(klipper(), N, false)));
    g.bench_function("marlin", |b| b.iter(|| run(marlin(false), N, false)));
    g.bench_function("marlin_s_curve", |b| b.iter(|| run(marlin(true), N, false)));
    g.bench_function("rrf", |b| b.iter(|| run(rrf(), N, false)));
    g.bench_function("klipper_and_profiles", |b| {
        b.iter(|| run(klipper(), N, true))
    });
    g.bench_function("marlin_s_curve_and_profiles", |b| {
        b.iter(|| run(marlin(true), N, true))
    });
    g.finish();
}

criterion_group!(benches, bench);

fn peak_rss_kib() -> Option<u64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    line.split_whitespace().nth(1)?.parse().ok()
}

fn main() {
    if let Some(which) = std::env::var_os("FIRMWARE_RSS") {
        let n: usize = std::env::var("FIRMWARE_RSS_MOVES")
            .ok()
            .and_then(|s| s.parse().ok())
            .unwrap_or(1_000_000);
        let p = match which.to_str() {
            Some("marlin") => marlin(true),
            Some("rrf") => rrf(),
            _ => klipper(),
        };
        let t = run(p, n, true);
        println!(
            "{:?}: {n} moves, print time {t:.1} s, peak RSS {} KiB",
            which,
            peak_rss_kib().unwrap_or(0)
        );
        return;
    }
    benches();
    Criterion::default().configure_from_args().final_summary();
}
