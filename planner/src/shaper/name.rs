//! Reading shaper names: `[firmware:]family[(parameters)]`.
//!
//! - Klipper (bare, or `klipper:`): `zv`, `mzv`, `zvd`, `ei`, `2hump_ei`, `3hump_ei`, and
//!   the parameterised forms Klipper's `shaper_type` accepts (klippy/extras/shaper_defs.py,
//!   `init_shaper`; docs/Config_Reference.md): `mzv(n=4,t=0.8)`, `mzv(n=4,tau=1.2)`,
//!   `ei(v_tol=0.03)`, or the same values by position (`mzv(4,0.8)`, `ei(0.03)`). As in
//!   Klipper, named and positional values do not mix, `n` is an integer, and `mzv(t=0)` is
//!   the classic `mzv`. Unlike Klipper, giving both `t` and `tau` is refused (Klipper
//!   silently uses `tau`).
//! - Marlin FT_MOTION: `marlin:zv`, `marlin:zvd`, `marlin:zvdd`, `marlin:zvddd`,
//!   `marlin:ei`, `marlin:2hei`, `marlin:3hei`, `marlin:mzv`; parameters `v_tol` (the EI
//!   family only, M493 `Q`, 0..=1) and `ftm_fs` (the trajectory rate `FTM_FS`, Hz).
//! - Marlin's stepper ZV (`M593 F D`, `INPUT_SHAPING_X`/`_Y`): `marlin:m593`, no parameters.
//! - RepRapFirmware M593: `rrf:zvd`, `rrf:zvdd`, `rrf:zvddd`, `rrf:mzv`, `rrf:ei2`,
//!   `rrf:ei3`; parameter `step_clock` (Hz).
//! - Prusa-Firmware-Buddy M593 `T3`..`T5`: `prusa:ei`, `prusa:2hump_ei`, `prusa:3hump_ei`;
//!   parameter `v_tol` (`1 / R`, > 0). Its `T0`..`T2` are Klipper's `zv`, `zvd`, `mzv`.
//!
//! Names are case-insensitive and spaces around parts are ignored.

use super::shaper_type::{
    KLIPPER_V_TOL, MARLIN_FTM_FS_HZ, MARLIN_V_TOL, MarlinShaper, PRUSA_V_TOL, PrusaShaper,
    RRF_STEP_CLOCK_HZ, RrfShaper, ShaperType,
};
use crate::PlanError;

/// One parameter as written: its key (if named) and its text.
struct Arg<'a> {
    key: Option<&'a str>,
    text: &'a str,
}

fn invalid(name: &str, reason: String) -> PlanError {
    PlanError::InvalidShaper {
        name: name.to_string(),
        reason,
    }
}

fn unknown(name: &str) -> PlanError {
    PlanError::UnknownShaper {
        name: name.to_string(),
        allowed: ShaperType::ALLOWED,
    }
}

/// Split `family(args)` into the family and its arguments.
fn split<'a>(original: &str, s: &'a str) -> Result<(&'a str, Vec<Arg<'a>>), PlanError> {
    let Some(open) = s.find('(') else {
        return Ok((s.trim(), Vec::new()));
    };
    let Some(inner) = s[open + 1..].trim_end().strip_suffix(')') else {
        return Err(invalid(
            original,
            "parameters must be closed by `)` at the end".into(),
        ));
    };
    let mut args = Vec::new();
    for part in inner.split(',') {
        let part = part.trim();
        if part.is_empty() {
            if inner.trim().is_empty() {
                continue;
            }
            return Err(invalid(original, "empty parameter".into()));
        }
        let arg = match part.split_once('=') {
            Some((k, v)) => Arg {
                key: Some(k.trim()),
                text: v.trim(),
            },
            None => Arg {
                key: None,
                text: part,
            },
        };
        args.push(arg);
    }
    Ok((s[..open].trim(), args))
}

/// A non-negative finite decimal (digits and at most one dot, as Klipper's `[\d.]+`).
fn number(original: &str, key: &str, text: &str) -> Result<f64, PlanError> {
    let ok = !text.is_empty()
        && text.chars().all(|c| c.is_ascii_digit() || c == '.')
        && text.chars().filter(|&c| c == '.').count() <= 1
        && text != ".";
    match text.parse::<f64>() {
        Ok(v) if ok && v.is_finite() => Ok(v),
        _ => Err(invalid(
            original,
            format!("`{key}` must be a non-negative decimal number, got `{text}`"),
        )),
    }
}

fn integer(original: &str, key: &str, text: &str) -> Result<u32, PlanError> {
    text.parse::<u32>().map_err(|_| {
        invalid(
            original,
            format!("`{key}` must be a whole number, got `{text}`"),
        )
    })
}

/// Assign arguments to the keys `order` (positional in that order, or named), refusing a
/// mix, unknown keys and repeats.
fn assign<'a>(
    original: &str,
    args: &[Arg<'a>],
    order: &[&'static str],
) -> Result<Vec<Option<&'a str>>, PlanError> {
    let mut out = vec![None; order.len()];
    let named = args.iter().filter(|a| a.key.is_some()).count();
    if named != 0 && named != args.len() {
        return Err(invalid(
            original,
            "named and positional parameters do not mix".into(),
        ));
    }
    if args.len() > order.len() {
        return Err(invalid(
            original,
            format!(
                "too many parameters: this shaper takes {}",
                if order.is_empty() {
                    "none".to_string()
                } else {
                    order.join(", ")
                }
            ),
        ));
    }
    for (i, a) in args.iter().enumerate() {
        let slot = match a.key {
            None => i,
            Some(k) => order.iter().position(|o| *o == k).ok_or_else(|| {
                invalid(
                    original,
                    format!(
                        "unknown parameter `{k}`; this shaper takes {}",
                        if order.is_empty() {
                            "none".to_string()
                        } else {
                            order.join(", ")
                        }
                    ),
                )
            })?,
        };
        if out[slot].replace(a.text).is_some() {
            return Err(invalid(
                original,
                format!("parameter `{}` given twice", order[slot]),
            ));
        }
    }
    Ok(out)
}

impl ShaperType {
    /// Parse a shaper name (syntax in this module's documentation). Unknown names give
    /// [`PlanError::UnknownShaper`] listing the allowed names; bad parameters give
    /// [`PlanError::InvalidShaper`] saying what is allowed.
    pub fn parse(name: &str) -> Result<Self, PlanError> {
        let lower = name.trim().to_ascii_lowercase();
        let (firmware, rest) = match lower.split_once(':') {
            Some((fw, rest)) => (Some(fw.trim()), rest),
            None => (None, lower.as_str()),
        };
        let (family, args) = split(name, rest)?;
        match firmware {
            None | Some("klipper") => klipper(name, family, &args),
            Some("marlin") => marlin(name, family, &args),
            Some("rrf") => rrf(name, family, &args),
            Some("prusa") => prusa(name, family, &args),
            Some(_) => Err(unknown(name)),
        }
    }
}

fn klipper(name: &str, family: &str, args: &[Arg<'_>]) -> Result<ShaperType, PlanError> {
    let kind = match family {
        "zv" => ShaperType::Zv,
        "zvd" => ShaperType::Zvd,
        "2hump_ei" => ShaperType::TwoHumpEi,
        "3hump_ei" => ShaperType::ThreeHumpEi,
        "mzv" => {
            let v = assign(name, args, &["n", "t", "tau"])?;
            let n = v[0]
                .map(|s| integer(name, "n", s))
                .transpose()?
                .unwrap_or(3);
            let t = v[1].map(|s| number(name, "t", s)).transpose()?;
            let tau = v[2].map(|s| number(name, "tau", s)).transpose()?;
            let t = match (t, tau) {
                (Some(_), Some(tau)) if tau != 0.0 => {
                    return Err(invalid(name, "give `t` or `tau`, not both".into()));
                }
                (_, Some(tau)) if tau != 0.0 => super::klipper::mzv_t_from_tau(n, tau),
                (Some(t), _) if t != 0.0 => t,
                _ => 0.75,
            };
            super::klipper::mzv_coeffs(n, t).map_err(|reason| invalid(name, reason))?;
            return Ok(ShaperType::Mzv { n, t });
        }
        "ei" => {
            let v = assign(name, args, &["v_tol"])?;
            let v_tol = v[0]
                .map(|s| number(name, "v_tol", s))
                .transpose()?
                .unwrap_or(KLIPPER_V_TOL);
            return Ok(ShaperType::Ei { v_tol });
        }
        _ => return Err(unknown(name)),
    };
    assign(name, args, &[])?;
    Ok(kind)
}

fn marlin(name: &str, family: &str, args: &[Arg<'_>]) -> Result<ShaperType, PlanError> {
    if family == "m593" {
        assign(name, args, &[])?;
        return Ok(ShaperType::MarlinM593);
    }
    let shaper = MarlinShaper::ALL
        .into_iter()
        .find(|s| s.name() == family)
        .ok_or_else(|| unknown(name))?;
    let keys: &[&'static str] = if shaper.has_v_tol() {
        &["v_tol", "ftm_fs"]
    } else {
        &["ftm_fs"]
    };
    let v = assign(name, args, keys)?;
    let (v_tol, fs) = if shaper.has_v_tol() {
        (v[0], v[1])
    } else {
        (None, v[0])
    };
    let v_tol = v_tol
        .map(|s| number(name, "v_tol", s))
        .transpose()?
        .unwrap_or(MARLIN_V_TOL);
    if v_tol > 1.0 {
        return Err(invalid(
            name,
            format!("`v_tol` must be in 0..=1 (M493 Q), got {v_tol}"),
        ));
    }
    let ftm_fs_hz = fs
        .map(|s| integer(name, "ftm_fs", s))
        .transpose()?
        .unwrap_or(MARLIN_FTM_FS_HZ);
    if ftm_fs_hz == 0 {
        return Err(invalid(name, "`ftm_fs` must be > 0 Hz".into()));
    }
    Ok(ShaperType::Marlin {
        shaper,
        v_tol,
        ftm_fs_hz,
    })
}

fn rrf(name: &str, family: &str, args: &[Arg<'_>]) -> Result<ShaperType, PlanError> {
    let shaper = RrfShaper::ALL
        .into_iter()
        .find(|s| s.name() == family)
        .ok_or_else(|| unknown(name))?;
    let v = assign(name, args, &["step_clock"])?;
    let step_clock_hz = v[0]
        .map(|s| integer(name, "step_clock", s))
        .transpose()?
        .unwrap_or(RRF_STEP_CLOCK_HZ);
    if step_clock_hz == 0 {
        return Err(invalid(name, "`step_clock` must be > 0 Hz".into()));
    }
    Ok(ShaperType::Rrf {
        shaper,
        step_clock_hz,
    })
}

fn prusa(name: &str, family: &str, args: &[Arg<'_>]) -> Result<ShaperType, PlanError> {
    let shaper = PrusaShaper::ALL
        .into_iter()
        .find(|s| s.name() == family)
        .ok_or_else(|| unknown(name))?;
    let v = assign(name, args, &["v_tol"])?;
    let v_tol = v[0]
        .map(|s| number(name, "v_tol", s))
        .transpose()?
        .unwrap_or(PRUSA_V_TOL);
    if !(v_tol > 0.0) {
        return Err(invalid(
            name,
            format!("`v_tol` must be > 0 (1 / M593 R), got {v_tol}"),
        ));
    }
    Ok(ShaperType::Prusa { shaper, v_tol })
}
