"""HMX parameter sets of the material library and their exact shock states under a piston.

The library's HMX sets (modules/strength/m_material_library.f90, manual/materials.md),
re-coded here from their sources (../shared/reference/published-data.md) so that a run can
be checked against numbers that do not come from SABRE:

  hmx_a  the dissertation (section A) as printed: c0 2058 m/s, s 2.38, Gamma0 1.1,
         cv 1000 J/(kg K), no strength
  hmx_b  the PBX study (section B): c0 2901 m/s, s 2.058, Gamma0 1.1, Y 0.37 GPa,
         G 7.2 GPa (cv 1000 from section A)
  hmx_f  Menikoff's EOSlib set (section F): Y 0.26 GPa, G 12 GPa, cv 1500 J/(kg K),
         Gamma0 1.1 and the Hayes EOS (K0 13.5 GPa, N 9.3), whose Hugoniot SABRE's linear
         Us-up form carries as the least-squares fit over up 0.1-1.5 km/s (`hayes_fit`).
         Plain `hmx` is this set.

The shock state behind a piston is the exact elastic-plastic solution of
sabre_py.elastoplastic (hydrodynamic when G = Y = 0); the temperature is SABRE's
Mie-Gruneisen closure (manual/eos-temperature.md) T = T0 exp(Gamma0 eta) + (e_th - e_s)/cv,
eta = 1 - rho0/rho, e_s the reference isentrope through (rho0, p = 0) integrated here with
scipy, and e_th the internal energy less the stored elastic energy J2/(2 G rho) and less the
plastic work that is not heat, (1 - beta) W_p (manual/theory.md 5.7).

The Hayes EOS (Menikoff & Sewell, Combust. Theory Modelling 6 (2002); Gamma/V constant):
    P(V, T) = K0/N ((V0/V)^N - 1) + (Gamma0/V0) cv (T - T0),
    E(V, T) = Phi(V) + cv (T - T0) - cv T0 Gamma0 (1 - V/V0),
    Phi(V) = K0 V0/(N (N - 1)) ((V0/V)^(N-1) - 1) + K0/N (V - V0),
on which the Hugoniot from (V0, T0) is closed exactly (`hayes_hugoniot`).
`python3 -B -m sabre_py.hmx` (from tools/) prints the table of manual/materials.md and the
void's collapse times of manual/hotspots.md (`rayleigh_collapse`).
"""
import math
from collections import namedtuple

import numpy as np
from scipy.integrate import solve_ivp
from scipy.optimize import brentq

from sabre_py import elastoplastic as ep

T0 = 298.0
HmxSet = namedtuple("HmxSet", "name rho0 c0 s gamma0 cv G Y beta source")

# Hayes EOS of Menikoff's set (published-data.md section F)
HAYES_K0, HAYES_N, HAYES_GAMMA0, HAYES_CV, HAYES_RHO0 = 13.5e9, 9.3, 1.1, 1500.0, 1900.0
HAYES_FIT_RANGE = (100.0, 1500.0)


def hayes_state(v):
    """(P, T, up, Us) on the Hayes EOS's Hugoniot from (V0, T0, P = 0) at volume v < V0."""
    v0 = 1.0 / HAYES_RHO0
    k0, n, g0, cv = HAYES_K0, HAYES_N, HAYES_GAMMA0, HAYES_CV
    x, eta = v0 / v, 1.0 - v / v0
    p_cold = k0 / n * (x ** n - 1.0)
    phi = k0 * v0 / (n * (n - 1.0)) * (x ** (n - 1.0) - 1.0) + k0 / n * (v - v0)
    # E - E0 = P (V0 - V)/2 is linear in theta = cv (T - T0)
    theta = (0.5 * p_cold * v0 * eta - phi + cv * T0 * g0 * eta) / (1.0 - 0.5 * g0 * eta)
    p = p_cold + g0 / v0 * theta
    return p, T0 + theta / cv, math.sqrt(p * (v0 - v)), v0 * math.sqrt(p / (v0 - v))


def hayes_hugoniot(up):
    """(P, T, Us, rho) on the Hayes Hugoniot at particle velocity up > 0."""
    v0 = 1.0 / HAYES_RHO0
    v = brentq(lambda vv: hayes_state(vv)[2] - up, 0.5 * v0, v0 * (1.0 - 1e-12), xtol=1e-16,
               rtol=1e-14)
    p, temp, _, us = hayes_state(v)
    return p, temp, us, 1.0 / v


def hayes_fit():
    """(c0, s): least-squares line Us = c0 + s up through the Hayes Hugoniot, up in
    HAYES_FIT_RANGE (the void-collapse studies' 0.5, 1 and 1.5 km/s)."""
    ups = np.linspace(HAYES_FIT_RANGE[0], HAYES_FIT_RANGE[1], 57)
    s, c0 = np.polyfit(ups, [hayes_hugoniot(u)[2] for u in ups], 1)
    return c0, s


SETS = {
    "hmx_a": HmxSet("hmx_a", 1900.0, 2058.0, 2.38, 1.1, 1000.0, 0.0, 0.0, 0.9,
                    "dissertation (section A) as printed"),
    "hmx_b": HmxSet("hmx_b", 1900.0, 2901.0, 2.058, 1.1, 1000.0, 7.2e9, 0.37e9, 0.9,
                    "PBX study (section B); cv of section A"),
    "hmx_f": HmxSet("hmx_f", 1900.0, 2801.0, 2.362, 1.1, 1500.0, 12.0e9, 0.26e9, 0.9,
                    "Menikoff, EOSlib (section F); c0, s = hayes_fit() rounded"),
}
SETS["hmx"] = SETS["hmx_f"]._replace(name="hmx")


def isentrope_energy(mat, rho):
    """e_s(rho): the Mie-Gruneisen reference isentrope through (rho0, e = 0), de/dv = -p."""
    def rate(v, e):
        return [-ep.pressure(mat, 1.0 / v, e[0])]
    return solve_ivp(rate, [1.0 / mat.rho0, 1.0 / rho], [0.0], rtol=1e-12,
                     atol=1e-9).y[0, -1]


def piston_state(hset, up):
    """Exact state behind a piston at up into hset: dict with regime, us (the last wave's
    speed), front (the leading wave's speed), sigma (longitudinal stress, compression
    positive), p, rho, u, e, w_p, w_el, T, dT."""
    mat = ep.Material(hset.name, hset.rho0, hset.c0, hset.s, hset.gamma0, hset.G, hset.Y)
    sol = ep.piston(mat, up)
    f = sol.final
    w_el, w_p = ep.elastic_energy(mat, f), ep.plastic_work(mat, f.rho)
    e_th = f.e - w_el - (1.0 - hset.beta) * w_p
    eta = 1.0 - hset.rho0 / f.rho
    temp = T0 * math.exp(hset.gamma0 * eta) + (e_th - isentrope_energy(mat, f.rho)) / hset.cv
    us = sol.plastic_speed if sol.plastic_speed is not None else sol.precursor_speed
    return dict(regime=sol.regime, us=us, front=sol.precursor_speed, sigma=-f.sigma, p=f.p,
                rho=f.rho, u=f.u, e=f.e, w_p=w_p, w_el=w_el, T=temp, dT=temp - T0,
                c_L=ep.longitudinal_speed(mat))


def rayleigh_collapse(hset, up, radius=5.0e-6, near=10.0e-6, rise_share=0.1):
    """Collapse time of a cylindrical void of this radius whose near side lies `near` from a
    velocity side at up (the scene of decks/void_collapse.nml), read as the dissertation
    reads it (published-data section F): the void collapses in Rayleigh's time
    t_R = 0.915 R sqrt(rho0 / p) once the shock has passed it, p the shocked pressure. So
    t = rise / 2 + (near + 2 R) / Us + t_R, the rise being rise_share of the shock's transit
    to the void (the deck's ramp; half of it delays the shock). Returns a dict with p, us,
    rise, transit (near + 2 R over Us), t_r and t."""
    r = piston_state(hset, up)
    rise = rise_share * near / r["us"]
    transit = (near + 2.0 * radius) / r["us"]
    t_r = 0.915 * radius * math.sqrt(hset.rho0 / r["p"])
    return dict(p=r["p"], us=r["us"], rise=rise, transit=transit, t_r=t_r,
                t=0.5 * rise + transit + t_r)


def main():
    c0, s = hayes_fit()
    print("Hayes EOS Hugoniot, linear fit over up %g-%g m/s: c0 %.1f m/s, s %.4f"
          % (HAYES_FIT_RANGE + (c0, s)))
    for up in (500.0, 1000.0, 1500.0):
        p, temp, us, rho = hayes_hugoniot(up)
        print("  Hayes up %6.0f: Us %7.1f (fit %7.1f), P %.4f GPa, rho %.2f, T %.1f K"
              % (up, us, 2801.0 + 2.362 * up, p / 1e9, rho, temp))
    print("set     regime      Us(m/s) front   sigma(GPa) p(GPa)  rho      T(K)    dT(K)")
    for name in ("hmx_a", "hmx_b", "hmx_f"):
        r = piston_state(SETS[name], 500.0)
        print("%-7s %-11s %7.1f %7.1f %.4f     %.4f  %.2f  %.2f  %.2f"
              % (name, r["regime"], r["us"], r["front"], r["sigma"] / 1e9, r["p"] / 1e9,
                 r["rho"], r["T"], r["dT"]))
    print("void collapse (R 5 um, near side 10 um from the velocity side), hmx_f:")
    print("  up(m/s) p(GPa)  Us(m/s) rise(ns) transit(ns) t_R(ns) rise/2+transit+t_R(ns)")
    for up in (500.0, 1000.0, 1500.0):
        c = rayleigh_collapse(SETS["hmx_f"], up)
        print("  %6.0f  %.3f  %7.1f  %.3f    %.3f       %.3f   %.3f"
              % (up, c["p"] / 1e9, c["us"], c["rise"] * 1e9, c["transit"] * 1e9,
                 c["t_r"] * 1e9, c["t"] * 1e9))


if __name__ == "__main__":
    main()
