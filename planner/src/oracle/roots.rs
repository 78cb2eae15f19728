//! Robust scalar root finding for the planners' one-parameter families: bracket on a
//! grid refined at structural knots and domain edges, catch close root pairs by
//! golden-section search, bisect to full precision.

/// Every root of `g` on `[first, last]` of the sorted `knots`, bracketed on a grid that
/// refines each knot interval, then bisected to full precision.
pub fn roots(g: &dyn Fn(f64) -> Option<f64>, knots: &[f64]) -> Vec<f64> {
    const SUB: usize = 16;
    let mut grid = Vec::with_capacity(knots.len() * SUB);
    for w in knots.windows(2) {
        for k in 0..SUB {
            grid.push(w[0] + (w[1] - w[0]) * k as f64 / SUB as f64);
        }
    }
    if let Some(&last) = knots.last() {
        grid.push(last);
    }
    let mut pts: Vec<(f64, Option<f64>)> = Vec::with_capacity(grid.len() + 8);
    for &x in &grid {
        let gx = g(x);
        // Where the domain of g ends between two grid points, add its edge (bisected), so
        // roots next to it are bracketed too.
        if let Some(&(xp, gp)) = pts.last()
            && gp.is_some() != gx.is_some()
        {
            {
                let (mut valid, mut invalid) = if gp.is_some() { (xp, x) } else { (x, xp) };
                for _ in 0..200 {
                    let mid = 0.5 * (valid + invalid);
                    if mid == valid || mid == invalid {
                        break;
                    }
                    if g(mid).is_some() {
                        valid = mid;
                    } else {
                        invalid = mid;
                    }
                }
                if valid != xp && valid != x {
                    pts.push((valid, g(valid)));
                }
            }
        }
        pts.push((x, gx));
    }
    // Where |g| has a local minimum between samples without a sign change, g may dip
    // through zero and back (two close roots): find the extremum by golden-section search
    // and, if it crosses zero, split the interval there.
    let mut i = 1;
    while i + 1 < pts.len() {
        if let ((xa, Some(ga)), (_, Some(gb)), (xc, Some(gc))) = (pts[i - 1], pts[i], pts[i + 1])
            && ga.signum() == gb.signum()
            && gc.signum() == gb.signum()
            && gb.abs() <= ga.abs()
            && gb.abs() <= gc.abs()
            && let Some((xm, gm)) = golden_min(&|x| g(x).map(|v| v * gb.signum()), xa, xc)
            && gm < 0.0
        {
            let at = if xm < pts[i].0 { i } else { i + 1 };
            pts.insert(at, (xm, Some(gm * gb.signum())));
            i += 1;
        }
        i += 1;
    }
    let mut out = Vec::new();
    for i in 0..pts.len() {
        let (xi, Some(gi)) = pts[i] else { continue };
        if gi == 0.0 {
            out.push(xi);
            continue;
        }
        let Some(&(xn, Some(gn))) = pts.get(i + 1) else {
            continue;
        };
        if gi.signum() != gn.signum() && gn != 0.0 {
            out.push(bisect(g, xi, gi, xn, gn));
        }
    }
    out
}

/// The root of `g` in `[lo, hi]` (`g(lo) = glo` and `g(hi) = ghi` of opposite signs), to
/// full precision: regula falsi with the Illinois modification (superlinear on smooth
/// pieces), falling back to bisection whenever a step would not shrink the bracket.
fn bisect(g: &dyn Fn(f64) -> Option<f64>, lo: f64, glo: f64, hi: f64, ghi: f64) -> f64 {
    let (mut lo, mut hi, mut glo, mut ghi) = (lo, hi, glo, ghi);
    let mut side = 0i8;
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo.min(hi) || mid >= hi.max(lo) {
            break;
        }
        let mut x = hi - ghi * (hi - lo) / (ghi - glo);
        if !(x > lo.min(hi) && x < lo.max(hi)) {
            x = mid;
        }
        let Some(gx) = g(x) else { break };
        if gx == 0.0 {
            return x;
        }
        if gx.signum() == ghi.signum() {
            hi = x;
            ghi = gx;
            if side == 1 {
                glo *= 0.5;
            }
            side = 1;
        } else {
            lo = x;
            glo = gx;
            if side == -1 {
                ghi *= 0.5;
            }
            side = -1;
        }
        // The halved values are only weights: stop on the bracket, not on them.
        if (hi - lo).abs() <= 4.0 * f64::EPSILON * hi.abs().max(lo.abs()) {
            break;
        }
    }
    let (gl, gh) = (
        g(lo).map_or(f64::INFINITY, f64::abs),
        g(hi).map_or(f64::INFINITY, f64::abs),
    );
    if gl <= gh { lo } else { hi }
}

/// Minimum of `f` on `[a, b]` by golden-section search (f assumed unimodal there).
fn golden_min(f: &dyn Fn(f64) -> Option<f64>, a: f64, b: f64) -> Option<(f64, f64)> {
    const R: f64 = 0.618_033_988_749_894_9;
    let (mut a, mut b) = (a, b);
    let mut c = b - R * (b - a);
    let mut d = a + R * (b - a);
    let (mut fc, mut fd) = (f(c)?, f(d)?);
    for _ in 0..100 {
        if fc < 0.0 {
            return Some((c, fc));
        }
        if fd < 0.0 {
            return Some((d, fd));
        }
        if fc < fd {
            b = d;
            d = c;
            fd = fc;
            c = b - R * (b - a);
            fc = f(c)?;
        } else {
            a = c;
            c = d;
            fc = fd;
            d = a + R * (b - a);
            fd = f(d)?;
        }
        if (b - a).abs() <= 1e-15 * (a.abs() + b.abs()) {
            break;
        }
    }
    Some(if fc < fd { (c, fc) } else { (d, fd) })
}
