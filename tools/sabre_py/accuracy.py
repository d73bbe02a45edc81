"""Accuracy against cost (issue 5, part 1): error measures, Pareto fronts, time budgets.

Used by tools/accuracy. Error measures, against exact solutions where there is one:

- Riemann families (sod, toro_*): L1 of rho = mean over cells |rho - rho_exact| at the end
  time, rho_exact from tools/sabre_py/riemann.py at the cell centres.
- smooth_wave: L1 of rho against the exact cell average of 1 + 0.2 sin(2 pi (x - t)).
- copper_impact_2500: L1 of rho against the exact symmetric impact (one overdriven
  elastic-plastic shock each way, tools/sabre_py/elastoplastic.py) at the cell centres.
- piston_al_*: mean of the relative errors of the final-state density (averaged between
  the piston and the plastic shock) and of the plastic-shock speed (u crossing half-way
  between the HEL and the piston speed), exact from tools/sabre_py/elastoplastic.py.

and against the finest run where there is not:

- taylor_bar: mean of the relative errors of the final length and of the foot radius
  (tools/sabre_py/taylor.py measures both on the level set) against those of the 0.075 mm
  reference run. Peak eps_p is reported beside them but left out of the error.
"""
import math

import numpy as np

from . import elastoplastic, riemann

# name: (x0, left (rho, u, p), right) as in decks/<name>.nml (gamma 1.4)
RIEMANN = {
    'sod': (0.5, (1.0, 0.0, 1.0), (0.125, 0.0, 0.1)),
    'toro_1': (0.3, (1.0, 0.75, 1.0), (0.125, 0.0, 0.1)),
    'toro_2': (0.5, (1.0, -2.0, 0.4), (1.0, 2.0, 0.4)),
    'toro_3': (0.5, (1.0, 0.0, 1000.0), (1.0, 0.0, 0.01)),
    'toro_4': (0.4, (5.99924, 19.5975, 460.894), (5.99242, -6.19633, 46.0950)),
    'toro_5': (0.8, (1.0, -19.59745, 1000.0), (1.0, -19.59745, 0.01)),
}


# the strong-shock families, where the study runs both reconstructed variables
# (&numerics variables, m_characteristic); the other families run the primitive ones
STRONG_SHOCK = ('toro_3', 'copper_impact_2500')


def variables_for(family, scheme, given=None):
    """The reconstructed variables the study runs for family and scheme: given (a list), or
    both on the strong-shock families and primitive elsewhere; eno1 has only one."""
    if scheme == 'eno1':
        return ['primitive']
    return given or (['primitive', 'characteristic'] if family in STRONG_SHOCK
                     else ['primitive'])


def impact_error(g, up=2500.0):
    """L1 of rho of a symmetric copper impact at +-up (decks/copper_impact_2500.nml)."""
    sol = elastoplastic.piston(elastoplastic.MATERIALS['copper'], up)
    rho_ex = sol.impact_state(g.x, g.time, 0.0)[0]
    return float(np.mean(np.abs(g.field('rho').reshape(-1) - rho_ex)))


def gas_water_error(g):
    """L1 of rho against the exact two-material solution (sabre_py/riemann.py with the air and
    water of decks/gas_water_tube.nml) at the cell centres of the last plot file."""
    ex = riemann.exact(g.x, g.time, 0.7, (50.0, 0.0, 1e9), (1000.0, 0.0, 1e5), gamma=1.4,
                       gamma_right=4.4, pinf_right=6e8)[0]
    num = g.field('rho').ravel()
    return sum(abs(a - b) for a, b in zip(num, ex)) / len(ex)


def is_gas(family):
    return family in RIEMANN or family == 'smooth_wave'


def riemann_error(family, g):
    x0, left, right = RIEMANN[family]
    rho_ex, _, _ = riemann.exact(g.x, g.time, x0, left, right, 1.4)
    return float(np.mean(np.abs(g.field('rho').reshape(-1) - rho_ex)))


def wave_error(g):
    x, t = g.x, g.time
    dx = float(x[1] - x[0])
    exact = 1 + 0.2 * (np.cos(2 * np.pi * (x - t - dx / 2))
                       - np.cos(2 * np.pi * (x - t + dx / 2))) / (2 * np.pi * dx)
    return float(np.mean(np.abs(g.field('rho').reshape(-1) - exact)))


def crossing(x, f, level, x_min=-np.inf):
    """Last x where f crosses level (linear interpolation); NaN if none."""
    s = (f[:-1] - level) * (f[1:] - level)
    idx = np.where((s <= 0) & (f[:-1] != f[1:]) & (x[:-1] > x_min))[0]
    if idx.size == 0:
        return float('nan')
    i = int(idx[-1])
    return float(x[i] + (level - f[i]) / (f[i + 1] - f[i]) * (x[i + 1] - x[i]))


def piston_error(sol, up, g):
    """(error, final-rho relative error, plastic-speed relative error)."""
    x, t = g.x, g.time
    rho, u = g.field('rho').reshape(-1), g.field('u').reshape(-1)
    xs = crossing(x, u, 0.5 * (sol.u_hel + up))
    dx = float(x[1] - x[0])
    fin = (x > up * t + 3 * dx) & (x < xs - 3 * dx)
    if not np.isfinite(xs) or not fin.any():
        return float('nan'), float('nan'), float('nan')
    e_rho = abs(float(rho[fin].mean()) - sol.final.rho) / sol.final.rho
    e_us = abs(xs / t - sol.plastic_speed) / sol.plastic_speed
    return 0.5 * (e_rho + e_us), e_rho, e_us


def taylor_error(run, ref):
    """(error, length relative error, radius relative error) of a Taylor-bar measurement
    against the reference's; both are dicts with length_mm and radius_mm."""
    e_len = abs(run['length_mm'] - ref['length_mm']) / ref['length_mm']
    e_rad = abs(run['radius_mm'] - ref['radius_mm']) / ref['radius_mm']
    return 0.5 * (e_len + e_rad), e_len, e_rad


def pareto(runs, err='error', cost='wall_s'):
    """Runs not dominated in (error, cost), sorted by cost. A run is dominated when another
    has error <= and cost <= with at least one strictly smaller."""
    ok = [r for r in runs if math.isfinite(r[err]) and math.isfinite(r[cost])]
    ok.sort(key=lambda r: (r[cost], r[err]))
    front, best = [], math.inf
    for r in ok:
        if r[err] < best:
            front.append(r)
            best = r[err]
    return front


def best_within(runs, budget, err='error', cost='wall_s'):
    """The run of least error whose cost is within the budget, or None."""
    ok = [r for r in runs if math.isfinite(r[err]) and r[cost] <= budget]
    return min(ok, key=lambda r: r[err]) if ok else None


def observed_order(runs):
    """[(n1, n2, order)] between successive resolutions of one configuration."""
    pts = sorted((r['cells'], r['error']) for r in runs)
    out = []
    for (n1, e1), (n2, e2) in zip(pts, pts[1:]):
        o = math.log(e1 / e2) / math.log(n2 / n1) if e1 > 0 and e2 > 0 else float('nan')
        out.append((n1, n2, o))
    return out


def label(r):
    char = ' char' if r.get('variables') == 'characteristic' else ''
    return f"{r['scheme']}{char} rk{r['rk']} {r['flux']}"


def num(v, spec):
    """v formatted, or '-' where a failed run left it empty."""
    return format(v, spec) if isinstance(v, (int, float)) else '-'


def md_table(rows, heads, cells):
    return (['| ' + ' | '.join(heads) + ' |', '|' + '---|' * len(heads)]
            + ['| ' + ' | '.join(str(c) for c in cells(r)) + ' |' for r in rows])
