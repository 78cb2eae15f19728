//! Klipper's `shaper_type` values, checked as `klippy/extras/shaper_defs.py` reads them
//! (`get_shaper_cfg`, `init_shaper`, `get_mzv_coeffs`): a family name, lower case,
//! optionally with parameters in parentheses, by name or by position but not both:
//! `mzv(n=4,t=0.8)`, `mzv(n=4,tau=1.2)`, `mzv(4,0.8)`, `ei(v_tol=0.03)`. Values are
//! decimals of digits and one dot (`[\d.]+`). The text is kept as written; turning it into
//! impulses is the planner's business (`settle_planner::shaper::ShaperType` reads the
//! same syntax).

/// The shaper families and the largest damping ratio Klipper accepts for each
/// (`INPUT_SHAPERS`, `max_damping_ratio`).
const FAMILIES: [(&str, f64); 6] = [
    ("zv", 0.99),
    ("mzv", 0.99),
    ("zvd", 0.99),
    ("ei", 0.4),
    ("2hump_ei", 0.3),
    ("3hump_ei", 0.2),
];

/// What `shaper_type` allows, for error messages.
pub(crate) const ALLOWED: &str = "zv, mzv, zvd, ei, 2hump_ei or 3hump_ei in lower case, optionally with parameters: mzv(n=N,t=T), mzv(n=N,tau=TAU), ei(v_tol=V)";

/// Klipper's default `v_tol`-free MZV duration parameter (`get_mzv_shaper`: `t = 0.75`).
const MZV_DEFAULT_T: f64 = 0.75;

/// A checked shaper type: its family and the largest damping ratio the family accepts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Family {
    pub(crate) name: &'static str,
    pub(crate) max_damping_ratio: f64,
}

fn is_word(s: &str) -> bool {
    !s.is_empty() && s.chars().all(|c| c.is_alphanumeric() || c == '_')
}

fn decimal(key: &str, text: &str) -> Result<f64, String> {
    let ok = !text.is_empty()
        && text.chars().all(|c| c.is_ascii_digit() || c == '.')
        && text.matches('.').count() <= 1
        && text != ".";
    match text.parse::<f64>() {
        Ok(v) if ok => Ok(v),
        _ => Err(format!(
            "`{key}` must be a decimal number like 0.8, got `{text}`"
        )),
    }
}

/// Checks `text`; the error says what is wrong with it.
pub(crate) fn check(text: &str) -> Result<Family, String> {
    let (name, args) = match text.find('(') {
        None => (text, None),
        Some(open) => {
            let inner = text[open + 1..]
                .strip_suffix(')')
                .ok_or_else(|| "parameters must end the text with `)`".to_string())?;
            (text[..open].trim_end(), Some(inner))
        }
    };
    let family = FAMILIES
        .iter()
        .find(|(n, _)| *n == name)
        .map(|&(name, max_damping_ratio)| Family {
            name,
            max_damping_ratio,
        })
        .ok_or_else(|| {
            if is_word(name) && FAMILIES.iter().any(|(n, _)| n.eq_ignore_ascii_case(name)) {
                format!("`{name}`: Klipper's shaper names are lower case")
            } else {
                format!("`{name}` is not a Klipper shaper")
            }
        })?;
    let Some(inner) = args.filter(|a| !a.trim().is_empty()) else {
        return Ok(family);
    };
    let order: &[&str] = match family.name {
        "mzv" => &["n", "t", "tau"],
        "ei" => &["v_tol"],
        _ => &[],
    };
    let mut values: Vec<Option<(String, f64)>> = vec![None; order.len()];
    let parts: Vec<&str> = inner.split(',').map(str::trim).collect();
    let named = parts.iter().filter(|p| p.contains('=')).count();
    if named != 0 && named != parts.len() {
        return Err("named and positional parameters do not mix".to_string());
    }
    if parts.len() > order.len() {
        return Err(format!(
            "{} takes {}",
            family.name,
            if order.is_empty() {
                "no parameters".to_string()
            } else {
                format!("at most: {}", order.join(", "))
            }
        ));
    }
    for (i, part) in parts.iter().enumerate() {
        let (slot, key, text) = match part.split_once('=') {
            Some((k, v)) => {
                let k = k.trim();
                let slot = order.iter().position(|o| *o == k).ok_or_else(|| {
                    format!(
                        "{} has no parameter `{k}` (it has {})",
                        family.name,
                        order.join(", ")
                    )
                })?;
                (slot, order[slot], v.trim())
            }
            None => (i, order[i], *part),
        };
        if values[slot].is_some() {
            return Err(format!("`{key}` given twice"));
        }
        values[slot] = Some((text.to_string(), decimal(key, text)?));
    }
    if family.name == "mzv" {
        mzv(&values)?;
    }
    Ok(family)
}

/// `get_mzv_shaper` / `get_mzv_coeffs`: `n` a whole number of at least 3 (default 3), the
/// duration `t` (or `tau`) short enough that `n > 2 t + 1`.
fn mzv(values: &[Option<(String, f64)>]) -> Result<(), String> {
    let n = match &values[0] {
        Some((text, v)) if !text.contains('.') => *v,
        Some((text, _)) => return Err(format!("`n` must be a whole number, got `{text}`")),
        None => 3.0,
    };
    if n < 3.0 {
        return Err(format!("`n` = {n} is too small: at least 3"));
    }
    let t = values[1].as_ref().map_or(0.0, |(_, v)| *v);
    let tau = values[2].as_ref().map_or(0.0, |(_, v)| *v);
    let t = if tau != 0.0 {
        tau * (n - 1.0) / (n + 2.0 * tau - 2.0)
    } else if t == 0.0 {
        MZV_DEFAULT_T
    } else {
        t
    };
    if n <= 2.0 * t + 1.0 + 1e-7 {
        return Err(format!(
            "t = {t} is too large for n = {n}: t must be below {}",
            0.5 * (n - 1.0)
        ));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_parameters() {
        for ok in [
            "zv",
            "mzv",
            "3hump_ei",
            "mzv(n=4,t=0.8)",
            "mzv (n = 4, tau = 1.2)",
            "mzv(4,0.8)",
            "ei(v_tol=0.03)",
            "ei(0.03)",
            "mzv()",
            "mzv(t=0)",
        ] {
            assert!(check(ok).is_ok(), "{ok}: {:?}", check(ok));
        }
        assert_eq!(check("ei").map(|f| f.max_damping_ratio), Ok(0.4));
        for (bad, why) in [
            ("MZV", "lower case"),
            ("zvdd", "not a Klipper shaper"),
            ("mzv(n=4", "end the text"),
            ("mzv(n=4,0.8)", "do not mix"),
            ("zv(1)", "no parameters"),
            ("ei(v=0.1)", "no parameter `v`"),
            ("mzv(n=4.0)", "whole number"),
            ("mzv(n=2)", "too small"),
            ("mzv(n=3,t=1)", "too large"),
            ("mzv(n=4,n=5)", "twice"),
            ("ei(v_tol=-0.1)", "decimal number"),
            ("ei(v_tol=1e-2)", "decimal number"),
        ] {
            let e = check(bad).expect_err(bad);
            assert!(e.contains(why), "{bad}: {e}");
        }
    }
}
