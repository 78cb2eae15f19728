"""Derivation of the three-arc (UDU) case polynomials used by planner/src/udu.rs.

Normalised units: jerk 1. Phases: +1 for t1 (a0 -> A1), hold h1 at A1 = amax, -1 for t2
(A1 -> A2), hold h2 at A2 = amin, +1 for t3 (A2 -> af). The velocity equation fixes one
unknown, the position equation gives the polynomial printed here (coefficients of the
numerator, highest degree first, divided by the leading coefficient).
Run: python3 planner/derivations/udu.py
"""
from sympy import Poly, expand, factor, fraction, simplify, solve, symbols, together

a0, af, v0, vf, x, dp, amax, amin, h1, h2, s, K = symbols(
    "a0 af v0 vf x dp amax amin h1 h2 s K", real=True
)


def arc(p, v, a, jk, t):
    return (p + v * t + a * t**2 / 2 + jk * t**3 / 6, v + a * t + jk * t**2 / 2, a + jk * t)


def run(segs):
    st = (0, v0, a0)
    for jk, t in segs:
        st = arc(*st, jk, t)
    return st


def show(name, expr, var):
    num, den = fraction(together(expand(expr)))
    num = Poly(expand(num), var)
    lc = num.LC()
    print(name, "denominator", factor(den), "leading", lc)
    for k, c in enumerate(num.all_coeffs()):
        print("  c%d =" % (num.degree() - k), simplify(c / lc))


# none: s = A1 - A2, A1 + A2 = K / s with K = dv - (af^2 - a0^2)/2.
A1 = (s + K / s) / 2
A2 = (K / s - s) / 2
p, v, a = run([(1, A1 - a0), (-1, s), (1, af - A2)])
assert simplify(a - af) == 0
assert simplify((v - vf).subs(K, (vf - v0) - (af**2 - a0**2) / 2)) == 0
show("none (in s)", p - dp, s)

# acc0: A1 = amax with hold h1, x = A2.
p, v, a = run([(1, amax - a0), (0, h1), (-1, amax - x), (1, af - x)])
h = solve(v - vf, h1)[0]
print("h1 =", h)
show("acc0 (in A2)", (p - dp).subs(h1, h), x)

# acc1: A2 = amin with hold h2, x = A1.
p, v, a = run([(1, x - a0), (-1, x - amin), (0, h2), (1, af - amin)])
h = solve(v - vf, h2)[0]
print("h2 =", h)
show("acc1 (in A1)", (p - dp).subs(h2, h), x)

# acc0_acc1: both holds, unknown h1.
p, v, a = run([(1, amax - a0), (0, h1), (-1, amax - amin), (0, h2), (1, af - amin)])
h = solve(v - vf, h2)[0]
print("h2 =", h)
show("acc0_acc1 (in h1)", (p - dp).subs(h2, h), h1)
