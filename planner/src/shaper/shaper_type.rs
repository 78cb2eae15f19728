//! Which shaper: the family, the firmware whose definition it follows, and its parameters.
//!
//! Bare names mean Klipper's current definitions (klippy/extras/shaper_defs.py); the
//! shapers of Marlin's FT_MOTION and RepRapFirmware's M593 carry a `marlin:` or `rrf:`
//! prefix (Marlin's stepper ZV of `M593` is `marlin:m593`), because the same name means different impulses there (Marlin's MZV decays by the
//! ZV factor, RepRapFirmware's MZV puts its impulses in the opposite order, both EIs differ
//! from Klipper's). Prusa-Firmware-Buddy's ZV, ZVD and MZV are Klipper's; its EI family
//! (Klipper's earlier closed forms) carries a `prusa:` prefix. See [`ShaperType::parse`] for the syntax; `Display` writes the same
//! syntax back, and a Klipper kind's text is what Klipper's `shaper_type` accepts.

use std::fmt;

use crate::firmware::Firmware;

/// Marlin FT_MOTION's shaper families (`ftMotionShaper_t`; M493 `C1`..`C8`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum MarlinShaper {
    /// ZV (M493 C1).
    Zv,
    /// ZVD (C2).
    Zvd,
    /// ZVDD (C3).
    Zvdd,
    /// ZVDDD (C4).
    Zvddd,
    /// EI (C5), the closed form with vibration tolerance `v_tol`.
    Ei,
    /// Two-hump EI (C6).
    TwoHei,
    /// Three-hump EI (C7).
    ThreeHei,
    /// MZV (C8): ZV's decay factor with impulses 0.375 damped periods apart.
    Mzv,
}

impl MarlinShaper {
    /// Every family, in M493 `C` order.
    pub const ALL: [MarlinShaper; 8] = [
        MarlinShaper::Zv,
        MarlinShaper::Zvd,
        MarlinShaper::Zvdd,
        MarlinShaper::Zvddd,
        MarlinShaper::Ei,
        MarlinShaper::TwoHei,
        MarlinShaper::ThreeHei,
        MarlinShaper::Mzv,
    ];

    /// The name after `marlin:`.
    pub fn name(self) -> &'static str {
        match self {
            MarlinShaper::Zv => "zv",
            MarlinShaper::Zvd => "zvd",
            MarlinShaper::Zvdd => "zvdd",
            MarlinShaper::Zvddd => "zvddd",
            MarlinShaper::Ei => "ei",
            MarlinShaper::TwoHei => "2hei",
            MarlinShaper::ThreeHei => "3hei",
            MarlinShaper::Mzv => "mzv",
        }
    }

    /// The family of an `M493 C<code>` value (1..=8; 0 is "no shaper").
    pub fn from_m493_code(code: u8) -> Option<Self> {
        Self::ALL.get(usize::from(code).checked_sub(1)?).copied()
    }

    /// Its `M493 C<code>` value (1..=8), the inverse of [`MarlinShaper::from_m493_code`].
    pub fn m493_code(self) -> u8 {
        self as u8 + 1
    }

    /// Whether the family takes a vibration tolerance (M493 `Q`).
    pub fn has_v_tol(self) -> bool {
        matches!(
            self,
            MarlinShaper::Ei | MarlinShaper::TwoHei | MarlinShaper::ThreeHei
        )
    }
}

/// RepRapFirmware's M593 shaper families (`InputShaperType`, `M593 P"..."`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RrfShaper {
    /// `zvd`.
    Zvd,
    /// `zvdd`.
    Zvdd,
    /// `zvddd`.
    Zvddd,
    /// `mzv` (Klipper's classic amplitudes, in reverse order).
    Mzv,
    /// `ei2`: two-hump EI from damping polynomials over the damped period.
    Ei2,
    /// `ei3`: three-hump EI from damping polynomials over the damped period.
    Ei3,
}

impl RrfShaper {
    /// Every family.
    pub const ALL: [RrfShaper; 6] = [
        RrfShaper::Zvd,
        RrfShaper::Zvdd,
        RrfShaper::Zvddd,
        RrfShaper::Mzv,
        RrfShaper::Ei2,
        RrfShaper::Ei3,
    ];

    /// The name after `rrf:` (M593's `P` value).
    pub fn name(self) -> &'static str {
        match self {
            RrfShaper::Zvd => "zvd",
            RrfShaper::Zvdd => "zvdd",
            RrfShaper::Zvddd => "zvddd",
            RrfShaper::Mzv => "mzv",
            RrfShaper::Ei2 => "ei2",
            RrfShaper::Ei3 => "ei3",
        }
    }
}

/// Prusa-Firmware-Buddy's EI family (`input_shaper::Type`, `M593 T3`..`T5`,
/// lib/Marlin/Marlin/src/feature/input_shaper/input_shaper_config.hpp).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum PrusaShaper {
    /// EI (`T3`).
    Ei,
    /// Two-hump EI (`T4`).
    TwoHumpEi,
    /// Three-hump EI (`T5`).
    ThreeHumpEi,
}

impl PrusaShaper {
    /// Every family, in `M593 T` order.
    pub const ALL: [PrusaShaper; 3] = [
        PrusaShaper::Ei,
        PrusaShaper::TwoHumpEi,
        PrusaShaper::ThreeHumpEi,
    ];

    /// The name after `prusa:`.
    pub fn name(self) -> &'static str {
        match self {
            PrusaShaper::Ei => "ei",
            PrusaShaper::TwoHumpEi => "2hump_ei",
            PrusaShaper::ThreeHumpEi => "3hump_ei",
        }
    }
}

/// Prusa-Firmware-Buddy's default vibration tolerance of its EI family: `1 / R` with the
/// `M593 R` default 20 (`vibration_reduction`, input_shaper_config.hpp).
pub const PRUSA_V_TOL: f64 = 1.0 / 20.0;

/// Klipper's default damping ratio of a shaper (`DEFAULT_DAMPING_RATIO`).
pub const KLIPPER_DEFAULT_DAMPING_RATIO: f64 = 0.1;
/// Klipper's default vibration tolerance of `ei` (`1/SHAPER_VIBRATION_REDUCTION`, 5%).
pub const KLIPPER_V_TOL: f64 = 1.0 / 20.0;
/// Marlin's default vibration tolerance of its EI family (`FTM_SHAPING_V_TOL`, 5%).
pub const MARLIN_V_TOL: f64 = 0.05;
/// Marlin's default FT_MOTION trajectory rate `FTM_FS` (Hz, Configuration_adv.h): impulse
/// times are whole periods of it.
pub const MARLIN_FTM_FS_HZ: u32 = 1000;
/// RepRapFirmware's step clock on Duet 3 boards (`StepClockRate = 48 MHz / 64`, Hz):
/// impulse delays are whole ticks of it. Duet 2 boards run at `SystemCoreClockFreq / 128`.
pub const RRF_STEP_CLOCK_HZ: u32 = 750_000;

/// A shaper family with the parameters that change its impulses (frequency and damping
/// ratio are given separately to [`crate::shaper::Shaper::new`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ShaperType {
    /// Klipper `zv`.
    Zv,
    /// Klipper `mzv(n, t)`: `n` impulses over `t` damped periods (classic MZV: 3, 0.75).
    Mzv {
        /// Number of impulses (>= 3).
        n: u32,
        /// Duration in damped periods (`0.5 <= t < (n - 1) / 2`).
        t: f64,
    },
    /// Klipper `zvd`.
    Zvd,
    /// Klipper `ei(v_tol)`, damping-dependent amplitudes and middle time.
    Ei {
        /// Vibration tolerance at the shaper frequency (default 1/20).
        v_tol: f64,
    },
    /// Klipper `2hump_ei`.
    TwoHumpEi,
    /// Klipper `3hump_ei`.
    ThreeHumpEi,
    /// Marlin's stepper ZV (`INPUT_SHAPING_X`/`_Y`, `M593 F D`): amplitudes in 128ths from
    /// a cubic in the damping ratio, the echo half the undamped period late
    /// (Marlin/src/module/stepper.cpp; `marlin:m593`).
    MarlinM593,
    /// A Marlin FT_MOTION shaper.
    Marlin {
        /// The family.
        shaper: MarlinShaper,
        /// Vibration tolerance of the EI family (M493 `Q`; ignored by the others).
        v_tol: f64,
        /// Trajectory rate `FTM_FS` (Hz) that impulse times are rounded to.
        ftm_fs_hz: u32,
    },
    /// A Prusa-Firmware-Buddy EI shaper (`M593 T3`..`T5`).
    Prusa {
        /// The family.
        shaper: PrusaShaper,
        /// Vibration tolerance, `1 / R` (`M593 R`, default 20).
        v_tol: f64,
    },
    /// A RepRapFirmware M593 shaper.
    Rrf {
        /// The family.
        shaper: RrfShaper,
        /// Step clock (Hz) that impulse delays are rounded to.
        step_clock_hz: u32,
    },
}

impl ShaperType {
    /// Klipper's classic MZV, `mzv` = `mzv(n=3,t=0.75)`.
    pub const MZV: ShaperType = ShaperType::Mzv { n: 3, t: 0.75 };
    /// Klipper's `ei` with its default tolerance.
    pub const EI: ShaperType = ShaperType::Ei {
        v_tol: KLIPPER_V_TOL,
    };
    /// Klipper's six shapers with their default parameters, shortest first: what the bare
    /// names mean.
    pub const KLIPPER: [ShaperType; 6] = [
        ShaperType::Zv,
        ShaperType::MZV,
        ShaperType::Zvd,
        ShaperType::EI,
        ShaperType::TwoHumpEi,
        ShaperType::ThreeHumpEi,
    ];
    /// Klipper's six (the same as [`ShaperType::KLIPPER`]).
    pub const ALL: [ShaperType; 6] = Self::KLIPPER;
    /// Marlin's eight with their defaults (`v_tol` 0.05, `FTM_FS` 1000 Hz).
    pub const MARLIN: [ShaperType; 8] = {
        let mut out = [ShaperType::Zv; 8];
        let mut i = 0;
        while i < 8 {
            out[i] = ShaperType::marlin(MarlinShaper::ALL[i]);
            i += 1;
        }
        out
    };
    /// RepRapFirmware's six with the Duet 3 step clock.
    pub const RRF: [ShaperType; 6] = {
        let mut out = [ShaperType::Zv; 6];
        let mut i = 0;
        while i < 6 {
            out[i] = ShaperType::rrf(RrfShaper::ALL[i]);
            i += 1;
        }
        out
    };
    /// The syntax [`ShaperType::parse`] accepts.
    pub const ALLOWED: &'static str = "zv, mzv, zvd, ei, 2hump_ei, 3hump_ei (Klipper; also \
        klipper:NAME, mzv(n=N,t=T) or mzv(n=N,tau=TAU) with integer N >= 3, ei(v_tol=V)); \
        marlin:zv, marlin:zvd, marlin:zvdd, marlin:zvddd, marlin:ei, marlin:2hei, \
        marlin:3hei, marlin:mzv (FT_MOTION's M493; parameters v_tol=V for the EI family, \
        ftm_fs=HZ); marlin:m593 (the stepper's ZV of M593); \
        rrf:zvd, rrf:zvdd, rrf:zvddd, rrf:mzv, rrf:ei2, rrf:ei3 (parameter step_clock=HZ); \
        prusa:ei, prusa:2hump_ei, prusa:3hump_ei (parameter v_tol=V)";

    /// A Marlin shaper with Marlin's defaults.
    pub const fn marlin(shaper: MarlinShaper) -> Self {
        ShaperType::Marlin {
            shaper,
            v_tol: MARLIN_V_TOL,
            ftm_fs_hz: MARLIN_FTM_FS_HZ,
        }
    }

    /// A RepRapFirmware shaper on the Duet 3 step clock.
    pub const fn rrf(shaper: RrfShaper) -> Self {
        ShaperType::Rrf {
            shaper,
            step_clock_hz: RRF_STEP_CLOCK_HZ,
        }
    }

    /// A Prusa-Firmware-Buddy EI shaper with its default tolerance.
    pub const fn prusa(shaper: PrusaShaper) -> Self {
        ShaperType::Prusa {
            shaper,
            v_tol: PRUSA_V_TOL,
        }
    }

    /// The firmware whose definition this is (Klipper, Marlin, Prusa or RepRapFirmware).
    pub fn firmware(self) -> Firmware {
        match self {
            ShaperType::Marlin { .. } | ShaperType::MarlinM593 => Firmware::Marlin,
            ShaperType::Prusa { .. } => Firmware::Prusa,
            ShaperType::Rrf { .. } => Firmware::Rrf,
            _ => Firmware::Klipper,
        }
    }

    /// Klipper's lowest test frequency for the family in its shaper choice (`min_freq` in
    /// shaper_defs.py's `INPUT_SHAPERS`, "chosen to have projected max_accel ~= 1500"), Hz;
    /// `None` for other firmwares' shapers.
    pub fn klipper_min_freq_hz(self) -> Option<f64> {
        match self {
            ShaperType::Zv => Some(21.0),
            ShaperType::Mzv { .. } => Some(23.0),
            ShaperType::Zvd | ShaperType::Ei { .. } => Some(29.0),
            ShaperType::TwoHumpEi => Some(39.0),
            ShaperType::ThreeHumpEi => Some(48.0),
            ShaperType::Marlin { .. }
            | ShaperType::MarlinM593
            | ShaperType::Prusa { .. }
            | ShaperType::Rrf { .. } => None,
        }
    }

    /// The family name without parameters (`mzv`, `marlin:zvdd`, `rrf:ei2`).
    pub fn family(self) -> &'static str {
        match self {
            ShaperType::Zv => "zv",
            ShaperType::Mzv { .. } => "mzv",
            ShaperType::Zvd => "zvd",
            ShaperType::Ei { .. } => "ei",
            ShaperType::TwoHumpEi => "2hump_ei",
            ShaperType::ThreeHumpEi => "3hump_ei",
            ShaperType::MarlinM593 => "marlin:m593",
            ShaperType::Marlin { shaper, .. } => match shaper {
                MarlinShaper::Zv => "marlin:zv",
                MarlinShaper::Zvd => "marlin:zvd",
                MarlinShaper::Zvdd => "marlin:zvdd",
                MarlinShaper::Zvddd => "marlin:zvddd",
                MarlinShaper::Ei => "marlin:ei",
                MarlinShaper::TwoHei => "marlin:2hei",
                MarlinShaper::ThreeHei => "marlin:3hei",
                MarlinShaper::Mzv => "marlin:mzv",
            },
            ShaperType::Prusa { shaper, .. } => match shaper {
                PrusaShaper::Ei => "prusa:ei",
                PrusaShaper::TwoHumpEi => "prusa:2hump_ei",
                PrusaShaper::ThreeHumpEi => "prusa:3hump_ei",
            },
            ShaperType::Rrf { shaper, .. } => match shaper {
                RrfShaper::Zvd => "rrf:zvd",
                RrfShaper::Zvdd => "rrf:zvdd",
                RrfShaper::Zvddd => "rrf:zvddd",
                RrfShaper::Mzv => "rrf:mzv",
                RrfShaper::Ei2 => "rrf:ei2",
                RrfShaper::Ei3 => "rrf:ei3",
            },
        }
    }

    /// The full name, parameters included where they differ from the defaults; parses back
    /// to the same kind (the same text as `Display`).
    pub fn name(self) -> String {
        self.to_string()
    }
}

impl fmt::Display for ShaperType {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.family())?;
        // `{}` of an f64 is the shortest text that parses back to the same value, without
        // an exponent: Klipper's parameter pattern (`[\d.]+`) reads it.
        let mut params: Vec<String> = Vec::new();
        match *self {
            ShaperType::Mzv { n, t } if *self != ShaperType::MZV => {
                params.push(format!("n={n}"));
                params.push(format!("t={t}"));
            }
            ShaperType::Ei { v_tol } if v_tol != KLIPPER_V_TOL => {
                params.push(format!("v_tol={v_tol}"));
            }
            ShaperType::Marlin {
                shaper,
                v_tol,
                ftm_fs_hz,
            } => {
                if shaper.has_v_tol() && v_tol != MARLIN_V_TOL {
                    params.push(format!("v_tol={v_tol}"));
                }
                if ftm_fs_hz != MARLIN_FTM_FS_HZ {
                    params.push(format!("ftm_fs={ftm_fs_hz}"));
                }
            }
            ShaperType::Prusa { v_tol, .. } if v_tol != PRUSA_V_TOL => {
                params.push(format!("v_tol={v_tol}"));
            }
            ShaperType::Rrf { step_clock_hz, .. } if step_clock_hz != RRF_STEP_CLOCK_HZ => {
                params.push(format!("step_clock={step_clock_hz}"));
            }
            _ => {}
        }
        if !params.is_empty() {
            write!(f, "({})", params.join(","))?;
        }
        Ok(())
    }
}

impl std::str::FromStr for ShaperType {
    type Err = crate::PlanError;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        ShaperType::parse(s)
    }
}

/// Amplitudes and times (s) of an impulse train.
pub(super) type Impulses = (Vec<f64>, Vec<f64>);
