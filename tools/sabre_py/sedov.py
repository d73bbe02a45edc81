"""Shock radius of the Sedov-Taylor point blast in a cold uniform ideal gas.

    R(t) = xi0 * (E t^2 / rho)^(1/(n+2)),   xi0 = alpha^(-1/(n+2))

n = 3 spherical (E = total energy), n = 2 cylindrical (E = energy per unit length of
the line source), n = 1 planar (E = energy per unit area, both sides of the plane).

alpha(gamma, n) follows from the energy integral of the self-similar solution.  This
module computes it by integrating the similarity ODEs from the strong-shock state at
xi = 1 inwards (see `alpha`; scipy.integrate.solve_ivp), and keeps the gamma = 1.4 values
as constants:

    geometry      n   alpha (computed)   xi0 = alpha^(-1/(n+2))
    cylindrical   2   0.98407402         1.00402161
    spherical     3   0.85107185         1.03277747
    (planar       1   1.077486           0.975430, both half-spaces counted)

Checked against published numbers by `python3 -m sabre_py.sedov` (run from tools/;
the regression case sedov_constants):
  - spherical, gamma 1.4: alpha = 0.851072 (J. R. Kamm and F. X. Timmes, "On
    efficient generation of numerically robust Sedov solutions", LA-UR-07-2849, 2007,
    the 'standard' Sedov test: E = 0.851072 puts the shock at r = 1 at t = 1), i.e.
    xi0 = 1.032777; G. I. Taylor (Proc. R. Soc. A 201, 1950) quoted 1.033.
  - spherical, gamma 5/3: xi0 = 1.15167 (xi0^5 = 2.026, the constant commonly quoted
    for supernova remnants), a second check of the integrator.
`profile(r, t, E, rho)` gives the exact state (rho, u, p) at radii r from the same ODEs
integrated with dense output (tools/blast_compare's error against the exact blast; the
check below: the profile holds the energy E and the strong-shock jump of 6 in density).
The cylindrical constant is this integrator's own (the same ODEs and quadrature that
reproduce both spherical numbers to 1e-7); no published cylindrical value was at hand
to compare with when it was written.
Source of the method: L. I. Sedov, Similarity and Dimensional Methods in Mechanics
(1959), ch. IV; the ODEs below are the Euler equations under the ansatz
u = D phi(xi), rho = rho0 g(xi), p = rho0 D^2 h(xi), D = dR/dt = delta R/t,
delta = 2/(n+2).
"""
import math

import numpy as np
from scipy.integrate import solve_ivp

__all__ = ["alpha", "xi0", "shock_radius", "shock_speed", "profile", "ALPHA", "XI0"]

# gamma = 1.4, computed with alpha() below and checked in __main__
ALPHA = {(1.4, 2): 0.98407402, (1.4, 3): 0.85107185}
XI0 = {k: a ** (-1.0 / (k[1] + 2)) for k, a in ALPHA.items()}

_AREA = {1: 2.0, 2: 2.0 * math.pi, 3: 4.0 * math.pi}  # surface measure A_n r^(n-1)


def _rhs(xi, y, gamma, n, k):
    """d/dxi of (g, phi, h) and of the energy integral, from the similarity ODEs
        mass:      w g' + g phi' = -(n-1) g phi / xi            (w = phi - xi)
        momentum:  w phi' + h'/g = -k phi                        (k = (delta-1)/delta)
        entropy:   w h' - gamma (h/g) w g' = -2 k h
    solved for the three derivatives by elimination."""
    g, phi, h = y[0], y[1], y[2]
    w = phi - xi
    b1, b2, b3 = -(n - 1) * g * phi / xi, -k * phi, -2.0 * k * h
    dphi = (b2 - b3 / (g * w) - gamma * h * b1 / (g * g * w)) / (w - gamma * h / (g * w))
    dg = (b1 - g * dphi) / w
    dh = b3 / w + gamma * (h / g) * dg
    de = _AREA[n] * xi ** (n - 1) * (0.5 * g * phi * phi + h / (gamma - 1.0))
    return (dg, dphi, dh, de)


def _integrate(gamma, n, xi_min, dense=False):
    """The similarity ODEs integrated from the strong-shock state at xi = 1 down to xi_min in
    s = ln(xi) (the solution is smooth in s) with scipy's 8th-order Runge-Kutta (DOP853) at
    a relative tolerance of 1e-12; y = (g, phi, h, energy integral from 1)."""
    if n not in _AREA:
        raise ValueError("n must be 1 (planar), 2 (cylindrical) or 3 (spherical)")
    if not gamma > 1.0:
        raise ValueError("gamma must be > 1")
    delta = 2.0 / (n + 2.0)
    k = (delta - 1.0) / delta
    y0 = [(gamma + 1.0) / (gamma - 1.0), 2.0 / (gamma + 1.0), 2.0 / (gamma + 1.0), 0.0]

    def f(s, y):
        xi = math.exp(s)
        return [xi * d for d in _rhs(xi, y, gamma, n, k)]  # d/ds = xi d/dxi

    sol = solve_ivp(f, (0.0, math.log(xi_min)), y0, method="DOP853", rtol=1e-12,
                    atol=1e-14, dense_output=dense)
    if not sol.success:
        raise ValueError("the Sedov similarity ODEs did not integrate: %s" % sol.message)
    return sol


def alpha(gamma=1.4, n=3, xi_min=1e-8):
    """Energy constant alpha: E = alpha rho R^(n+2) / t^2 for a cold uniform gas.

    Integrates the similarity ODEs from the strong-shock state at xi = 1 down to xi_min
    (`_integrate`; the part of the energy inside xi_min is negligible)."""
    delta = 2.0 / (n + 2.0)
    return delta * delta * -_integrate(gamma, n, xi_min).y[3, -1]  # y[3] = int_1^xi_min < 0


def xi0(gamma=1.4, n=3):
    """xi0 = alpha^(-1/(n+2)); tabulated for gamma 1.4, n = 2, 3, else computed."""
    key = (round(float(gamma), 12), int(n))
    if key in XI0:
        return XI0[key]
    return alpha(gamma, n) ** (-1.0 / (n + 2))


def shock_radius(t, energy, rho, n=3, gamma=1.4):
    """R(t) = xi0 (E t^2 / rho)^(1/(n+2)); E per unit length for n = 2."""
    t = np.asarray(t, dtype=float)
    return xi0(gamma, n) * (energy * t * t / rho) ** (1.0 / (n + 2))


def shock_speed(t, energy, rho, n=3, gamma=1.4):
    """dR/dt = (2/(n+2)) R/t."""
    t = np.asarray(t, dtype=float)
    return 2.0 / (n + 2) * shock_radius(t, energy, rho, n, gamma) / t


def profile(r, t, energy, rho, n=3, gamma=1.4, p_ambient=0.0, xi_min=1e-6):
    """The exact self-similar state at radii r and time t: (rho, u, p) arrays of r's shape.

    Behind the shock rho = rho0 g(xi), u = D phi(xi), p = rho0 D^2 h(xi) with xi = r/R(t)
    and D = dR/dt (the ODEs of `_rhs`, integrated once with dense output); ahead of it
    (xi > 1) the gas at rest, rho0 and p_ambient.  The strong-shock solution holds for
    p_ambient << rho0 D^2; inside xi_min the values at xi_min (the centre, where g -> 0)."""
    r = np.asarray(r, dtype=float)
    radius = float(shock_radius(t, energy, rho, n, gamma))
    speed = float(shock_speed(t, energy, rho, n, gamma))
    sol = _integrate(gamma, n, xi_min, dense=True)
    xi = r / radius
    inside = xi <= 1.0
    s = np.log(np.clip(xi[inside], xi_min, 1.0))
    g, phi, h = sol.sol(s)[:3] if s.size else (np.empty(0),) * 3
    density = np.full(r.shape, float(rho))
    velocity = np.zeros(r.shape)
    pressure = np.full(r.shape, float(p_ambient))
    density[inside] = rho * g
    velocity[inside] = speed * phi
    pressure[inside] = rho * speed * speed * h
    return density, velocity, pressure


if __name__ == "__main__":
    import sys
    failures = 0
    checks = [((1.4, 3), "alpha", 0.851072, 1e-6), ((1.4, 3), "xi0", 1.032777, 1e-6),
              ((5.0 / 3.0, 3), "xi0", 1.15167, 5e-6)]
    for (g, n), what, ref, tol in checks:
        a = alpha(g, n)
        got = a if what == "alpha" else a ** (-1.0 / (n + 2))
        ok = abs(got - ref) <= tol * abs(ref) + 5e-7
        failures += not ok
        print("%s gamma=%.6g n=%d %s = %.8f published %.6f"
              % ("ok  " if ok else "FAIL", g, n, what, got, ref))
    for (g, n), a_tab in ALPHA.items():
        a = alpha(g, n)
        ok = abs(a - a_tab) <= 1e-8
        failures += not ok
        print("%s gamma=%.6g n=%d alpha = %.10f tabulated %.8f xi0 = %.6f"
              % ("ok  " if ok else "FAIL", g, n, a, a_tab, a ** (-1.0 / (n + 2))))
    # the profile: the strong-shock jump just inside R, ambient just outside, and the
    # energy of the profile (kinetic + internal over the ball) equal to E
    e_blast, t_end = 1.0, 1.0
    radius = float(shock_radius(t_end, e_blast, 1.0))
    r = np.linspace(0.0, radius, 200001)[1:]
    d, u, p = profile(r, t_end, e_blast, 1.0)
    dens = (0.5 * d * u * u + p / 0.4) * 4.0 * math.pi * r * r
    total = float(np.sum(0.5 * (dens[1:] + dens[:-1]) * np.diff(r)))
    jump = profile(np.array([radius * (1 - 1e-12), radius * (1 + 1e-12)]), t_end, e_blast, 1.0)[0]
    ok = abs(total - e_blast) < 1e-4 and abs(jump[0] - 6.0) < 1e-6 and jump[1] == 1.0
    failures += not ok
    print("%s profile gamma=1.4 n=3: energy of the profile %.6f (E = 1), rho behind the shock "
          "%.6f (6), ahead %.1f" % ("ok  " if ok else "FAIL", total, jump[0], jump[1]))
    sys.exit(1 if failures else 0)
