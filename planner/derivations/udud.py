"""Derivation of the four-arc (UDUD, acceleration touching zero between the halves) case
polynomials used by planner/src/udud.rs. Normalised units: jerk 1. Phases: +1 (a0 ->
A), hold at A = amax, -1 (A -> 0), +1 (0 -> B), hold at B = amax, -1 (B -> af).
Run: python3 planner/derivations/udud.py
"""
from sympy import Poly, expand, factor, fraction, simplify, solve, symbols, together

a0, af, v0, vf, dp, amax, h1, h2, A, B, tau, r = symbols(
    "a0 af v0 vf dp amax h1 h2 A B tau r", real=True
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
    print(name, "degree", num.degree(), "denominator", factor(den))
    for k, c in enumerate(num.all_coeffs()):
        print("  c%d =" % (num.degree() - k), factor(c))


# none: A^2 + B^2 = C = r^2, rational parametrisation of the quarter circle.
Aa = r * (1 - tau**2) / (1 + tau**2)
Bb = r * 2 * tau / (1 + tau**2)
p, v, a = run([(1, Aa - a0), (-1, Aa), (1, Bb), (-1, Bb - af)])
assert simplify(a - af) == 0
show("none (in tau)", expand(simplify((p - dp) * (1 + tau**2) ** 3)), tau)

p, v, a = run([(1, amax - a0), (0, h1), (-1, amax), (1, B), (-1, B - af)])
h = solve(v - vf, h1)[0]
print("h1 =", h)
show("acc0 (in B)", (p - dp).subs(h1, h), B)

p, v, a = run([(1, A - a0), (-1, A), (1, amax), (0, h2), (-1, amax - af)])
h = solve(v - vf, h2)[0]
print("h2 =", h)
show("acc1 (in A)", (p - dp).subs(h2, h), A)

p, v, a = run([(1, amax - a0), (0, h1), (-1, amax), (1, amax), (0, h2), (-1, amax - af)])
h = solve(v - vf, h2)[0]
print("h2 =", h)
show("acc0_acc1 (in h1)", (p - dp).subs(h2, h), h1)
