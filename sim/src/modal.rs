//! The modal reference plant: exact discretisation of the linearised lumped model.
//!
//! For each axis, with `g` the static gain (`K g = bk`: where every body sits for a unit
//! command), the deflection from the instantaneous static equilibrium `r = q - g x_cmd`
//! obeys `M r'' + C r' + K r = -M g a + (bc - C g) v` (a base-excited structure: only the
//! command's velocity and acceleration drive it). Over a step in which the commanded jerk
//! is constant, the augmented state `[r, r', v, a, j]` evolves linearly, so the step is
//! exactly the matrix exponential of the augmented system. The exponential is taken in
//! mass-normalised, frequency-scaled coordinates (`w0^2 M^1/2 r`, `w0 M^1/2 r'`, `w0 v`,
//! `a`, `j / w0`, with `w0` the highest natural frequency), which balances the matrix, and
//! mapped back to physical coordinates once. A step that a profile breakpoint cuts short
//! (a partial step) applies the exponential's Taylor series to the state instead, halved
//! and squared when longer than `1 / |A|`: equal to the exponential to rounding
//! (sim/tests/all/modal_transition.rs).
//!
//! Position-dependent stiffness (a belt's spans) is **linearised at the start position**
//! of each run, or at fixed axis positions given to the plant
//! ([`ModalPlant::linearised_at`]: a G-code job is linearised where the print is, its
//! layer ranges too): the model is exactly linear, which is what makes it the reference.
//! What that costs against the real belt (stiffer towards the pulley) is measured by
//! `settle validate` (rapier with the varying belt against rapier with it frozen).
//!
//! The modal plant simulates the linear driver spring only ([`DriverMode::Linear`]); the
//! stepper driver and microstep quantisation are nonlinear and run on rapier or MuJoCo.

use nalgebra::DMatrix;
use settle_planner::{Sample, State};

use crate::axis::{AxisModel, DriverMode};
use crate::modal_jump::Jumps;
use crate::plant::{InnerBreak, check_step};
use crate::stepper::StepperState;
use crate::{Observation, Plant, SimError};

/// One axis's linear model, discretised.
#[derive(Debug, Clone)]
struct Discrete {
    n: usize,
    /// Rows stored per column: `2n` rounded up to a multiple of 4 (zero padding).
    stride: usize,
    /// Continuous augmented matrix in scaled coordinates (`w0`-scaled, times 1 s).
    a_scaled: DMatrix<f64>,
    /// Scale of each augmented state (physical = scaled / scale).
    scale: Vec<f64>,
    /// Static gain g (body coordinate per metre of command).
    g: Vec<f64>,
    /// The nominal step (s).
    nominal_dt_s: f64,
    /// The first `2n` rows of the transition for the nominal step, physical coordinates,
    /// stored by column (`2n + 3` columns of [`Discrete::stride`] entries, zero padded);
    /// computed at the axis's first step ([`Discrete::nominal`]: an axis that never
    /// moves never needs it).
    nominal: std::sync::OnceLock<Vec<f64>>,
    /// Induced infinity norm of `a_scaled` (1/s): bounds the Taylor remainder.
    norm_per_s: f64,
    /// The first `2n` rows of `a_scaled^k / k!` in physical coordinates (by column), for
    /// partial steps ([`Discrete::partial`]); built at the first partial step.
    powers: std::sync::OnceLock<Vec<Vec<f64>>>,
    /// Rows `n..2n` of the augmented matrix in physical coordinates (`r''` in terms of
    /// `r, r', v, a`; the jerk enters through `a` only), row by row: what a short partial
    /// step multiplies the state by ([`Discrete::advance_short`]).
    accel_rows: Vec<f64>,
    /// The response to a jump of the command inside a step, built at the first one
    /// ([`crate::modal_jump`]).
    jumps: std::sync::OnceLock<Jumps>,
}

/// Largest `|A h|` (infinity norm, scaled coordinates) over which partial steps sum the
/// Taylor series of the exponential (longer ones are halved first, then squared): every
/// term is then below the previous one and [`TAYLOR_TERMS`] terms leave a remainder below
/// `e^1 / 24! = 4e-24`, far below rounding.
const TAYLOR_MAX_NORM: f64 = 1.0;

/// Terms of the Taylor series (degree 0 to `TAYLOR_TERMS - 1`); at `|A h| <= 0.3` (the
/// printer preset at 10 kHz) the last ones are far below rounding and cost little.
const TAYLOR_TERMS: usize = 24;

/// Bound on the first omitted Taylor term, relative, of a short partial step
/// ([`Discrete::advance_short`]).
const TAYLOR_OMITTED: f64 = 1e-18;

impl Discrete {
    fn new(axis: &AxisModel, start_m: f64, nominal_dt_s: f64) -> Result<Self, SimError> {
        let l = &axis.lumped;
        let n = l.dof();
        let q0 = l.equilibrium(start_m, None)?;
        let lin = l.linearised(&q0);
        let g = lin
            .k
            .clone()
            .lu()
            .solve(&lin.bk)
            .filter(|g| g.iter().all(|x| x.is_finite()))
            .ok_or_else(|| SimError::Unsupported {
                backend: "modal",
                reason: format!("axis `{}`: some body is held by no spring", axis.name),
            })?;
        let sq: Vec<f64> = (0..n).map(|i| lin.m[(i, i)].sqrt()).collect();
        let kt = DMatrix::from_fn(n, n, |i, j| lin.k[(i, j)] / (sq[i] * sq[j]));
        let ct = DMatrix::from_fn(n, n, |i, j| lin.c[(i, j)] / (sq[i] * sq[j]));
        let w0 = kt
            .clone()
            .symmetric_eigenvalues()
            .iter()
            .fold(0.0f64, |m, &l| m.max(l))
            .sqrt()
            .max(1e-9);
        // h_a = M^1/2 g, h_v = M^-1/2 (bc - C g).
        let cg = &lin.c * &g;
        let ha: Vec<f64> = (0..n).map(|i| sq[i] * g[i]).collect();
        let hv: Vec<f64> = (0..n).map(|i| (lin.bc[i] - cg[i]) / sq[i]).collect();
        let dim = 2 * n + 3;
        let mut a = DMatrix::zeros(dim, dim);
        for i in 0..n {
            a[(i, n + i)] = 1.0;
            for j in 0..n {
                a[(n + i, j)] = -kt[(i, j)] / (w0 * w0);
                a[(n + i, n + j)] = -ct[(i, j)] / w0;
            }
            a[(n + i, 2 * n)] = hv[i] / w0;
            a[(n + i, 2 * n + 1)] = -ha[i];
        }
        a[(2 * n, 2 * n + 1)] = 1.0;
        a[(2 * n + 1, 2 * n + 2)] = 1.0;
        let a_scaled = a * w0;
        // Scaled state = scale * physical: [w0^2 sqrt(m) r, w0 sqrt(m) r', w0 v, a, j/w0].
        let mut scale = Vec::with_capacity(dim);
        scale.extend(sq.iter().map(|s| w0 * w0 * s));
        scale.extend(sq.iter().map(|s| w0 * s));
        scale.extend([w0, 1.0, 1.0 / w0]);
        let accel_rows = (n..2 * n)
            .flat_map(|i| (0..2 * n + 2).map(move |j| (i, j)))
            .map(|(i, j)| a_scaled[(i, j)] * scale[j] / scale[i])
            .collect();
        let norm_per_s = (0..dim)
            .map(|i| (0..dim).map(|j| a_scaled[(i, j)].abs()).sum::<f64>())
            .fold(0.0, f64::max);
        Ok(Self {
            n,
            stride: (2 * n).div_ceil(4) * 4,
            a_scaled,
            scale,
            g: g.iter().copied().collect(),
            nominal_dt_s,
            nominal: std::sync::OnceLock::new(),
            norm_per_s,
            powers: std::sync::OnceLock::new(),
            accel_rows,
            jumps: std::sync::OnceLock::new(),
        })
    }

    /// The response to a jump of the command inside a step ([`crate::modal_jump`]).
    fn jumps(&self) -> &Jumps {
        self.jumps
            .get_or_init(|| Jumps::new(&self.a_scaled, &self.scale, self.n, self.norm_per_s))
    }

    /// The transition for the nominal step, computed at the first call (the field of the
    /// same name keeps it).
    fn nominal(&self) -> &[f64] {
        self.nominal
            .get_or_init(|| self.transition(self.nominal_dt_s))
    }

    /// The first `2n` rows of the transition over `dt_s`, in physical coordinates, by
    /// column.
    fn transition(&self, dt_s: f64) -> Vec<f64> {
        let phi = (&self.a_scaled * dt_s).exp();
        let dim = 2 * self.n + 3;
        let stride = self.stride();
        let mut cols = vec![0.0; stride * dim];
        for j in 0..dim {
            for i in 0..2 * self.n {
                cols[j * stride + i] = phi[(i, j)] * self.scale[j] / self.scale[i];
            }
        }
        cols
    }

    /// Rows stored per column: `2n` rounded up to a multiple of 4 (zero padding).
    fn stride(&self) -> usize {
        self.stride
    }

    /// The first `2n` rows of the transition over a partial step `dt_s` (a profile
    /// breakpoint falls inside a sample interval), by column as [`Discrete::transition`]
    /// gives them. The step is halved `s` times until `|A dt / 2^s| <= 1`; the Taylor
    /// series `sum_k (A tau)^k / k!` over `tau = dt / 2^s` is summed from powers of `A`
    /// computed once per run, and squared `s` times (`Phi(2 tau) = Phi(tau)^2`, see
    /// [`square`]): `O(K n^2 + s n^3)` per step instead of a Pade `expm` with its matrix
    /// products, solve and allocations (the same scaling and squaring, on a series whose
    /// remainder is below rounding).
    fn partial(&self, dt_s: f64, out: &mut Vec<f64>) {
        let powers = self.powers.get_or_init(|| self.taylor_powers());
        // Halving is exact (a power of two), so `tau * 2^s` is `dt_s` again.
        let mut tau = dt_s;
        let mut halvings = 0;
        while self.norm_per_s * tau > TAYLOR_MAX_NORM {
            tau /= 2.0;
            halvings += 1;
        }
        let len = powers[0].len();
        out.clear();
        out.resize(len, 0.0);
        // Horner-free sum, smallest terms first (they only matter near rounding).
        for (k, p) in powers.iter().enumerate().rev() {
            let c = tau.powi(k as i32);
            for (o, x) in out.iter_mut().zip(p) {
                *o += c * x;
            }
        }
        for _ in 0..halvings {
            square(out, 2 * self.n, self.stride, tau);
            tau *= 2.0;
        }
    }

    /// `z = Phi(dt_s) [z; cmd]` for a partial step (`z` padded to the stride, `buf` a
    /// reused buffer): [`Discrete::advance_short`] when `|A dt| <= 1`, else the
    /// transition of [`Discrete::partial`] applied as the nominal one is. Returns
    /// `sum z_i * 0` over the new state: 0 when every entry is finite, NaN otherwise.
    fn advance_partial(
        &self,
        dt_s: f64,
        z: &mut [f64],
        cmd: [f64; 3],
        buf: &mut Vec<f64>,
        scratch: &mut [f64],
    ) -> f64 {
        if self.norm_per_s * dt_s <= TAYLOR_MAX_NORM {
            return self.advance_short(dt_s, z, cmd, buf);
        }
        self.partial(dt_s, buf);
        apply_any(buf, z, 2 * self.n, cmd, scratch)
    }

    /// `z = Phi(dt_s) [z; cmd]` for a step with `|A dt| <= 1`: the Taylor series applied
    /// to the state by Horner's rule, `x + tau A (x + tau A / 2 (x + ... (x + tau A / K
    /// x)))` with `x = [z; cmd]`, one product with the sparse `A` per term (`r' = r'`,
    /// `r''` from [`Discrete::accel_rows`], `v' = a`, `a' = j`, `j' = 0`), `O(K n^2)`
    /// per step. `K` is the least degree whose first omitted term `|A dt|^(K+1)/(K+1)!`
    /// is below `1e-18` (at most 20 at `|A dt| = 1`): the remainder, below
    /// `e^1 1e-18`, is far below rounding.
    fn advance_short(&self, dt_s: f64, z: &mut [f64], cmd: [f64; 3], buf: &mut Vec<f64>) -> f64 {
        let n = self.n;
        let n2 = 2 * n;
        let dim = n2 + 3;
        let x_norm = self.norm_per_s * dt_s;
        let mut degree = 0;
        let mut term = 1.0;
        while term > TAYLOR_OMITTED && degree + 1 < TAYLOR_TERMS {
            degree += 1;
            term *= x_norm / degree as f64;
        }
        // Fixed sizes for the usual state sizes: the loops unroll, the state stays in
        // registers (the same operations in the same order as the loop below).
        let rows = &self.accel_rows;
        match n {
            1 => return horner::<1, 5>(rows, z, cmd, dt_s, degree),
            2 => return horner::<2, 7>(rows, z, cmd, dt_s, degree),
            3 => return horner::<3, 9>(rows, z, cmd, dt_s, degree),
            4 => return horner::<4, 11>(rows, z, cmd, dt_s, degree),
            _ => {}
        }
        buf.clear();
        buf.extend_from_slice(&z[..n2]);
        buf.extend_from_slice(&cmd);
        buf.extend_from_within(..dim);
        buf.resize(2 * dim + n, 0.0);
        let (x, rest) = buf.split_at_mut(dim);
        let (y, t) = rest.split_at_mut(dim);
        for k in (1..=degree).rev() {
            let h = dt_s / k as f64;
            // y = x + h A y, every row from the old `y`: r'' into `t` first.
            for ((ti, row), xi) in t
                .iter_mut()
                .zip(self.accel_rows.chunks_exact(n2 + 2))
                .zip(&x[n..n2])
            {
                let mut acc = 0.0;
                for (p, yj) in row.iter().zip(y.iter()) {
                    acc += p * yj;
                }
                *ti = xi + h * acc;
            }
            for i in 0..n {
                y[i] = x[i] + h * y[n + i];
            }
            y[n..n2].copy_from_slice(t);
            y[n2] = x[n2] + h * y[n2 + 1];
            y[n2 + 1] = x[n2 + 1] + h * y[n2 + 2];
        }
        z[..n2].copy_from_slice(&y[..n2]);
        z[..n2].iter().fold(0.0, |s, v| s + v * 0.0)
    }

    /// `a_scaled^k / k!` (first `2n` rows, physical coordinates) for `k < TAYLOR_TERMS`.
    fn taylor_powers(&self) -> Vec<Vec<f64>> {
        let dim = 2 * self.n + 3;
        let mut out = Vec::with_capacity(TAYLOR_TERMS);
        let mut p = DMatrix::<f64>::identity(dim, dim);
        for k in 0..TAYLOR_TERMS {
            if k > 0 {
                p = (&self.a_scaled * &p) / k as f64;
            }
            let stride = self.stride();
            let mut cols = vec![0.0; stride * dim];
            for j in 0..dim {
                for i in 0..2 * self.n {
                    cols[j * stride + i] = p[(i, j)] * self.scale[j] / self.scale[i];
                }
            }
            out.push(cols);
        }
        out
    }
}

/// [`Discrete::advance_short`]'s Horner loop for `N` bodies (`D = 2N + 3` augmented
/// states), with `accel_rows` its [`Discrete::accel_rows`]: the same operations in the
/// same order, in fixed-size arrays.
#[inline(always)]
fn horner<const N: usize, const D: usize>(
    accel_rows: &[f64],
    z: &mut [f64],
    cmd: [f64; 3],
    dt_s: f64,
    degree: usize,
) -> f64 {
    let n2 = 2 * N;
    let mut x = [0.0f64; D];
    x[..n2].copy_from_slice(&z[..n2]);
    x[n2..].copy_from_slice(&cmd);
    let mut y = x;
    let rows: &[f64] = &accel_rows[..N * (n2 + 2)];
    for k in (1..=degree).rev() {
        let h = dt_s / k as f64;
        let mut t = [0.0f64; N];
        for (i, ti) in t.iter_mut().enumerate() {
            let row = &rows[i * (n2 + 2)..(i + 1) * (n2 + 2)];
            let mut acc = 0.0;
            for (p, yj) in row.iter().zip(&y[..n2 + 2]) {
                acc += p * yj;
            }
            *ti = x[N + i] + h * acc;
        }
        for i in 0..N {
            y[i] = x[i] + h * y[N + i];
        }
        y[N..n2].copy_from_slice(&t);
        y[n2] = x[n2] + h * y[n2 + 1];
        y[n2 + 1] = x[n2 + 1] + h * y[n2 + 2];
    }
    z[..n2].copy_from_slice(&y[..n2]);
    z[..n2].iter().fold(0.0, |s, v| s + v * 0.0)
}

/// `Phi(2 tau)` from `Phi(tau)`: the first `n2` rows of the transition over `tau`
/// (physical coordinates, by column, `stride` rows per column: the state block `P`, then
/// the command columns `Q` for `v, a, j`) become those over `2 tau`. The rows below are
/// the command's own polynomial, `E(tau) = [[1, tau, tau^2/2], [0, 1, tau], [0, 0, 1]]`
/// (constant jerk), so `Phi(tau)^2` has the rows `[P P, P Q + Q E]`.
fn square(cols: &mut [f64], n2: usize, stride: usize, tau: f64) {
    let old = cols.to_vec();
    let col = |j: usize| &old[j * stride..j * stride + n2];
    // `P [P | Q]`: column j of the product is P times column j of [P | Q].
    for j in 0..n2 + 3 {
        let acc = &mut cols[j * stride..j * stride + n2];
        acc.fill(0.0);
        for (k, &x) in col(j).iter().enumerate() {
            for (a, p) in acc.iter_mut().zip(col(k)) {
                *a += p * x;
            }
        }
    }
    // `+ Q E`: Q0 to v, Q0 tau + Q1 to a, Q0 tau^2/2 + Q1 tau + Q2 to j.
    let e = [
        [1.0, 0.0, 0.0],
        [tau, 1.0, 0.0],
        [tau * tau / 2.0, tau, 1.0],
    ];
    for (c, e) in e.iter().enumerate() {
        for i in 0..n2 {
            let qe = (old[n2 * stride + i] * e[0] + old[(n2 + 1) * stride + i] * e[1])
                + old[(n2 + 2) * stride + i] * e[2];
            cols[(n2 + c) * stride + i] += qe;
        }
    }
}

/// The modal reference plant (model: constant).
#[derive(Debug, Clone)]
pub struct ModalPlant {
    axes: Vec<AxisModel>,
    nominal_dt_s: f64,
    /// Where each axis is linearised (m), when not at its start ([`ModalPlant::linearised_at`]).
    linearise_at_m: Option<Vec<f64>>,
}

/// One axis's mutable state.
#[derive(Debug, Clone)]
pub struct ModalAxis {
    /// Commanded base state at `t_s`.
    pub base: State,
    /// The state `[r, r']`: deflection of every body from the static equilibrium of the
    /// command (m, rad) and its rate (m/s, rad/s), zero padded to [`Discrete::stride`]
    /// entries (the transition's padding rows are zero, so the padding stays zero).
    z: Vec<f64>,
    /// True while the axis has never been stepped: it sits exactly at the static
    /// equilibrium of its start (`z` all zero), so a step with the command at rest would
    /// compute exact zeros and is skipped.
    idle: bool,
    /// Load-angle bookkeeping of the axis's motor, if it has one.
    pub stepper: Option<StepperState>,
    disc: std::sync::Arc<Discrete>,
    scratch: Vec<f64>,
    /// Reused buffer of the partial steps ([`Discrete::advance_partial`]).
    partial: Vec<f64>,
    /// `(x, toolhead, probe)` of [`axis_positions`] at the start (`z` zero): what an
    /// axis that is still idle at the same command reports, computed once.
    at_rest: (f64, f64, f64),
    /// What [`Plant::step_samples`] restores when its fast path meets a sample it cannot
    /// vouch for (reused buffer).
    undo: Undo,
}

/// The part of a [`ModalAxis`] that stepping changes.
#[derive(Debug, Clone)]
struct Undo {
    base: State,
    z: Vec<f64>,
    idle: bool,
    stepper: Option<StepperState>,
}

impl ModalAxis {
    fn save(&mut self) {
        self.undo.base = self.base;
        self.undo.z.copy_from_slice(&self.z);
        self.undo.idle = self.idle;
        self.undo.stepper.clone_from(&self.stepper);
    }

    fn restore(&mut self) {
        self.base = self.undo.base;
        self.z.copy_from_slice(&self.undo.z);
        self.idle = self.undo.idle;
        self.stepper.clone_from(&self.undo.stepper);
    }
}

impl ModalAxis {
    /// Deflection of every body from the static equilibrium of the command (m, rad).
    pub fn r(&self) -> &[f64] {
        &self.z[..self.disc.n]
    }

    /// Its rate (m/s, rad/s).
    pub fn rd(&self) -> &[f64] {
        &self.z[self.disc.n..2 * self.disc.n]
    }

    /// Set the deflection of body `i` (m, rad), e.g. to start a free decay.
    pub fn set_r(&mut self, i: usize, value: f64) {
        assert!(i < self.disc.n, "body {i} of {}", self.disc.n);
        self.z[i] = value;
        self.idle = false;
    }
}

/// `z = Phi [z; cmd]` for a transition stored by column (`M` rows per column, zero
/// padded; `z.len() == M`; the first `n2` columns multiply the state, the last three the
/// command's `v, a, j`), with the state and the outputs in fixed-size arrays the compiler
/// keeps in registers (no store-to-load chain through memory, no `memcpy` of a run-time
/// length). The sum runs over the columns in order, as a plain matrix-vector product
/// would. State columns are never skipped: a zero entry adds `p * 0 = +-0` to an
/// accumulator that starts at `+0` and so can never be `-0`, which leaves it unchanged,
/// exactly as skipping would. Command columns whose entry is zero (the command holds)
/// are skipped to save the work.
///
/// Returns `sum z_i * 0` over the new state (in no particular order): 0 when every entry
/// is finite, NaN otherwise.
#[inline]
fn apply<const M: usize>(cols: &[f64], z: &mut [f64], n2: usize, cmd: [f64; 3]) -> f64 {
    let zs: [f64; M] = z.try_into().expect("state padded to the stride");
    let mut acc = [0.0f64; M];
    for (col, &zj) in cols.chunks_exact(M).zip(&zs[..n2]) {
        for (a, p) in acc.iter_mut().zip(col) {
            *a += p * zj;
        }
    }
    for (col, &cj) in cols[n2 * M..].chunks_exact(M).zip(&cmd) {
        if cj != 0.0 {
            for (a, p) in acc.iter_mut().zip(col) {
                *a += p * cj;
            }
        }
    }
    z.copy_from_slice(&acc);
    // Four independent lanes (M is a multiple of 4): no serial chain of M additions.
    let mut lanes = [0.0f64; 4];
    for c in acc.chunks_exact(4) {
        for (l, x) in lanes.iter_mut().zip(c) {
            *l += x * 0.0;
        }
    }
    (lanes[0] + lanes[1]) + (lanes[2] + lanes[3])
}

/// [`apply`] for any stride (`rows` by column, `z.len()` rows per column; `scratch` of
/// the same length).
fn apply_any(rows: &[f64], z: &mut [f64], n2: usize, cmd: [f64; 3], scratch: &mut [f64]) -> f64 {
    match z.len() {
        4 => apply::<4>(rows, z, n2, cmd),
        8 => apply::<8>(rows, z, n2, cmd),
        12 => apply::<12>(rows, z, n2, cmd),
        16 => apply::<16>(rows, z, n2, cmd),
        stride => {
            scratch.fill(0.0);
            for (j, col) in rows.chunks_exact(stride).enumerate() {
                let zj = if j < n2 { z[j] } else { cmd[j - n2] };
                if j < n2 || zj != 0.0 {
                    for (o, p) in scratch.iter_mut().zip(col) {
                        *o += p * zj;
                    }
                }
            }
            z.copy_from_slice(scratch);
            z.iter().fold(0.0, |s, x| s + x * 0.0)
        }
    }
}

/// After a step with a standing command (no velocity, acceleration or jerk, no
/// breakpoint inside), a state whose entries are all subnormal or zero, one at least not
/// zero, is set to rest (`+0`). A machine left standing decays below the least normal
/// number (about 2.2e-308 m) after some tens of seconds and may then stay there, a
/// limit cycle of rounding, for as long as it stands; arithmetic on subnormal numbers is
/// tens of times slower (an axis of four modes standing still: 30 ns a sample for the
/// first 20 s, 750 to 1,000 ns a sample from 30 s on). A subnormal deflection adds
/// nothing to a position other than exactly 0 m, below any output's resolution.
#[inline(always)]
fn rest_if_subnormal(z: &mut [f64]) {
    const EXPONENT: u64 = 0x7ff0_0000_0000_0000;
    let (mut exponents, mut magnitudes) = (0, 0);
    for v in z.iter() {
        let b = v.to_bits();
        exponents |= b & EXPONENT;
        magnitudes |= b << 1;
    }
    if exponents == 0 && magnitudes != 0 {
        z.fill(0.0);
    }
}

/// The modal plant's mutable state.
#[derive(Debug, Clone)]
pub struct ModalState {
    /// Simulation time (s).
    pub t_s: f64,
    /// Per axis.
    pub axes: Vec<ModalAxis>,
}

impl ModalPlant {
    /// A plant for these axes. `nominal_dt_s` is the step size used most (the sample
    /// period): its transition is computed once per run; other step sizes (partial steps
    /// at profile breakpoints) are computed when needed. Only [`DriverMode::Linear`] axes.
    pub fn new(axes: Vec<AxisModel>, nominal_dt_s: f64) -> Result<Self, SimError> {
        if axes.is_empty() {
            return Err(SimError::NoModes);
        }
        if !(nominal_dt_s.is_finite() && nominal_dt_s >= 0.0) {
            return Err(SimError::InvalidStep { dt_s: nominal_dt_s });
        }
        for a in &axes {
            a.validate()?;
            if a.mode != DriverMode::Linear {
                return Err(SimError::Unsupported {
                    backend: "modal",
                    reason: format!(
                        "axis `{}` uses the `{}` driver; the modal backend is the exact solution of the linear model and simulates the `linear` driver only (use driver = \"linear\", or the rapier backend)",
                        a.name, a.mode
                    ),
                });
            }
        }
        Ok(Self {
            axes,
            nominal_dt_s,
            linearise_at_m: None,
        })
    }

    /// The same plant linearised at these axis positions (m, one per axis, in the order
    /// of the axes) instead of each run's start: [`Plant::initial_state`] then starts
    /// each axis at rest in the commanded state it is given (the deflection from the
    /// command's static equilibrium zero) with the model linearised at the static
    /// equilibrium of its axis position here. A machine whose stiffness does not depend
    /// on position gives the same model at any point.
    pub fn linearised_at(mut self, positions_m: Vec<f64>) -> Result<Self, SimError> {
        crate::plant::check_positions(self.axes.len(), &positions_m, "the linearisation point")?;
        self.linearise_at_m = Some(positions_m);
        Ok(self)
    }

    /// Where the plant is linearised (m per axis), when not at each run's start.
    pub fn linearisation_point(&self) -> Option<&[f64]> {
        self.linearise_at_m.as_deref()
    }

    /// The axes.
    pub fn axis_models(&self) -> &[AxisModel] {
        &self.axes
    }

    /// Axis `axis`'s transition over `dt_s` as stepping from `state` uses it (linearised
    /// where the axis started): the first `2n` rows, physical coordinates, by column,
    /// padded to a multiple of 4 rows. First as a partial step ([`Plant::step`] with a
    /// step other than the nominal one) computes it, column by column (the step applied
    /// to each unit vector of `[z; v, a, j]`), then as the
    /// matrix exponential of the augmented system gives it (nalgebra's Pade `expm`, what
    /// the nominal step uses); last the scale of each augmented coordinate (`2n + 3`:
    /// scaled = scale x physical), the balanced coordinates in which the exponential is
    /// taken. For tests that hold the one to the other.
    #[doc(hidden)]
    pub fn partial_transition(state: &ModalState, axis: usize, dt_s: f64) -> [Vec<f64>; 3] {
        let disc = &state.axes[axis].disc;
        let (n2, stride) = (2 * disc.n, disc.stride());
        let (mut buf, mut scratch) = (Vec::new(), vec![0.0; stride]);
        // Column j: the step applied to the j-th unit vector of `[z; v, a, j]`.
        let mut fast = vec![0.0; stride * (n2 + 3)];
        for (j, col) in fast.chunks_exact_mut(stride).enumerate() {
            let mut cmd = [0.0; 3];
            if j < n2 {
                col[j] = 1.0;
            } else {
                cmd[j - n2] = 1.0;
            }
            disc.advance_partial(dt_s, col, cmd, &mut buf, &mut scratch);
        }
        [fast, disc.transition(dt_s), disc.scale.clone()]
    }

    /// Envelope of the free vibration (m) of body `body` of axis `axis` as if it were a
    /// single mode of angular frequency `w` and damping ratio `zeta` (modal form: body `i`
    /// is mode `i`): `sqrt(e^2 + ((e' + zeta w e)/wd)^2)`.
    pub fn free_amplitude(state: &ModalState, axis: usize, body: usize, w: f64, zeta: f64) -> f64 {
        let a = &state.axes[axis];
        let (e, ed) = (a.r()[body], a.rd()[body]);
        let wd = w * (1.0 - zeta * zeta).sqrt();
        e.hypot((ed + zeta * w * e) / wd)
    }
}

impl ModalPlant {
    /// Every axis through the samples of `io` ([`run_axis`]), axis `a` across the
    /// breakpoints `breaks[a]` (none when `breaks` is empty). Returns whether every
    /// sample is one [`Plant::step`] and [`Plant::positions`] would vouch for; when not,
    /// the axes are back where they were.
    fn run_axes(
        &self,
        state: &mut ModalState,
        io: &Io<'_>,
        breaks: &[&[InnerBreak]],
        commanded_m: &mut [f64],
        toolhead_m: &mut [f64],
    ) -> bool {
        let mut good = true;
        let mut done = 0;
        for (a, (ax, st)) in self.axes.iter().zip(&mut state.axes).enumerate() {
            st.save();
            done = a + 1;
            let b = breaks.get(a).copied().unwrap_or(&[]);
            // The state's size as a constant: the product unrolls and `z` stays in
            // registers.
            good = match 2 * st.disc.n {
                2 => run_axis::<4, 2>(ax, st, io, a, b, commanded_m, toolhead_m),
                4 => run_axis::<4, 4>(ax, st, io, a, b, commanded_m, toolhead_m),
                6 => run_axis::<8, 6>(ax, st, io, a, b, commanded_m, toolhead_m),
                8 => run_axis::<8, 8>(ax, st, io, a, b, commanded_m, toolhead_m),
                10 => run_axis::<12, 10>(ax, st, io, a, b, commanded_m, toolhead_m),
                12 => run_axis::<12, 12>(ax, st, io, a, b, commanded_m, toolhead_m),
                14 => run_axis::<16, 14>(ax, st, io, a, b, commanded_m, toolhead_m),
                16 => run_axis::<16, 16>(ax, st, io, a, b, commanded_m, toolhead_m),
                _ => false,
            };
            if !good {
                break;
            }
        }
        if !good {
            for st in &mut state.axes[..done] {
                st.restore();
            }
        }
        good
    }

    /// [`Plant::step_samples`] as [`Plant::step`] and [`Plant::positions`] per sample.
    fn samples_one_by_one(
        &self,
        state: &mut ModalState,
        cmds: &[Sample],
        dt_s: f64,
        blowup_m: f64,
        commanded_m: &mut [f64],
        toolhead_m: &mut [f64],
    ) -> Result<Option<usize>, (usize, SimError)> {
        let axes = self.axes.len();
        let n = cmds.len() / axes;
        for (i, cmd) in cmds.chunks_exact(axes).enumerate() {
            self.step(state, cmd, dt_s).map_err(|e| (i, e))?;
            let c = &mut commanded_m[i * axes..(i + 1) * axes];
            let h = &mut toolhead_m[i * axes..(i + 1) * axes];
            let vouched = self.positions(state, c, h)
                && c.iter()
                    .zip(h.iter())
                    .all(|(c, h)| (h - c).abs() <= blowup_m);
            if !vouched {
                return Ok(Some(i + 1));
            }
        }
        Ok(Some(n))
    }
}

/// The inputs of one [`Plant::step_samples`] call.
struct Io<'a> {
    cmds: &'a [Sample],
    axes: usize,
    dt_s: f64,
    blowup_m: f64,
}

/// Axis `a` through every sample of `io` with the nominal transition (`M` rows per
/// column), writing its commanded and toolhead positions: per sample exactly the
/// arithmetic of [`ModalPlant::step`] and [`ModalPlant::positions`] for this axis.
/// Returns whether every sample is one those would vouch for: every value finite (the
/// step's check and the positions' probe) and the toolhead within `blowup_m` of the
/// command.
///
/// The state's finiteness is checked once, after the last sample: a non-finite entry of
/// `z` makes every entry non-finite one step later (each row adds `p z_j`, which is
/// `+-inf` or NaN for a non-finite `z_j` whatever `p` is, and a sum with a non-finite
/// term is non-finite; state columns are never skipped), and so it stays, so the last
/// `z` is finite only if every `z` was. The base polynomial only reaches the outputs
/// through its position, which is checked per sample (with the command, as the step
/// does; a non-finite command makes the position non-finite).
#[inline(always)]
fn run_axis<const M: usize, const N2: usize>(
    ax: &AxisModel,
    st: &mut ModalAxis,
    io: &Io<'_>,
    a: usize,
    breaks: &[InnerBreak],
    commanded_m: &mut [f64],
    toolhead_m: &mut [f64],
) -> bool {
    let h = io.dt_s;
    if st.disc.stride() != M || st.disc.n * 2 != N2 {
        return false;
    }
    let disc = std::sync::Arc::clone(&st.disc);
    let g: &[f64] = &disc.g;
    let mut z: [f64; N2] = st.z[..N2].try_into().expect("state of N2 entries");
    let track = ax
        .stepper
        .as_ref()
        .map(|sp| (-f64::from(sp.rotor_teeth), sp.rotor));
    let mut stepper = st.stepper.clone();
    let mut idle = st.idle;
    let at_rest = st.at_rest;
    let mut probe = 0.0;
    let mut within = true;
    let axes = io.axes;
    let n = io.cmds.len() / axes;
    let first = io.cmds[a];
    // The base polynomial's position after a step from `c`.
    let base_p = |c: &Sample| {
        let hj = h * c.j;
        let hj6 = if c.j == 0.0 { hj } else { hj / 6.0 };
        c.p + h * (c.v + h * (c.a / 2.0 + hj6))
    };
    let (p0, v0, a0, j0) = (
        first.p.to_bits(),
        first.v.to_bits(),
        first.a.to_bits(),
        first.j.to_bits(),
    );
    let held = breaks.is_empty()
        && first.v == 0.0
        && first.a == 0.0
        && first.j == 0.0
        && (1..n).all(|i| {
            let c = &io.cmds[i * axes + a];
            (c.p.to_bits() ^ p0)
                | (c.v.to_bits() ^ v0)
                | (c.a.to_bits() ^ a0)
                | (c.j.to_bits() ^ j0)
                == 0
        });
    // The transition's first `N2` rows by column: the state columns, then `v, a, j`.
    // (The padding rows are zero; they only ever add `+-0` to the padding entries of `z`,
    // which start at +0 and stay +0 while the state is finite, so they are left out: a
    // non-finite state sends the call to the per-sample path anyway.)
    // An idle axis whose command holds never steps: it needs no transition.
    let nominal: &[f64] = if held && idle { &[] } else { disc.nominal() };
    let col = |j: usize| -> [f64; N2] {
        nominal
            .get(j * M..j * M + N2)
            .map_or([0.0; N2], |c| c.try_into().expect("N2 rows per column"))
    };
    let phi: [[f64; N2]; N2] = std::array::from_fn(col);
    let phi_cmd: [[f64; N2]; 3] = std::array::from_fn(|j| col(N2 + j));
    // This axis's outputs of every sample, and its commands (sample-major, `axes` per
    // sample), one chunk per sample.
    let outs = commanded_m
        .chunks_exact_mut(axes)
        .zip(toolhead_m.chunks_exact_mut(axes))
        .take(n)
        .map(|(cm, th)| (&mut cm[a], &mut th[a]));
    let mut last = first;
    // The breakpoints of the last step (their share of the base after it).
    let mut last_breaks: &[InnerBreak] = &[];
    if held {
        // The command holds (the observation window): the same base position every
        // sample, no command columns (all zero), and an idle axis stays where it is.
        let x = base_p(&first);
        if !idle {
            // The step's check of the command, the same every sample.
            probe += x * 0.0 + (first.v * 0.0 + first.a * 0.0 + first.j * 0.0);
        }
        let rest = idle && x.to_bits() == at_rest.0.to_bits();
        let mut at_idle = (at_rest.1, at_rest.2);
        if idle && !rest {
            at_idle = axis_positions(ax, &z, g, x);
        }
        if idle {
            // Nothing moves: the same outputs every sample (and the same checks).
            let (toolhead, p) = at_idle;
            if n > 0 {
                probe += p;
                within &= (toolhead - x).abs() <= io.blowup_m;
            }
            for (cm, th) in outs {
                *cm = x;
                *th = toolhead;
            }
        } else {
            for (cm, th) in outs {
                advance(&phi, &phi_cmd, &mut z, None);
                rest_if_subnormal(&mut z);
                if let (Some((nr, rotor)), Some(ss)) = (track, stepper.as_mut()) {
                    ss.track(nr * z[rotor]);
                }
                let (toolhead, p) = axis_positions(ax, &z, g, x);
                probe += p;
                within &= (toolhead - x).abs() <= io.blowup_m;
                *cm = x;
                *th = toolhead;
            }
        }
    } else {
        // What each breakpoint adds to the state ([`crate::modal_jump`]), formed ahead:
        // the sums do not depend on the state, so those of successive breakpoints overlap.
        let responses: Vec<[f64; N2]> = match breaks.is_empty() {
            true => Vec::new(),
            false => {
                let jumps = disc.jumps();
                breaks
                    .iter()
                    .map(|b| jumps.response::<N2>(b.before_end_s, [b.dv, b.da, b.dj]))
                    .collect()
            }
        };
        let mut rest = breaks;
        let mut rest_responses = &responses[..];
        for (i, ((cm, th), c)) in outs.zip(io.cmds.chunks_exact(axes)).enumerate() {
            let c = &c[a];
            last = *c;
            let mut x = base_p(c);
            // This step's breakpoints ([`crate::modal_jump`]).
            let here = rest.iter().take_while(|b| b.step == i).count();
            let (jumps, after) = rest.split_at(here);
            rest = after;
            let (adds, after) = rest_responses.split_at(here);
            rest_responses = after;
            last_breaks = jumps;
            if !(idle && c.v == 0.0 && c.a == 0.0 && c.j == 0.0 && jumps.is_empty()) {
                idle = false;
                advance(&phi, &phi_cmd, &mut z, Some([c.v, c.a, c.j]));
                if jumps.is_empty() && [c.v, c.a, c.j] == [0.0; 3] {
                    rest_if_subnormal(&mut z);
                }
                for (b, r) in jumps.iter().zip(adds) {
                    for (zi, r) in z.iter_mut().zip(r) {
                        *zi += r;
                    }
                    let s = b.before_end_s;
                    x += s * (b.dv + s * (b.da / 2.0 + s * b.dj / 6.0));
                    probe += b.dv * 0.0 + b.da * 0.0 + b.dj * 0.0;
                }
                if let (Some((nr, rotor)), Some(ss)) = (track, stepper.as_mut()) {
                    ss.track(nr * z[rotor]);
                }
                probe += x * 0.0 + (c.v * 0.0 + c.a * 0.0 + c.j * 0.0);
            }
            let (toolhead, p) = if idle && x.to_bits() == at_rest.0.to_bits() {
                (at_rest.1, at_rest.2)
            } else {
                axis_positions(ax, &z, g, x)
            };
            probe += p;
            within &= (toolhead - x).abs() <= io.blowup_m;
            *cm = x;
            *th = toolhead;
        }
    }
    // The base after the last step (its velocity and acceleration are read by nothing
    // in between).
    let c = last;
    st.base = State {
        p: base_p(&c),
        v: c.v + h * (c.a + h * c.j / 2.0),
        a: c.a + h * c.j,
    };
    for b in last_breaks {
        let s = b.before_end_s;
        st.base.p += s * (b.dv + s * (b.da / 2.0 + s * b.dj / 6.0));
        st.base.v += b.dv + s * (b.da + s * b.dj / 2.0);
        st.base.a += b.da + s * b.dj;
    }
    st.idle = idle;
    st.stepper = stepper;
    st.z[..N2].copy_from_slice(&z);
    probe == 0.0 && within && z.iter().all(|v| v.is_finite())
}

/// `z = Phi [z; cmd]` for the state columns `phi` and the command columns `phi_cmd`
/// (`v, a, j`; `None`: all zero): [`apply`]'s sums, column by column in order, command
/// columns with a zero entry skipped.
#[inline(always)]
fn advance<const N2: usize>(
    phi: &[[f64; N2]; N2],
    phi_cmd: &[[f64; N2]; 3],
    z: &mut [f64; N2],
    cmd: Option<[f64; 3]>,
) {
    let mut acc = [0.0f64; N2];
    for (col, &zj) in phi.iter().zip(z.iter()) {
        for (a, p) in acc.iter_mut().zip(col) {
            *a += p * zj;
        }
    }
    if let Some(cmd) = cmd {
        for (col, &cj) in phi_cmd.iter().zip(&cmd) {
            if cj != 0.0 {
                for (a, p) in acc.iter_mut().zip(col) {
                    *a += p * cj;
                }
            }
        }
    }
    *z = acc;
}

impl Plant for ModalPlant {
    type State = ModalState;

    fn axes(&self) -> usize {
        self.axes.len()
    }

    fn initial_state(&self, start: &[State]) -> Result<ModalState, SimError> {
        if start.len() != self.axes.len() {
            return Err(SimError::AxisCount {
                expected: self.axes.len(),
                got: start.len(),
            });
        }
        let axes = self
            .axes
            .iter()
            .zip(start)
            .enumerate()
            .map(|(i, (a, s))| {
                let at = self.linearise_at_m.as_ref().map_or(s.p, |p| p[i]);
                let disc = Discrete::new(a, at, self.nominal_dt_s)?;
                let stride = disc.stride();
                let stepper = a.stepper.as_ref().map(|st| {
                    let mut ss = st.at_rest(s.p).0;
                    ss.track(0.0);
                    ss
                });
                let z = vec![0.0; stride];
                let (toolhead, probe) = axis_positions(a, &z, &disc.g, s.p);
                Ok(ModalAxis {
                    base: *s,
                    at_rest: (s.p, toolhead, probe),
                    undo: Undo {
                        base: *s,
                        z: z.clone(),
                        idle: true,
                        stepper: stepper.clone(),
                    },
                    z,
                    idle: true,
                    stepper,
                    disc: std::sync::Arc::new(disc),
                    scratch: vec![0.0; stride],
                    partial: Vec::new(),
                })
            })
            .collect::<Result<_, SimError>>()?;
        Ok(ModalState { t_s: 0.0, axes })
    }

    fn step(&self, state: &mut ModalState, cmd: &[Sample], dt_s: f64) -> Result<(), SimError> {
        check_step(self.axes.len(), cmd, dt_s)?;
        let nominal = dt_s == self.nominal_dt_s;
        for ((ax, st), c) in self.axes.iter().zip(&mut state.axes).zip(cmd) {
            let h = dt_s;
            // `h j / 6` is `h j` itself (a signed zero) when j is zero: skip the division.
            let hj = h * c.j;
            let hj6 = if c.j == 0.0 { hj } else { hj / 6.0 };
            st.base = State {
                p: c.p + h * (c.v + h * (c.a / 2.0 + hj6)),
                v: c.v + h * (c.a + h * c.j / 2.0),
                a: c.a + h * c.j,
            };
            // An axis at rest with a command at rest stays exactly at rest (the update
            // below would compute exact zeros): skip it.
            if st.idle && c.v == 0.0 && c.a == 0.0 && c.j == 0.0 {
                continue;
            }
            st.idle = false;
            let disc = &st.disc;
            let n2 = 2 * disc.n;
            let cmd = [c.v, c.a, c.j];
            let z_probe = if nominal {
                apply_any(disc.nominal(), &mut st.z, n2, cmd, &mut st.scratch)
            } else {
                disc.advance_partial(dt_s, &mut st.z, cmd, &mut st.partial, &mut st.scratch)
            };
            if cmd == [0.0; 3] {
                rest_if_subnormal(&mut st.z);
            }
            if let (Some(sp), Some(ss)) = (&ax.stepper, st.stepper.as_mut()) {
                // Linear driver: the load angle Nr (x rad_per_m - theta) is -Nr r_rotor.
                ss.track(-f64::from(sp.rotor_teeth) * st.z[sp.rotor]);
            }
            // `x * 0` is 0 for a finite `x` and NaN otherwise: one sum, no branch per entry.
            let probe = (st.base.p * 0.0 + (c.v * 0.0 + c.a * 0.0 + c.j * 0.0)) + z_probe;
            if probe != 0.0 {
                return Err(SimError::NonFinite {
                    t_s: state.t_s + dt_s,
                });
            }
        }
        state.t_s += dt_s;
        Ok(())
    }

    fn positions(
        &self,
        state: &ModalState,
        commanded_m: &mut [f64],
        toolhead_m: &mut [f64],
    ) -> bool {
        // `x * 0` is 0 for a finite `x` and NaN otherwise.
        let mut probe = 0.0;
        for (((ax, st), c), t) in self
            .axes
            .iter()
            .zip(&state.axes)
            .zip(commanded_m.iter_mut())
            .zip(toolhead_m.iter_mut())
        {
            let x = st.base.p;
            *c = x;
            let (toolhead, p) = if st.idle && x.to_bits() == st.at_rest.0.to_bits() {
                (st.at_rest.1, st.at_rest.2)
            } else {
                axis_positions(ax, &st.z, &st.disc.g, x)
            };
            *t = toolhead;
            probe += p;
        }
        probe == 0.0
    }

    /// Bit for bit what [`Plant::step`] then [`Plant::positions`] give per sample. The
    /// fast path steps each axis through all samples in one loop (the nominal step's
    /// transition, the state in registers) and checks at the end that everything stayed
    /// finite and within `blowup_m`; if not, it restores the axes and repeats the call
    /// sample by sample, which stops at the first bad sample as the contract asks.
    fn step_samples(
        &self,
        state: &mut ModalState,
        cmds: &[Sample],
        dt_s: f64,
        blowup_m: f64,
        commanded_m: &mut [f64],
        toolhead_m: &mut [f64],
    ) -> Result<Option<usize>, (usize, SimError)> {
        let axes = self.axes.len();
        let n = cmds.len() / axes;
        if dt_s != self.nominal_dt_s || n * axes != cmds.len() {
            return self.samples_one_by_one(state, cmds, dt_s, blowup_m, commanded_m, toolhead_m);
        }
        let io = Io {
            cmds,
            axes,
            dt_s,
            blowup_m,
        };
        if !self.run_axes(state, &io, &[], commanded_m, toolhead_m) {
            return self.samples_one_by_one(state, cmds, dt_s, blowup_m, commanded_m, toolhead_m);
        }
        for _ in 0..n {
            state.t_s += dt_s;
        }
        Ok(Some(n))
    }

    /// [`Plant::step_samples`] with whole steps across breakpoints
    /// (module `modal_jump`): `Ok(None)` when the step is not the nominal one, when a
    /// step is too long for the jump's series on some axis (`Jumps::covers`), or when a
    /// sample is not one to vouch for (the state is then unchanged and the caller splits
    /// the steps, which finds the sample).
    fn step_samples_across(
        &self,
        state: &mut ModalState,
        cmds: &[Sample],
        breaks: &[&[InnerBreak]],
        dt_s: f64,
        blowup_m: f64,
        commanded_m: &mut [f64],
        toolhead_m: &mut [f64],
    ) -> Result<Option<usize>, (usize, SimError)> {
        let axes = self.axes.len();
        let n = cmds.len() / axes;
        if dt_s != self.nominal_dt_s
            || n * axes != cmds.len()
            || breaks.len() != axes
            || state.axes.iter().any(|st| !st.disc.jumps().covers(dt_s))
        {
            return Ok(None);
        }
        let io = Io {
            cmds,
            axes,
            dt_s,
            blowup_m,
        };
        if !self.run_axes(state, &io, breaks, commanded_m, toolhead_m) {
            return Ok(None);
        }
        for _ in 0..n {
            state.t_s += dt_s;
        }
        Ok(Some(n))
    }

    fn observe(&self, state: &ModalState, out: &mut [Observation]) {
        for ((ax, st), o) in self.axes.iter().zip(&state.axes).zip(out.iter_mut()) {
            let x = st.base.p;
            let g = &st.disc.g;
            let q = |i: usize| st.z[i] + g[i] * x;
            *o = Observation {
                commanded_m: x,
                toolhead_m: toolhead(ax, x, q),
                carriage_m: ax.carriage.map(q),
                motor_angle_rad: ax.stepper.as_ref().map(|s| q(s.rotor)),
                currents_a: None,
                load_angle_rad: st.stepper.as_ref().map(|s| s.load_angle_rad),
                lost_steps: st.stepper.as_ref().map_or(0, StepperState::lost_steps),
                max_load_angle_rad: st.stepper.as_ref().map(|s| s.max_load_angle_rad),
            };
        }
    }
}

/// The toolhead position (m) of `axis` for the command at `x` (m), with `q(i)` the
/// position of body `i`: the sum of the output terms, in their order.
#[inline(always)]
fn toolhead(axis: &AxisModel, x: f64, q: impl Fn(usize) -> f64) -> f64 {
    let value = |t: &crate::lumped::Term| match t.node {
        crate::lumped::Node::Ground => 0.0,
        crate::lumped::Node::Command => x,
        crate::lumped::Node::Body(i) => q(i),
    };
    // One term (every compiled machine: the toolhead body) without the loop.
    if let [t] = axis.lumped.output.as_slice() {
        return 0.0 + t.gain * value(t);
    }
    let mut toolhead = 0.0;
    for t in &axis.lumped.output {
        toolhead += t.gain * value(t);
    }
    toolhead
}

/// The toolhead position (m) of `axis` for the command at `x` (m) and the state `z`, and
/// the sum of `v * 0` over `x`, the toolhead, the carriage and the motor angle (0 when
/// they are all finite, NaN otherwise).
#[inline(always)]
fn axis_positions(axis: &AxisModel, z: &[f64], g: &[f64], x: f64) -> (f64, f64) {
    let q = |i: usize| z[i] + g[i] * x;
    let t = toolhead(axis, x, q);
    let mut probe = x * 0.0 + t * 0.0;
    if let Some(i) = axis.carriage {
        probe += q(i) * 0.0;
    }
    if let Some(s) = &axis.stepper {
        probe += q(s.rotor) * 0.0;
    }
    (t, probe)
}
