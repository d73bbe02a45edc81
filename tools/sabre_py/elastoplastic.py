"""Exact 1D piston problem for an elastic-plastic solid in uniaxial strain.

A half-space x > 0 of a solid at rest (rho0, u = 0, p = 0, S = 0, e = 0) is pushed from
t = 0 by a piston at constant velocity u_p > 0 (no rise time).  The solid is the one SABRE
models: hypo-elastic deviatoric stress S (shear modulus G, Jaumann rate: no spin in 1D),
von Mises yield (Y, optional linear hardening H; H = 0 is perfectly plastic), and a
Mie-Gruneisen pressure on the linear Us-up Hugoniot (c0, s, Gamma0 rho = Gamma0 rho0):

    p(rho, e) = p_H(rho) + Gamma0 rho0 (e - e_H(rho)),                          (2)
    p_H = rho0 c0^2 eta / (1 - s eta)^2,  e_H = p_H eta / (2 rho0),  eta = 1 - rho0/rho,

(p_H = rho0 c0^2 (rho/rho0 - 1) in expansion, as in modules/eos/m_eos.f90).  Stress is
tension-positive: sigma = sigma_xx = -p + S, S = S_xx (S_yy = S_zz = -S/2).

Constitutive path in uniaxial compression (equation numbers as in the manual page
manual/elastic-plastic-piston.md):
    D_xx = du/dx = -(1/rho) drho/dt,  D'_xx = (2/3) D_xx,  dS/dt = 2 G D'_xx
      => elastic: S = -(4/3) G ln(rho/rho0)                                     (4)
    von Mises: sigma_eq = (3/2)|S| = Y  =>  yield at ln(rho/rho0) = Y/(2G)        (5)
    plastic (monotone loading): eps_p = (2/3)(ln(rho/rho0) - Y/(2G)) / (1 + H/(3G)),
      S = -(2/3)(Y + H eps_p)                                                   (6)
so S is a function of rho alone for monotone compression, whatever the path through a
shock's structure: the jump conditions below are closed without a shock-path assumption.
(For comparison with other solvers a Material may instead take the infinitesimal-strain
law S = -(4/3) G (1 - rho0/rho) (elastic='linear') and Gamma = Gamma0 in place of
Gamma rho = Gamma0 rho0 (gamma_form='const'); SABRE's model is the default.)

Energy: e is the specific internal energy that SABRE's EOS takes, and SABRE's energy
equation puts the whole stress power into it, rho de/dt = sigma_xx D_xx, i.e.
de = sigma dv (v = 1/rho): e includes the deviatoric (elastic plus dissipated) work.

Rankine-Hugoniot across a shock of lab speed D, ahead state a, behind state b, with the
mass flux m = rho_a (D - u_a) = rho_b (D - u_b) > 0:
    m^2 = (sigma_a - sigma_b) / (v_a - v_b),   u_b = u_a + m (v_a - v_b),        (9, 10)
    e_b - e_a = (sigma_a + sigma_b)/2 (v_b - v_a).                              (11)
With (2) and S_b = S(rho_b), (11) is linear in e_b and is solved exactly (eq 12); the
density behind is the root of u_b(rho_b) = u_p (scipy.optimize.brentq).

Waves: an elastic precursor (a weak shock, solved exactly, not linearised) from rest to
the Hugoniot elastic limit (HEL, rho_HEL = rho0 exp(Y/(2G))), then a plastic shock from
the HEL state to u = u_p.  u_p <= u_HEL: the elastic shock alone.  Plastic shock at least
as fast as the precursor: one overdriven shock from rest.  The small-amplitude precursor
speed is c_L = sqrt(c0^2 + (4/3) G/rho0).

Sources: M. L. Wilkins, "Calculation of elastic-plastic flow", Methods in Computational
Physics 3 (1964) 211-263 (hypo-elastic stress, von Mises radial return, e with the
deviatoric work); the two-wave structure and the HEL of uniaxial strain as in M. A.
Meyers, Dynamic Behavior of Materials (Wiley 1994).  LANL ExactPack's ep_piston solves
the same problem with the same jump formulation; with its constitutive choices
(elastic='linear', gamma_form='const') this module reproduces its published unit-test
values (regress/unit/test_elastoplastic_exact).  The formulas are derived in
manual/elastic-plastic-piston.md.  `python3 -B -m sabre_py.elastoplastic` (from tools/)
prints the verification cases.
"""
import math
from collections import namedtuple

import numpy as np
from scipy.integrate import quad
from scipy.optimize import brentq

__all__ = ["Material", "State", "PistonSolution", "MATERIALS", "ElastoPlasticError",
           "reference_curve", "pressure", "deviator", "elastic_energy", "plastic_work",
           "rest_state", "shock_from", "solve_shock",
           "hel_state", "piston", "hydro_hugoniot", "longitudinal_speed",
           "plastic_sound_speed"]


class ElastoPlasticError(ValueError):
    """Bad material parameters or piston speed, or no solution."""


_MaterialBase = namedtuple("Material", "name rho0 c0 s gamma0 G Y H elastic gamma_form")


class Material(_MaterialBase):
    """Material(name, rho0, c0, s, gamma0, G, Y, H=0, elastic='hypo', gamma_form='rho0'):
    SI units (kg/m3, m/s, Pa).

    G = 0: no deviatoric stress (hydrodynamic).  Y = inf: purely elastic.
    H: linear hardening modulus, sigma_y = Y + H eps_p (0 = perfectly plastic).
    elastic: 'hypo' (SABRE: S = -(4/3) G ln(rho/rho0)) or 'linear' (infinitesimal-strain
      hyper-elasticity, S = -(4/3) G (1 - rho0/rho)), for comparison with other solvers.
    gamma_form: 'rho0' (SABRE: Gamma rho = Gamma0 rho0 in eq 1) or 'const' (Gamma = Gamma0,
      p = p_H + Gamma0 rho (e - e_H)), for comparison with other solvers."""

    def __new__(cls, name, rho0, c0, s, gamma0, G, Y, H=0.0, elastic="hypo",
                gamma_form="rho0"):
        vals = [float(v) for v in (rho0, c0, s, gamma0, G, Y, H)]
        rho0, c0, s, gamma0, G, Y, H = vals
        if not (rho0 > 0 and c0 > 0 and s >= 0 and gamma0 >= 0 and G >= 0 and Y >= 0
                and H >= 0) or not all(math.isfinite(v) for v in vals if v != Y):
            raise ElastoPlasticError("need rho0, c0 > 0 and s, Gamma0, G, Y, H >= 0: %r"
                                     % (vals,))
        if elastic not in ("hypo", "linear") or gamma_form not in ("rho0", "const"):
            raise ElastoPlasticError("elastic must be 'hypo' or 'linear', "
                                     "gamma_form 'rho0' or 'const'")
        return _MaterialBase.__new__(cls, name, rho0, c0, s, gamma0, G, Y, H, elastic,
                                     gamma_form)


# The issue-3 verification materials (published-data.md section A; aluminium: the issue's)
MATERIALS = {
    "aluminium": Material("aluminium", 2790.0, 5330.0, 1.34, 2.0, 28.6e9, 0.26e9),
    "copper": Material("copper", 8930.0, 3940.0, 1.49, 2.0, 43.33e9, 0.40e9),
}

State = namedtuple("State", "rho u p sxx sigma e eps_p")
State.__doc__ = """Uniform state: density, velocity, pressure p(rho, e), deviator S_xx,
total stress sigma_xx = -p + S_xx (tension positive), specific internal energy e (with the
deviatoric work), effective plastic strain."""


def reference_curve(mat, rho):
    """(p_H, e_H) of eq (2); compression and (linear p_H) expansion branches."""
    eta = 1.0 - mat.rho0 / rho
    k0 = mat.rho0 * mat.c0 ** 2
    if eta >= 0.0:
        den = 1.0 - mat.s * eta
        if den <= 0.0:
            raise ElastoPlasticError("compression beyond the Hugoniot limit eta = 1/s")
        ph = k0 * eta / den ** 2
    else:
        ph = k0 * (rho / mat.rho0 - 1.0)
    return ph, 0.5 * ph * eta / mat.rho0


def _gamma_rho(mat, rho):
    """Gamma rho of eq (2): Gamma0 rho0 (SABRE) or Gamma0 rho (gamma_form 'const')."""
    return mat.gamma0 * (mat.rho0 if mat.gamma_form == "rho0" else rho)


def pressure(mat, rho, e):
    """Mie-Gruneisen p(rho, e), eq (2)."""
    ph, eh = reference_curve(mat, rho)
    return ph + _gamma_rho(mat, rho) * (e - eh)


def _strain(mat, rho):
    """Compressive strain measure of the elastic law: ln(rho/rho0) (hypo, eq 4) or
    1 - rho0/rho (linear), and its derivative d/drho."""
    if mat.elastic == "hypo":
        return math.log(rho / mat.rho0), 1.0 / rho
    return 1.0 - mat.rho0 / rho, mat.rho0 / rho ** 2


def _density_at_strain(mat, eps):
    """Inverse of _strain; inf when the strain cannot be reached."""
    if mat.elastic == "hypo":
        return mat.rho0 * math.exp(eps) if eps < 700.0 else math.inf
    return mat.rho0 / (1.0 - eps) if eps < 1.0 else math.inf


def _yield_strain(mat):
    """Strain at first yield, Y/(2G) (eq 5); inf when it never yields."""
    if mat.G == 0.0 or math.isinf(mat.Y):
        return math.inf
    return mat.Y / (2.0 * mat.G)


def deviator(mat, rho):
    """(S_xx, eps_p) after monotone uniaxial compression from rho0 to rho (eqs 4-6)."""
    if rho < mat.rho0:
        raise ElastoPlasticError("the constitutive path here is for compression only")
    if mat.G == 0.0:
        return 0.0, 0.0
    eps = _strain(mat, rho)[0]
    ly = _yield_strain(mat)
    if eps <= ly:
        return -4.0 / 3.0 * mat.G * eps, 0.0
    eps_p = 2.0 / 3.0 * (eps - ly) / (1.0 + mat.H / (3.0 * mat.G))
    return -2.0 / 3.0 * (mat.Y + mat.H * eps_p), eps_p


def elastic_energy(mat, st):
    """Stored elastic shear energy per unit mass, J2/(2 G rho) = 3 S_xx^2/(8 G rho)."""
    return 0.0 if mat.G == 0.0 else 3.0 * st.sxx ** 2 / (8.0 * mat.G * st.rho)


def plastic_work(mat, rho):
    """Plastic work per unit mass on the monotone path from rho0 to rho (eq 6):
    int sigma_y d(eps_p) / rho; (2/3) Y (1/rho_HEL - 1/rho) in the hypo-elastic, perfectly
    plastic case.  Path-independent for the same reason as S (eq 6)."""
    ly = _yield_strain(mat)
    rho_y = _density_at_strain(mat, ly) if math.isfinite(ly) else math.inf
    if not rho > rho_y:
        return 0.0
    if mat.H == 0.0 and mat.elastic == "hypo":
        return 2.0 / 3.0 * mat.Y * (1.0 / rho_y - 1.0 / rho)
    k = 1.0 / (1.0 + mat.H / (3.0 * mat.G))

    def dwork(r):  # sigma_y d(eps_p)/d(rho) / rho
        return (mat.Y + mat.H * deviator(mat, r)[1]) * (2.0 / 3.0) * k * _strain(mat, r)[1] / r

    return quad(dwork, rho_y, rho, epsabs=0.0, epsrel=1e-12)[0]  # adaptive (QUADPACK)


def rest_state(mat):
    return State(mat.rho0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)


def shock_from(mat, a, rho_b):
    """(state behind, lab shock speed D) for a right-moving shock from state a to density
    rho_b > a.rho, from eqs (9)-(12).  a must lie on the monotone compression path from
    rest (rest itself or the HEL), so that S_b = S(rho_b).  Raises if the jump is not
    compressive."""
    sb, eps_p = deviator(mat, rho_b)
    ph, eh = reference_curve(mat, rho_b)
    g = _gamma_rho(mat, rho_b)
    va, vb = 1.0 / a.rho, 1.0 / rho_b
    dv = vb - va
    den = 1.0 + 0.5 * g * dv
    if not (dv < 0.0 and den > 0.0):
        raise ElastoPlasticError("no compressive shock to rho = %r" % rho_b)
    # eq (12): e_b (1 + g dv/2) = e_a + (sigma_a + S_b - p_H + g e_H) dv/2
    eb = (a.e + 0.5 * (a.sigma + sb - ph + g * eh) * dv) / den
    pb = ph + g * (eb - eh)
    sigb = -pb + sb
    m2 = (a.sigma - sigb) / (va - vb)
    if not m2 > 0.0:
        raise ElastoPlasticError("the stress does not rise across the jump to rho = %r"
                                 % rho_b)
    m = math.sqrt(m2)
    ub = a.u + m * (va - vb)
    return State(rho_b, ub, pb, sb, sigb, eb, eps_p), a.u + m * va


def _rho_limit(mat, a):
    """Largest density a shock from state a can reach (u_b -> infinity below it)."""
    lim = mat.rho0 / (1.0 - 1.0 / mat.s) if mat.s > 1.0 else math.inf
    if mat.gamma0 > 0.0:  # denominator of eq (12): 1 - (Gamma rho)_b (v_a - v_b)/2 > 0
        if mat.gamma_form == "rho0":
            vmin = 1.0 / a.rho - 2.0 / (mat.gamma0 * mat.rho0)
            if vmin > 0.0:
                lim = min(lim, 1.0 / vmin)
        else:
            lim = min(lim, a.rho * (1.0 + 2.0 / mat.gamma0))
    return lim


def solve_shock(mat, a, u_target):
    """Shock from state a whose state behind moves at u_target > a.u: (state, D).

    u_b increases with rho_b on the Hugoniot: rho_b is the root of u_b(rho_b) = u_target,
    bracketed between a.rho and the limiting compression and found by scipy's brentq."""
    if not u_target > a.u:
        raise ElastoPlasticError("the piston must be faster than the state ahead")

    def du(rho):
        try:
            return shock_from(mat, a, rho)[0].u - u_target
        except ElastoPlasticError:
            # a jump too small to resolve (sigma_b == sigma_a to round-off) moves nothing;
            # otherwise we are at or past the limiting compression
            return a.u - u_target if rho - a.rho < 1e-8 * a.rho else math.inf

    lim = _rho_limit(mat, a)
    lo = a.rho
    if math.isfinite(lim):
        # u_b -> infinity at lim: halve towards lo until u_b there is finite and too fast
        hi = lim
        while not 0.0 <= du(hi) < math.inf:
            mid = 0.5 * (lo + hi)
            if mid <= lo or mid >= hi:
                raise ElastoPlasticError("piston too fast: u_p = %r is beyond the Hugoniot"
                                         % u_target)
            if du(mid) < 0.0:
                lo = mid
            else:
                hi = mid
    else:  # no limiting compression (s <= 1 and Gamma0 = 0): double until bracketed
        hi = 2.0 * a.rho
        while du(hi) < 0.0:
            lo, hi = hi, 2.0 * hi
            if hi > 1e6 * a.rho:
                raise ElastoPlasticError("no shock found to u = %r" % u_target)
    rho = brentq(du, lo, hi, xtol=1e-300, rtol=4.0 * np.finfo(float).eps, maxiter=500)
    return shock_from(mat, a, rho)


def longitudinal_speed(mat):
    """Small-amplitude longitudinal elastic wave speed at rest, sqrt(c0^2 + 4G/(3 rho0))."""
    return math.sqrt(mat.c0 ** 2 + 4.0 * mat.G / (3.0 * mat.rho0))


def plastic_sound_speed(mat, st):
    """Small-amplitude plastic wave speed relative to the material in a state st on the
    yield surface (a weak plastic shock from st moves at st.u + this in the lab).
    Perfectly plastic: c^2 = dp/drho|_e + Gamma rho (p - S)/rho^2 (de = -(p - S) dv with
    S fixed); hardening adds (4/9) H (1 + H/(3G))^-1 d(strain)/drho (eq 6)."""
    k0 = mat.rho0 * mat.c0 ** 2
    eta = 1.0 - mat.rho0 / st.rho
    deta = mat.rho0 / st.rho ** 2
    den = 1.0 - mat.s * eta
    dph = k0 * (1.0 + mat.s * eta) / den ** 3 * deta
    ph = k0 * eta / den ** 2
    eh = 0.5 * ph * eta / mat.rho0
    deh = 0.5 * (dph * eta + ph * deta) / mat.rho0
    g = _gamma_rho(mat, st.rho)
    dg = 0.0 if mat.gamma_form == "rho0" else mat.gamma0
    c2 = dph - g * deh + dg * (st.e - eh) + g * (st.p - st.sxx) / st.rho ** 2
    if mat.H > 0.0 and mat.G > 0.0:
        c2 += 4.0 / 9.0 * mat.H / (1.0 + mat.H / (3.0 * mat.G)) * _strain(mat, st.rho)[1]
    return math.sqrt(c2)


def hel_state(mat):
    """(HEL state, precursor speed) of the elastic shock from rest to first yield;
    (None, c_L) when the material never yields (G = 0, Y = inf, or a yield strain
    Y/(2G) beyond the limiting compression of the Hugoniot)."""
    ly = _yield_strain(mat)
    if math.isinf(ly):
        return None, longitudinal_speed(mat)
    if ly == 0.0:  # Y = 0: yields at once, the precursor has no amplitude
        return rest_state(mat), longitudinal_speed(mat)
    lim = _rho_limit(mat, rest_state(mat))
    rho = _density_at_strain(mat, ly)
    if rho >= lim:  # yields beyond any reachable compression
        return None, longitudinal_speed(mat)
    st, d = shock_from(mat, rest_state(mat), rho)
    sb = -2.0 / 3.0 * mat.Y  # exactly on the yield surface (eq 5)
    return st._replace(sxx=sb, sigma=-st.p + sb), d


def hydro_hugoniot(mat, up):
    """Hydrodynamic Hugoniot from rest: (Us, p = rho0 Us up, rho = rho0 Us/(Us - up))."""
    us = mat.c0 + mat.s * up
    return us, mat.rho0 * us * up, mat.rho0 * us / (us - up)


class PistonSolution:
    """Exact piston solution; see piston().  Attributes:
      material, up
      regime            'elastic' (one elastic shock), 'two-wave' (elastic precursor +
                        plastic shock) or 'overdriven' (one plastic shock)
      precursor_speed   lab speed of the leading shock (the elastic precursor; the single
                        shock when regime is 'overdriven')
      hel               HEL state (None unless 'two-wave')
      u_hel             particle velocity of the HEL state (None if it never yields)
      plastic_speed     lab speed of the plastic shock (None when 'elastic'; equal to
                        precursor_speed when 'overdriven'; u_HEL + c_pl, the acoustic
                        limit, when u_p is within 1e-9 of u_HEL)
      final             state behind the last wave (u = up)
      hel_overdrive     (regime 'overdriven') the two-wave plastic speed that exceeded
                        the precursor, for the record
    """

    def __init__(self, material, up, regime, precursor_speed, hel, u_hel, plastic_speed,
                 final, hel_overdrive=None):
        self.material, self.up, self.regime = material, up, regime
        self.precursor_speed, self.hel, self.u_hel = precursor_speed, hel, u_hel
        self.plastic_speed, self.final = plastic_speed, final
        self.hel_overdrive = hel_overdrive

    def waves(self):
        """[(speed, state behind)] from the leading wave backwards."""
        if self.regime == "two-wave":
            return [(self.precursor_speed, self.hel), (self.plastic_speed, self.final)]
        return [(self.precursor_speed, self.final)]

    def state(self, x, t, x0=0.0):
        """Sample (rho, u, p, sxx, e) at points x (array) and time t > 0; the piston
        started at x0.  Every point behind the last wave gets the final state, including
        x < x0 + up t: that is inflowing material through an Eulerian velocity boundary
        at x0 (the Lagrangian piston face is at x0 + up t)."""
        x = np.asarray(x, dtype=float)
        if not t > 0.0:
            raise ElastoPlasticError("time must be > 0, got %r" % t)
        xi = (x - x0) / t
        rest = rest_state(self.material)
        out = [np.full(x.shape, getattr(rest, k)) for k in ("rho", "u", "p", "sxx", "e")]
        for speed, st in self.waves():  # leading wave first: later ones overwrite
            behind = xi < speed
            for arr, k in zip(out, ("rho", "u", "p", "sxx", "e")):
                arr[behind] = getattr(st, k)
        return tuple(out)

    def impact_state(self, x, t, x0=0.0):
        """Symmetric impact of two slabs of this material meeting at x0 at t = 0, the left
        one moving at +up and the right one at -up: each sees this piston solution in its
        own rest frame (the interface stays at x0 with u = 0).  Sample (rho, u, p, sxx, e)
        at points x and time t > 0 in the frame of the interface; the left half is the
        mirror image (u -> -u)."""
        x = np.asarray(x, dtype=float)
        if not t > 0.0:
            raise ElastoPlasticError("time must be > 0, got %r" % t)
        d = np.abs(x - x0)
        # right slab: material frame x' = x - x0 + up t, where the piston face is up t
        rho, u, p, sxx, e = self.state(d + self.up * t, t, 0.0)
        u = np.where(x >= x0, u - self.up, self.up - u)
        return rho, u, p, sxx, e

    def summary(self):
        """Flat dict of the numbers (SI): regime, up, c_L, u_hel, precursor_speed,
        plastic_speed, hel_<k> and final_<k> for k in State fields (None when absent)."""
        out = {"material": self.material.name, "regime": self.regime, "up": self.up,
               "c_L": longitudinal_speed(self.material), "u_hel": self.u_hel,
               "precursor_speed": self.precursor_speed, "plastic_speed": self.plastic_speed}
        for name, st in (("hel", self.hel), ("final", self.final)):
            for k in State._fields:
                out["%s_%s" % (name, k)] = None if st is None else getattr(st, k)
            out["%s_w_el" % name] = (None if st is None else
                                     elastic_energy(self.material, st))
            out["%s_w_p" % name] = (None if st is None else
                                    plastic_work(self.material, st.rho))
            out["%s_e_ref" % name] = (None if st is None else
                                      reference_curve(self.material, st.rho)[1])
        us, ph, rhoh = hydro_hugoniot(self.material, self.up)
        out.update(hydro_us=us, hydro_p=ph, hydro_rho=rhoh)
        return out


def piston(mat, up):
    """Exact solution for a piston at speed up > 0 into mat at rest: a PistonSolution."""
    up = float(up)
    if not (up > 0.0 and math.isfinite(up)):
        raise ElastoPlasticError("the piston speed must be > 0, got %r" % up)
    rest = rest_state(mat)
    hel, d_el = hel_state(mat)
    u_hel = None if hel is None else hel.u
    if hel is None or up <= u_hel:
        final, d = solve_shock(mat, rest, up)
        return PistonSolution(mat, up, "elastic", d, None, u_hel, None, final)
    if u_hel == 0.0:  # Y = 0: no precursor
        final, d = solve_shock(mat, rest, up)
        return PistonSolution(mat, up, "overdriven", d, None, 0.0, d, final)
    if up - u_hel <= 1e-9 * u_hel:
        # the plastic jump is below round-off (its speed would be a 0/0): it is the
        # acoustic plastic wave of the HEL state, and the final state is the HEL
        return PistonSolution(mat, up, "two-wave", d_el, hel, u_hel,
                              u_hel + plastic_sound_speed(mat, hel), hel)
    final, d_pl = solve_shock(mat, hel, up)
    if d_pl < d_el:
        return PistonSolution(mat, up, "two-wave", d_el, hel, u_hel, d_pl, final)
    single, d = solve_shock(mat, rest, up)
    return PistonSolution(mat, up, "overdriven", d, None, u_hel, d, single,
                          hel_overdrive=d_pl)


# The issue-3 cases: (material, piston speed or slab speed, kind)
CASES = [("aluminium", 100.0, "piston"), ("aluminium", 500.0, "piston"),
         ("copper", 250.0, "impact"), ("copper", 2500.0, "impact")]


def format_case(mat, up, kind="piston"):
    """Text block of one case, numbers in engineering units (GPa, kJ/kg).  kind 'impact':
    symmetric impact at +-up, also gives the wave speeds in the interface frame."""
    sol = piston(mat, up)
    us, ph, rhoh = hydro_hugoniot(mat, up)
    what = ("symmetric impact at +-%g m/s: each slab sees u_p = %g m/s" % (up, up)
            if kind == "impact" else "piston at u_p = %g m/s" % up)
    lines = ["%s, %s: %s" % (mat.name, what, sol.regime)]
    lines.append("  c_L = %.2f m/s, u_HEL = %s" % (
        longitudinal_speed(mat),
        "none (never yields)" if sol.u_hel is None else "%.4f m/s" % sol.u_hel))
    fmt = "  %-10s %10s %12s %9s %9s %10s %10s %9s"
    lines.append(fmt % ("state", "speed", "rho", "u", "p", "S_xx", "sigma_xx", "e"))
    lines.append(fmt % ("", "(m/s)", "(kg/m3)", "(m/s)", "(GPa)", "(GPa)", "(GPa)",
                        "(kJ/kg)"))
    row = "  %-10s %10.2f %12.4f %9.4f %9.5f %10.5f %10.5f %9.5f"
    names = {"two-wave": ["HEL", "final"], "elastic": ["elastic"], "overdriven": ["final"]}
    for name, (speed, st) in zip(names[sol.regime], sol.waves()):
        lines.append(row % (name, speed, st.rho, st.u, st.p / 1e9, st.sxx / 1e9,
                            st.sigma / 1e9, st.e / 1e3))
    frame = ""
    if kind == "impact":
        frame = "; interface-frame speeds (D - u_p): %s" % ", ".join(
            "%.2f" % (d - up) for d, _ in sol.waves())
    lines.append("  (speeds and u in the frame of the material at rest%s)" % frame)
    lines.append("  hydrodynamic Hugoniot (G = 0): Us = %.2f m/s, rho = %.4f, "
                 "p = rho0 Us up = %.5f GPa" % (us, rhoh, ph / 1e9))
    lines.append("  final -sigma_xx / (rho0 Us up) - 1 = %+.3f %%, p / (rho0 Us up) - 1 = "
                 "%+.3f %%" % (100 * (-sol.final.sigma / ph - 1),
                               100 * (sol.final.p / ph - 1)))
    if sol.regime == "overdriven" and sol.hel_overdrive is not None:
        lines.append("  (two-wave construction would give a plastic shock at %.2f m/s > "
                     "precursor %.2f m/s)" % (sol.hel_overdrive, hel_state(mat)[1]))
    return "\n".join(lines)


if __name__ == "__main__":
    import sys
    failures = 0
    for name, up, kind in CASES:
        mat = MATERIALS[name]
        print(format_case(mat, up, kind))
        sol = piston(mat, up)
        ok = abs(sol.final.u - up) <= 1e-10 * up
        failures += not ok
        print("  %s final u - u_p = %.3g m/s\n" % ("ok  " if ok else "FAIL",
                                                   sol.final.u - up))
    sys.exit(1 if failures else 0)
