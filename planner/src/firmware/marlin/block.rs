//! One Marlin block: `Planner::_populate_block` (planner.cpp) in SI units.

use super::config::{JdSmallSegments, MarlinConfig, MarlinJerk};
use crate::firmware::Kinematics;

/// A planned block (planner.h `block_t`), speeds squared in m^2/s^2.
#[derive(Debug, Clone, Copy)]
pub(super) struct Block {
    /// Position in the block buffer's history.
    pub(super) id: u64,
    /// Input move this block ends.
    pub(super) seq: u64,
    /// Head X, Y, Z and E at the start (m, on the step grid).
    pub(super) start_m: [f64; 4],
    /// Head X, Y, Z and E displacement per metre of `millimeters`.
    pub(super) axes_r: [f64; 4],
    /// `millimeters` (m): the head's XYZ travel, or the extruder's for E-only blocks.
    pub(super) millimeters: f64,
    /// `step_event_count`: the largest step count of any motor.
    pub(super) step_event_count: f64,
    /// `nominal_rate` (steps/s).
    pub(super) nominal_rate: f64,
    pub(super) nominal_speed_sqr: f64,
    /// `acceleration_steps_per_s2`.
    pub(super) accel_steps: f64,
    /// `acceleration` (m/s^2).
    pub(super) acceleration: f64,
    pub(super) max_entry_speed_sqr: f64,
    pub(super) entry_speed_sqr: f64,
    pub(super) nominal_length: bool,
    pub(super) recalculate: bool,
}

/// What Marlin keeps between blocks to compute the next junction (`prev_unit_vec`,
/// `previous_speed`, `previous_nominal_speed_sqr`, `previous_safe_speed`).
#[derive(Debug, Clone, Copy, Default)]
pub(super) struct JunctionState {
    prev_unit_vec: [f64; 4],
    previous_speed: [f64; 4],
    previous_nominal_speed_sqr: f64,
    previous_safe_speed: f64,
}

/// `UNEAR_ZERO` of a speed squared: below 1e-6 mm^2/s^2.
const NEAR_ZERO_V2: f64 = 1e-12;
/// Blocks shorter than 1 mm get the small-segment arc limit.
const SMALL_SEGMENT_M: f64 = 1e-3;
/// `SLOWDOWN_DIVISOR`.
const SLOWDOWN_DIVISOR: usize = 2;

impl Block {
    /// `_populate_block` for a move to `target` (X, Y, Z, E in m) at `speed` (m/s), with
    /// `moves_queued` non-busy blocks ahead of it. Returns `None` (and leaves the position
    /// alone, so the steps join the next block) for a block of too few steps.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn populate(
        cfg: &MarlinConfig,
        js: &mut JunctionState,
        position: &mut [i64; 4],
        target: [f64; 4],
        speed: f64,
        moves_queued: usize,
        seq: u64,
        id: u64,
    ) -> Option<Self> {
        let spm = cfg.steps_per_m;
        let tgt: [i64; 4] = std::array::from_fn(|i| (target[i] * spm[i]).round() as i64);
        let d: [i64; 4] = std::array::from_fn(|i| tgt[i] - position[i]);
        let head_m = [
            d[0] as f64 / spm[0],
            d[1] as f64 / spm[1],
            d[2] as f64 / spm[2],
            d[3] as f64 / spm[3],
        ];
        // Motor steps and the distance each motor moves (`steps_dist_mm`).
        let (steps, motor_m): ([f64; 4], [f64; 4]) = match cfg.kinematics {
            Kinematics::Cartesian => (d.map(|x| x.unsigned_abs() as f64), head_m),
            Kinematics::CoreXy => (
                [
                    (d[0] + d[1]).unsigned_abs() as f64,
                    (d[0] - d[1]).unsigned_abs() as f64,
                    d[2].unsigned_abs() as f64,
                    d[3].unsigned_abs() as f64,
                ],
                [
                    (d[0] + d[1]) as f64 / spm[0],
                    (d[0] - d[1]) as f64 / spm[1],
                    head_m[2],
                    head_m[3],
                ],
            ),
        };
        let min_steps = f64::from(cfg.min_steps_per_segment);
        let xyz_few = steps[..3].iter().all(|&s| s < min_steps);
        let millimeters = if xyz_few {
            head_m[3].abs()
        } else {
            (head_m[0] * head_m[0] + head_m[1] * head_m[1] + head_m[2] * head_m[2]).sqrt()
        };
        let n = steps.iter().fold(0.0f64, |m, &s| m.max(s));
        if n < min_steps {
            return None;
        }
        let esteps = steps[3];
        let fr = speed.max(if esteps > 0.0 {
            cfg.min_feedrate_m_s
        } else {
            cfg.min_travel_feedrate_m_s
        });
        let mut inverse_secs = fr / millimeters;
        // SLOWDOWN: stretch short blocks while the queue runs low.
        if cfg.slowdown
            && (2..=cfg.block_buffer_size / SLOWDOWN_DIVISOR - 1).contains(&moves_queued)
        {
            let segment_time_us = (1e6 / inverse_secs).round() as i64;
            let min_us = (cfg.min_segment_time_s * 1e6).round() as i64;
            let time_diff = min_us - segment_time_us;
            if time_diff > 0 {
                let nst = segment_time_us + 2 * time_diff / moves_queued as i64;
                inverse_secs = 1e6 / nst as f64;
            }
        }
        let mut nominal_speed_sqr = (millimeters * inverse_secs).powi(2);
        let mut nominal_rate = (n * inverse_secs).ceil();
        // Per-axis speed limits (M203), on the motors.
        let mut current_speed = motor_m.map(|m| m * inverse_secs);
        let mut speed_factor = 1.0f64;
        for (cs, max) in current_speed.iter().zip(cfg.max_feedrate_m_s) {
            if cs.abs() > max {
                speed_factor = speed_factor.min(max / cs.abs());
            }
        }
        if speed_factor < 1.0 {
            current_speed = current_speed.map(|c| c * speed_factor);
            nominal_rate = (nominal_rate * speed_factor).floor();
            nominal_speed_sqr *= speed_factor * speed_factor;
        }
        // Acceleration in steps/s^2, limited per axis (M201).
        let steps_per_m = n / millimeters;
        let mut accel;
        if steps[..3].iter().all(|&s| s == 0.0) {
            accel = (cfg.retract_accel_m_s2 * steps_per_m).ceil();
        } else {
            let a = if esteps > 0.0 {
                cfg.print_accel_m_s2
            } else {
                cfg.travel_accel_m_s2
            };
            accel = (a * steps_per_m).ceil();
            for i in 0..4 {
                let max_steps = (cfg.max_accel_m_s2[i] * spm[i]).floor();
                if steps[i] > 0.0 && max_steps < accel {
                    accel = accel.min((max_steps * n / steps[i]).floor());
                }
            }
        }
        let acceleration = accel / steps_per_m;

        let max_entry_speed_sqr = match cfg.jerk {
            MarlinJerk::JunctionDeviation {
                deviation_m,
                small_segments,
            } => js.junction_deviation(
                cfg,
                motor_m,
                esteps > 0.0,
                millimeters,
                acceleration,
                nominal_speed_sqr,
                moves_queued,
                deviation_m,
                small_segments,
            ),
            MarlinJerk::Classic {
                max_jerk_m_s,
                travel_extra_xy_jerk_m_s,
            } => {
                let extra = if d[3] <= 0 {
                    travel_extra_xy_jerk_m_s
                } else {
                    0.0
                };
                js.classic_jerk(
                    current_speed,
                    nominal_speed_sqr,
                    moves_queued,
                    max_jerk_m_s,
                    extra,
                )
            }
        };
        let min_v2 = cfg.minimum_planner_speed_m_s.powi(2);
        let v_allowable_sqr = min_v2 + 2.0 * acceleration * millimeters;
        js.previous_speed = current_speed;
        js.previous_nominal_speed_sqr = nominal_speed_sqr;

        let start_m: [f64; 4] = std::array::from_fn(|i| position[i] as f64 / spm[i]);
        *position = tgt;
        Some(Self {
            id,
            seq,
            start_m,
            axes_r: head_m.map(|h| h / millimeters),
            millimeters,
            step_event_count: n,
            nominal_rate,
            nominal_speed_sqr,
            accel_steps: accel,
            acceleration,
            max_entry_speed_sqr,
            entry_speed_sqr: min_v2,
            nominal_length: nominal_speed_sqr <= v_allowable_sqr,
            recalculate: true,
        })
    }
}

impl JunctionState {
    /// The junction-deviation entry limit (m^2/s^2) of a block moving `motor_m` (m per
    /// motor and E).
    #[allow(clippy::too_many_arguments)]
    fn junction_deviation(
        &mut self,
        cfg: &MarlinConfig,
        motor_m: [f64; 4],
        extrudes: bool,
        millimeters: f64,
        acceleration: f64,
        nominal_speed_sqr: f64,
        moves_queued: usize,
        deviation_m: f64,
        small_segments: JdSmallSegments,
    ) -> f64 {
        let unit_vec = if cfg.kinematics == Kinematics::CoreXy || extrudes {
            normalize(motor_m)
        } else {
            motor_m.map(|m| m / millimeters)
        };
        let mut vmax_junction_sqr = 0.0;
        if moves_queued > 0 && self.previous_nominal_speed_sqr >= NEAR_ZERO_V2 {
            let p = self.prev_unit_vec;
            let mut cos_theta = -(0..4).map(|i| p[i] * unit_vec[i]).sum::<f64>();
            if cos_theta > 0.999_999 {
                // A reversal: stop.
                vmax_junction_sqr = cfg.minimum_planner_speed_m_s.powi(2);
            } else {
                cos_theta = cos_theta.max(-0.999_999);
                let junction_unit = normalize(std::array::from_fn(|i| unit_vec[i] - p[i]));
                let mut junction_accel = acceleration;
                for (u, max) in junction_unit.iter().zip(cfg.max_accel_m_s2) {
                    if *u != 0.0 && junction_accel * u.abs() > max {
                        junction_accel = (max / u).abs();
                    }
                }
                let sin_half = (0.5 * (1.0 - cos_theta)).sqrt();
                vmax_junction_sqr = junction_accel * deviation_m * sin_half / (1.0 - sin_half);
                if millimeters < SMALL_SEGMENT_M && cos_theta < -std::f64::consts::FRAC_1_SQRT_2 {
                    // Short segments of a curve: the speed of the arc through them.
                    let theta = match small_segments {
                        JdSmallSegments::Off => None,
                        JdSmallSegments::Acos => Some((-cos_theta).acos()),
                        JdSmallSegments::LookupTable => Some(acos_lookup(-cos_theta)),
                    };
                    if let Some(theta) = theta {
                        vmax_junction_sqr =
                            vmax_junction_sqr.min(millimeters * junction_accel / theta);
                    }
                }
            }
            vmax_junction_sqr = vmax_junction_sqr
                .min(nominal_speed_sqr)
                .min(self.previous_nominal_speed_sqr);
        }
        self.prev_unit_vec = unit_vec;
        vmax_junction_sqr
    }

    /// The classic-jerk entry limit (m^2/s^2): the largest junction speed at which no
    /// axis changes speed by more than its jerk, or the "safe speed" from which the block
    /// could start from rest.
    fn classic_jerk(
        &mut self,
        current_speed: [f64; 4],
        nominal_speed_sqr: f64,
        moves_queued: usize,
        max_jerk: [f64; 4],
        extra_xy: f64,
    ) -> f64 {
        let nominal_speed = nominal_speed_sqr.sqrt();
        let maxj = |i: usize| max_jerk[i] + if i < 2 { extra_xy } else { 0.0 };
        let mut safe_speed = nominal_speed;
        for (i, cs) in current_speed.iter().enumerate() {
            let jerk = cs.abs();
            if jerk > maxj(i) {
                safe_speed = safe_speed.min(nominal_speed * maxj(i) / jerk);
            }
        }
        let vmax_junction = if moves_queued > 0 && self.previous_nominal_speed_sqr >= NEAR_ZERO_V2 {
            let previous_nominal_speed = self.previous_nominal_speed_sqr.sqrt();
            let (mut vmax, smaller_speed_factor) = if nominal_speed < previous_nominal_speed {
                (nominal_speed, nominal_speed / previous_nominal_speed)
            } else {
                (previous_nominal_speed, 1.0)
            };
            let mut v_factor = 1.0;
            let mut limited = false;
            for (axis, (&prev, &cur)) in self.previous_speed.iter().zip(&current_speed).enumerate()
            {
                let mut v_exit = prev * smaller_speed_factor;
                let mut v_entry = cur;
                if limited {
                    v_exit *= v_factor;
                    v_entry *= v_factor;
                }
                // Coasting in the same direction, or reversing.
                let jerk = if v_exit > v_entry {
                    if v_entry > 0.0 || v_exit < 0.0 {
                        v_exit - v_entry
                    } else {
                        v_exit.max(-v_entry)
                    }
                } else if v_entry < 0.0 || v_exit > 0.0 {
                    v_entry - v_exit
                } else {
                    (-v_exit).max(v_entry)
                };
                if jerk > maxj(axis) {
                    v_factor *= maxj(axis) / jerk;
                    limited = true;
                }
            }
            if limited {
                vmax *= v_factor;
            }
            let threshold = vmax * 0.99;
            if self.previous_safe_speed > threshold && safe_speed > threshold {
                vmax = safe_speed;
            }
            // Marlin stops here; an entry above the previous block's nominal speed would
            // break its trapezoid, so it is capped.
            vmax.min(previous_nominal_speed)
        } else {
            safe_speed
        };
        self.previous_safe_speed = safe_speed;
        vmax_junction * vmax_junction
    }
}

/// `normalize_junction_vector`: unit length over the non-zero components.
fn normalize(v: [f64; 4]) -> [f64; 4] {
    let mag2: f64 = v.iter().filter(|x| **x != 0.0).map(|x| x * x).sum();
    let inv = 1.0 / mag2.sqrt();
    v.map(|x| x * inv)
}

/// Marlin's `JD_USE_LOOKUP_TABLE` approximation of `acos(t)` for `0.5 < t < 1`, where the
/// small-segment limit applies: 16 chords of `acos` between `t_i = 1 - 2^-i` and the
/// midpoint to 1, scaled by 1.00751495 to centre the error (the generator in planner.cpp's
/// comment, which reproduces its published table, e.g. slope -1.03145837 and intercept
/// 1.57079637 for the first piece).
fn acos_lookup(t: f64) -> f64 {
    const C: f64 = 1.007_514_95;
    const COUNT: usize = 16;
    // Piece index: the leading zeros of (1 - t) 2^15 as a 16-bit integer, minus one.
    let v = ((1.0 - t) * 32768.0) as u32 & 0xffff;
    let idx = if t < 0.000_000_03 {
        0
    } else if v == 0 {
        // clz(0) is 32 on ARM: the last piece.
        COUNT - 1
    } else {
        (v.leading_zeros() as usize)
            .saturating_sub(17)
            .min(COUNT - 1)
    };
    let x0 = 1.0 - 0.5f64.powi(idx as i32);
    let y0 = x0.acos() * if idx == 0 { 1.0 } else { C };
    let (x1, y1) = if idx < COUNT - 1 {
        let x1 = 0.5 * x0 + 0.5;
        (x1, x1.acos() * C)
    } else {
        // The firmware's float literal 0.999999f.
        let x1 = f64::from(0.999_999f32);
        (x1, x1.acos())
    };
    let k = (y0 - y1) / (x0 - x1);
    let b = (y1 * x0 - y0 * x1) / (x0 - x1);
    t * k + b
}

#[cfg(test)]
mod tests {
    use super::acos_lookup;

    #[test]
    fn lookup_table_reproduces_marlins_published_pieces() {
        // planner.cpp's jd_lut_k / jd_lut_b: piece 0 (t in (0, 0.5]) has slope
        // -1.03145837 and intercept 1.57079637; piece 1 slope -1.30760646, intercept
        // 1.70887053; piece 15 slope -218.532821, intercept 218.534011.
        let piece = |t0: f64, t1: f64| {
            let k = (acos_lookup(t1) - acos_lookup(t0)) / (t1 - t0);
            (k, acos_lookup(t0) - k * t0)
        };
        let (k0, b0) = piece(0.1, 0.4);
        assert!((k0 + 1.031_458_37).abs() < 1e-6 && (b0 - 1.570_796_37).abs() < 1e-6);
        let (k1, b1) = piece(0.55, 0.7);
        assert!((k1 + 1.307_606_46).abs() < 1e-6 && (b1 - 1.708_870_53).abs() < 1e-6);
        let (k15, b15) = piece(1.0 - 2.5e-5, 1.0 - 2.0e-5);
        assert!((k15 + 218.532_821).abs() < 1e-4 && (b15 - 218.534_011).abs() < 1e-4);
        // Within 0.01 rad of acos where the limit applies.
        for i in 1..200 {
            let t = 0.71 + 0.29 * f64::from(i) / 200.0;
            assert!((acos_lookup(t) - t.acos()).abs() < 0.012, "t = {t}");
        }
    }
}
