"""Taylor-bar measurements (used by tools/taylor_bar): final length, foot (mushroom) radius and
peak effective plastic strain of one body of a SABRE plot file, read from its level set
phi_<body> (negative inside, roughly a signed distance) and the field eps_p.

Geometry. 2D files are axisymmetric, x = r and y = z, so the bar axis is y and the radius is the
largest x of the body. 3D files have the bar axis along z by default (axis y on request); the
radius is the largest distance of the surface from the bar axis, whose position across the axis
is, per direction, the domain's low edge when that edge is 0 and the bar touches it (a symmetry
plane: quarter- or half-bar runs), else the mean position of the cells of the top few cell
layers of the bar weighted by their inside fraction (the top stays undeformed, so this is the
centre of the initial footprint). File lengths are taken to be metres; every length reported
is in mm.

Sub-cell accuracy. The surface is where phi = 0. Between two neighbouring cell centres a, b of
opposite sign it is placed at a + (b - a) phi_a / (phi_a - phi_b). Where the bar fills the first
(last) cell of a line, the surface is the zero of phi extrapolated linearly from the two end
cells, clamped to the domain edge: a bar standing on the boundary wall then has its bottom on
the wall. Along a lateral direction the bar filling an end cell means the domain cuts it (the
measurement is then a bound and a warning says so), except at a symmetry plane.

Not done here: the radius is the largest over the cell rows (2D) or the grid lines (3D) that
cross the surface, with no interpolation between rows; any cell with phi < 0 belongs to the bar,
so stray negative phi away from the bar would count.
"""
import json
import os
import tempfile

import numpy as np

from .h5io import GridFile, SabreDataError, history_column, numbered_files, read_history

MM = 1.0e3  # metres -> mm

# (key, label, published band, range of the other codes) for the 227 m/s copper Taylor bar
PUBLISHED = {
    2: [("length_mm", "final length L (mm)", (21.1, 21.9), (21.15, 21.48)),
        ("radius_mm", "foot radius (mm)", (6.6, 7.4), (6.8, 7.24)),
        ("peak_eps_p", "peak eps_p", (2.8, 3.3), (2.86, 3.25))],
    3: [("length_mm", "final length L (mm)", (21.23, 21.80), None),
        ("radius_mm", "foot radius (mm)", (6.18, 7.1), None)],
}
TOP_LAYERS = 5  # cell layers at the top of the bar whose inside cells give the axis position


class TaylorError(Exception):
    """A user error: an option that does not fit the run, or a bar the tool cannot measure."""


# -- surface positions along grid lines ------------------------------------------------------
def _crossings(p, c):
    """Zero crossings of phi along the last axis of p (cell centres c), as two arrays of shape
    p.shape[:-1] + (n-1,): where phi goes from >= 0 to < 0 moving up the axis (entering the
    body) and from < 0 to >= 0 (leaving it); NaN where there is no such crossing."""
    a, b = p[..., :-1], p[..., 1:]
    ok = np.isfinite(a) & np.isfinite(b)
    with np.errstate(invalid="ignore", divide="ignore"):
        pos = c[:-1] + a / (a - b) * (c[1:] - c[:-1])
        enter = ok & (a >= 0) & (b < 0)
        leave = ok & (a < 0) & (b >= 0)
    return np.where(enter, pos, np.nan), np.where(leave, pos, np.nan)


def _end_extrapolation(p_end, p_next, c_end, c_next, edge):
    """Where phi, negative in the end cell of a line, reaches zero beyond it: the linear
    extrapolation from the end cell and its neighbour, clamped between the end cell centre
    and the domain edge (the edge itself when phi does not rise towards it)."""
    with np.errstate(invalid="ignore", divide="ignore"):
        rise = (p_end - p_next) / np.abs(c_end - c_next)  # d phi / d(distance outwards)
        out = np.where(rise > 0, p_end / rise, np.inf)     # p_end < 0: a distance <= 0
        dist = np.abs(c_end - edge)
        step = np.minimum(np.where(np.isfinite(out), -out, dist), dist)
    return c_end + np.sign(edge - c_end) * step


def _column_ends(p, c, lo, hi):
    """Lowest and highest surface position of the body along the last axis of p, per line
    (NaN for lines that miss it), and whether the body fills the first / last cell of a line."""
    enter, leave = _crossings(p, c)
    first_in = p[..., 0] < 0
    last_in = p[..., -1] < 0
    low = np.where(first_in, _end_extrapolation(p[..., 0], p[..., 1], c[0], c[1], lo),
                   np.fmin.reduce(enter, axis=-1))
    high = np.where(last_in, _end_extrapolation(p[..., -1], p[..., -2], c[-1], c[-2], hi),
                    np.fmax.reduce(leave, axis=-1))
    return low, high, bool(first_in.any()), bool(last_in.any())


def _surface_points(p, c, lo, hi, low_is_mirror):
    """Every surface position along the last axis of p: (positions, tuple of the leading
    indices of each point's line, sides where the body fills an end cell). A body filling
    the high end cell, or the low one when that edge is not a symmetry plane, gives a point
    on the domain edge."""
    enter, leave = _crossings(p, c)
    both = np.where(np.isfinite(enter), enter, leave)
    idx = np.nonzero(np.isfinite(both))
    pos, lead = [both[idx]], [list(idx[:-1])]
    touched = []
    ends = [("high", p[..., -1] < 0, hi)]
    if not low_is_mirror:
        ends.append(("low", p[..., 0] < 0, lo))
    for side, filled, edge in ends:
        if filled.any():
            touched.append(side)
            where = np.nonzero(filled)
            pos.append(np.full(where[0].size, float(edge)))
            lead.append(list(where))
    leads = tuple(np.concatenate([lz[k] for lz in lead]) for k in range(p.ndim - 1))
    return np.concatenate(pos), leads, touched


# -- measuring one file ----------------------------------------------------------------------
def level_set_name(body):
    return body if body.startswith("phi_") else "phi_" + body


def _is_zero(value, length):
    return abs(value) <= 1e-9 * max(abs(length), 1e-300)


def measure_file(path, body="bar", axis=None, centre=None, with_eps_p=True):
    """Measurements of the bar phi_<body> in plot file `path` as a dict (lengths in mm).
    axis: 'y' or 'z' (default y in 2D, z in 3D); centre: (a, b) in metres, the bar axis
    position across the axis (3D only; default as in the module docstring)."""
    name = level_set_name(body)
    with GridFile(path) as gf:
        if gf.ndim == 1 or (gf.shape[0] == 1 and gf.shape[1] == 1):
            raise TaylorError("%s is 1D: a Taylor bar needs a 2D (axisymmetric) or 3D run"
                              % path)
        if name not in gf.field_names:
            present = [n for n in gf.field_names if n.startswith("phi_")]
            raise TaylorError("%s: no field %s; level sets in the file: %s (choose the body "
                              "with --body)" % (path, name, ", ".join(present) or "none"))
        phi = np.asarray(gf.field(name), dtype=float)
        eps = None
        if with_eps_p and "eps_p" in gf.field_names:
            eps = np.asarray(gf.field("eps_p"), dtype=float)
        two_d = gf.ndim == 2 or gf.shape[0] == 1
        res = {"file": path, "time": gf.time, "step": gf.step, "ndim": 2 if two_d else 3,
               "body": name[len("phi_"):], "warnings": []}
        grid = {"x": (gf.x, gf.lo[0], gf.hi[0]), "y": (gf.y, gf.lo[1], gf.hi[1]),
                "z": (gf.z, gf.lo[2], gf.hi[2])}
    if axis is None:
        axis = "y" if two_d else "z"
    if two_d and axis != "y":
        raise TaylorError("%s is 2D axisymmetric (x = r, y = z): the bar axis is y, not %s"
                          % (path, axis))
    if two_d and centre is not None:
        raise TaylorError("--centre is for 3D runs; in 2D the bar axis is r = 0")
    if not np.any(phi < 0):
        raise TaylorError("%s: %s is nowhere negative: the bar is not in the domain"
                          % (path, name))
    res["axis"] = axis
    if two_d:
        _measure_2d(phi[0], grid, res)
    else:
        _measure_3d(phi, grid, axis, centre, res)
    res["length_mm"] = res["top_mm"] - res["bottom_mm"]
    res["peak_eps_p"], res["peak_eps_p_at_mm"] = None, None
    if eps is not None:
        inside = np.isfinite(phi) & (phi < 0) & np.isfinite(eps)
        if inside.any():
            flat = int(np.argmax(np.where(inside, eps, -np.inf)))
            k, j, i = np.unravel_index(flat, phi.shape)
            res["peak_eps_p"] = float(eps[k, j, i])
            at = [grid["x"][0][i], grid["y"][0][j]] + ([] if two_d else [grid["z"][0][k]])
            res["peak_eps_p_at_mm"] = [MM * float(v) for v in at]
    elif with_eps_p:
        res["warnings"].append("no field eps_p in the file: no peak plastic strain")
    return res


def _measure_2d(phi, grid, res):
    """phi of shape (ny, nx), x = r, y = z."""
    (x, xlo, xhi), (y, ylo, yhi) = grid["x"], grid["y"]
    if x.size < 2 or y.size < 2:
        raise TaylorError("%s: needs at least 2 cells in x and y" % res["file"])
    res["cell_mm"] = [MM * float(x[1] - x[0]), MM * float(y[1] - y[0])]
    low, high, _, top_cut = _column_ends(phi.T, y, ylo, yhi)
    res["bottom_mm"], res["top_mm"] = MM * float(np.nanmin(low)), MM * float(np.nanmax(high))
    if top_cut:
        res["warnings"].append("the bar fills the top cell layer: it leaves the domain, so "
                               "the length is a lower bound")
    _, right, _, side_cut = _column_ends(phi, x, xlo, xhi)
    j = int(np.nanargmax(right))
    res["radius_mm"] = MM * float(right[j])
    res["radius_at_mm"] = MM * float(y[j])
    if side_cut:
        res["warnings"].append("the bar fills the last cell in r: the domain cuts it, so the "
                               "radius is a lower bound")
    if not _is_zero(xlo, xhi - xlo):
        res["warnings"].append("x starts at %g mm, not on the axis r = 0; the radius is the "
                               "largest x" % (MM * xlo))


def _axis_position(bar, c, lo, hi, side_axis):
    """(position, is a symmetry plane) of the bar axis along one transverse direction.
    bar: phi as (na, np, nq); side_axis: 1 (p) or 2 (q). Off a symmetry plane, the mean of the
    cell centres of the top layers weighted by the cells' inside fraction, clip(1/2 - phi/h),
    which is the volume fraction for a distance phi and cell size h across the surface."""
    inside = np.isfinite(bar) & (bar < 0)
    if _is_zero(lo, hi - lo) and inside.take(0, axis=side_axis).any():
        return float(lo), True
    layers = np.nonzero(inside.any(axis=(1, 2)))[0]
    top = bar[max(layers[-1] - TOP_LAYERS + 1, layers[0]):layers[-1] + 1]
    frac = np.clip(0.5 - np.nan_to_num(top, nan=np.inf) / abs(c[1] - c[0]), 0.0, 1.0)
    weights = frac.sum(axis=(0, 2 if side_axis == 1 else 1))
    return float(np.sum(weights * c) / np.sum(weights)), False


def _measure_3d(phi, grid, axis, centre, res):
    """phi of shape (nz, ny, nx); the bar axis is `axis` ('z' or 'y')."""
    if axis == "z":
        bar, (pn, qn) = phi.transpose(0, 2, 1), ("x", "y")   # (z, x, y)
    else:
        bar, (pn, qn) = phi.transpose(1, 2, 0), ("x", "z")   # (y, x, z)
    (a, alo, ahi), (pc, p_lo, p_hi), (qc, q_lo, q_hi) = grid[axis], grid[pn], grid[qn]
    if min(a.size, pc.size, qc.size) < 2:
        raise TaylorError("%s: needs at least 2 cells in each direction" % res["file"])
    res["cell_mm"] = [MM * float(v[1] - v[0]) for v in (grid["x"][0], grid["y"][0],
                                                        grid["z"][0])]
    low, high, _, top_cut = _column_ends(np.moveaxis(bar, 0, -1), a, alo, ahi)
    res["bottom_mm"], res["top_mm"] = MM * float(np.nanmin(low)), MM * float(np.nanmax(high))
    if top_cut:
        res["warnings"].append("the bar fills the top cell layer: it leaves the domain, so "
                               "the length is a lower bound")
    p0, p_mirror = _axis_position(bar, pc, p_lo, p_hi, 1)
    q0, q_mirror = _axis_position(bar, qc, q_lo, q_hi, 2)
    res["centre_from"] = ("symmetry plane" if p_mirror and q_mirror else
                          "top of the bar" if not (p_mirror or q_mirror) else
                          "symmetry plane and top of the bar")
    if centre is not None:
        p0, q0 = (float(v) for v in centre)
        p_mirror = p_mirror and _is_zero(p0 - p_lo, p_hi - p_lo)
        q_mirror = q_mirror and _is_zero(q0 - q_lo, q_hi - q_lo)
        res["centre_from"] = "--centre"
    res["transverse"] = [pn, qn]
    res["symmetry_planes"] = [p_mirror, q_mirror]
    res["centre_mm"] = [MM * p0, MM * q0]
    # surface points along p lines (bar as (a, q, p)) and along q lines (bar as (a, p, q))
    p_pos, (ia1, iq), p_cut = _surface_points(bar.transpose(0, 2, 1), pc, p_lo, p_hi,
                                              p_mirror)
    q_pos, (ia2, ip), q_cut = _surface_points(bar, qc, q_lo, q_hi, q_mirror)
    dist = np.concatenate([np.hypot(p_pos - p0, qc[iq] - q0), np.hypot(pc[ip] - p0, q_pos - q0)])
    at = np.concatenate([a[ia1], a[ia2]])
    k = int(np.argmax(dist))
    res["radius_mm"], res["radius_at_mm"] = MM * float(dist[k]), MM * float(at[k])
    half = {}
    for n, pos, mirror, c0 in ((pn, p_pos, p_mirror, p0), (qn, q_pos, q_mirror, q0)):
        half[n] = MM * float(pos.max() - c0 if mirror else 0.5 * (pos.max() - pos.min()))
    res["half_width_mm"] = half
    res["roundness"] = half[pn] / half[qn] if half[qn] > 0 else None
    for n, cut in ((pn, p_cut), (qn, q_cut)):
        for side in cut:
            res["warnings"].append("the bar fills the %s-%s cell layer: the domain cuts it, so "
                                   "the radius is a lower bound" % (side, n))


# -- the whole run ---------------------------------------------------------------------------
def _history_notes(out_dir, plot_time):
    """Lines about history.csv: how far it runs beyond the plot file, kinetic energy left."""
    path = os.path.join(out_dir, "history.csv")
    if not os.path.isfile(path):
        return []
    try:
        names, data = read_history(path)
        t = history_column(names, data, "time", path)
        ke = history_column(names, data, "kinetic", path)
    except SabreDataError as exc:
        return ["history.csv not used: %s" % exc]
    if t.size == 0:
        return []
    notes = []
    if t[-1] > plot_time * (1 + 1e-9) + 1e-300:
        notes.append("history.csv runs to t = %.6g s, beyond the last plot file" % t[-1])
    if ke.max() > 0:
        notes.append("kinetic energy at t = %.6g s: %.3g %% of its peak (all material)"
                     % (t[-1], 100.0 * ke[-1] / ke.max()))
    return notes


def measure_run(target, body="bar", axis=None, centre=None):
    """Measure the last plot file of run folder `target` (or the plot file `target`); adds the
    initial length and radius from the first plot file and notes from history.csv."""
    if os.path.isfile(target):
        files, out_dir = [target], os.path.dirname(os.path.abspath(target))
    else:
        if not os.path.isdir(target):
            raise TaylorError("run folder not found: %s" % target)
        files, out_dir = numbered_files(target, "plot"), target
        if not files:
            raise TaylorError("no plot_NNNNNN.h5 files in %s" % target)
    res = measure_file(files[-1], body, axis, centre)
    res["plot_files"] = len(files)
    res["notes"] = []
    if len(files) > 1:
        try:
            first = measure_file(files[0], body, res["axis"], centre, with_eps_p=False)
            res["initial"] = {"file": files[0], "time": first["time"],
                              "length_mm": first["length_mm"], "radius_mm": first["radius_mm"]}
        except (SabreDataError, TaylorError) as exc:
            res["notes"].append("first plot file not measured: %s" % exc)
    res["notes"] += _history_notes(out_dir, res["time"])
    res["published"] = [{"quantity": k, "band": band, "codes": codes,
                         "in_band": (None if res.get(k) is None else
                                     bool(band[0] <= res[k] <= band[1]))}
                        for k, _, band, codes in PUBLISHED[res["ndim"]]]
    return res


def _f(v):
    """%.3f without a '-0.000'."""
    return "%.3f" % (round(v, 9) + 0.0)


def _band(r):
    return "-" if r is None else "%g - %g" % r


def report(res, published=True):
    """The measurements as text: a heading, the table, then extra lines and warnings."""
    kind = "2D axisymmetric (x = r, y = z)" if res["ndim"] == 2 else "3D"
    cell = " x ".join("%.4g" % v for v in res["cell_mm"])
    out = ["%s  t = %.6g s  step %d" % (res["file"], res["time"], res["step"]),
           "%s, bar axis %s, body %s, cells %s mm" % (kind, res["axis"], res["body"], cell), ""]
    rows = [(k, label) for k, label, _, _ in PUBLISHED[res["ndim"]]]
    bands = {p["quantity"]: p for p in res["published"]}
    head = "%-22s %9s" % ("quantity", "SABRE")
    if published:
        head += "   %-15s %-15s %s" % ("published band", "codes", "verdict")
    out += [head, "-" * len(head)]
    for key, label in rows:
        v = res.get(key)
        line = "%-22s %9s" % (label, "n/a" if v is None else "%.3f" % v)
        if published:
            b = bands[key]
            verdict = ("-" if b["in_band"] is None else
                       "in band" if b["in_band"] else "OUT of band")
            line += "   %-15s %-15s %s" % (_band(b["band"]), _band(b["codes"]), verdict)
        out.append(line)
    out.append("")
    axial = res["axis"]
    out.append("bar from %s = %s to %s mm; widest at %s = %s mm"
               % (axial, _f(res["bottom_mm"]), _f(res["top_mm"]), axial,
                  _f(res["radius_at_mm"])))
    if res["ndim"] == 3:
        pn, qn = res["transverse"]
        h = res["half_width_mm"]
        out.append("axis at %s = %s, %s = %s mm (%s)" % (pn, _f(res["centre_mm"][0]), qn,
                                                        _f(res["centre_mm"][1]),
                                                        res["centre_from"]))
        rnd = "n/a" if res["roundness"] is None else "%.4f" % res["roundness"]
        out.append("foot half-width along %s %.3f mm, along %s %.3f mm, ratio %s/%s %s"
                   % (pn, h[pn], qn, h[qn], pn, qn, rnd))
    if res["peak_eps_p_at_mm"] is not None:
        out.append("peak eps_p at (%s) mm" % ", ".join(_f(v) for v in res["peak_eps_p_at_mm"]))
    if "initial" in res:
        ini = res["initial"]
        ratio = res["length_mm"] / ini["length_mm"] if ini["length_mm"] > 0 else float("nan")
        out.append("first plot file (t = %.6g s): length %.3f mm, radius %.3f mm; "
                   "L/L0 = %.4f" % (ini["time"], ini["length_mm"], ini["radius_mm"], ratio))
    out += ["note: " + n for n in res["notes"]]
    out += ["warning: " + w for w in res["warnings"]]
    return "\n".join(out)


def write_json(res, path):
    try:
        with open(path, "w") as f:
            json.dump(res, f, indent=2)
            f.write("\n")
    except OSError as exc:
        raise TaylorError("cannot write %s: %s" % (path, exc.strerror or exc))


# -- self-test on analytic shapes ------------------------------------------------------------
def write_plot_file(path, x, y, z, fields, ndim, time=1e-4, step=100):
    """A plot file in the layout h5io.GridFile reads (cell centres x, y, z; uniform cells)."""
    import h5py
    centres = [np.asarray(v, dtype=float) for v in (x, y, z)]
    widths = [v[1] - v[0] if v.size > 1 else 1.0 for v in centres]
    with h5py.File(path, "w") as f:
        f.attrs["time"], f.attrs["step"], f.attrs["ndim"] = time, step, ndim
        f.attrs["cells"] = np.array([v.size for v in centres], dtype=np.int32)
        f.attrs["lo"] = np.array([v[0] - w / 2 for v, w in zip(centres, widths)])
        f.attrs["hi"] = np.array([v[-1] + w / 2 for v, w in zip(centres, widths)])
        f.attrs["title"] = b"taylor self-test"
        for n, v in zip("xyz", centres):
            f["grid/" + n] = v
        for n, v in fields.items():
            f["fields/" + n] = v


def _box_sdf(r, z, radius, z0, z1):
    """Signed distance to the (r, z) rectangle 0 <= r <= radius, z0 <= z <= z1."""
    dr, dz = np.abs(r) - radius, np.abs(z - 0.5 * (z0 + z1)) - 0.5 * (z1 - z0)
    return np.hypot(np.maximum(dr, 0), np.maximum(dz, 0)) + np.minimum(np.maximum(dr, dz), 0)


def _centres(lo, hi, h):
    n = int(round((hi - lo) / h))
    return lo + h * (np.arange(n) + 0.5)


def _mushroom(r, z, z0, foot=7.0e-3):
    """phi and eps_p of a bar r < 3.2 mm, z0 < z < z0 + 21.5 mm with a foot r < `foot`,
    z0 < z < z0 + 2 mm; eps_p peaks at 3 on the axis at the bottom and is 50 outside."""
    phi = np.minimum(_box_sdf(r, z, 3.2e-3, z0, z0 + 21.5e-3),
                     _box_sdf(r, z, foot, z0, z0 + 2e-3))
    eps = np.where(phi < 0, 3.0 * np.exp(-(r ** 2 + (z - z0) ** 2) / (2e-3) ** 2), 50.0)
    return phi, eps


def _expect(what, got, want, tol, failures, case):
    ok = got is not None and abs(got - want) <= tol
    print("  %-34s %10.4f  expected %8.4f +- %g  %s" % (what, np.nan if got is None else got,
                                                      want, tol, "ok" if ok else "FAILED"))
    if not ok:
        failures.append("%s %s" % (case, what))


def self_test():
    """Measure analytic mushrooms in synthetic plot files; True when every check passes."""
    h2, h3 = 0.15e-3, 0.25e-3
    failures, case = [], ""

    def check(what, got, want, tol):
        _expect(what, got, want, tol, failures, case)

    with tempfile.TemporaryDirectory(prefix="taylor_selftest_") as tmp:
        # 2D on the floor (domain starts at z = 0) and 2D above a gap (floor at z = 0.61 mm)
        for case, zlo, z0 in (("2d_floor", 0.0, 0.0), ("2d_gap", -1.5e-3, 0.61e-3)):
            run = os.path.join(tmp, case)
            os.mkdir(run)
            r, z = _centres(0, 12e-3, h2), _centres(zlo, zlo + 28e-3, h2)
            phi, eps = _mushroom(r[None, :], z[:, None], z0)
            if case == "2d_gap":  # same zero set, no longer a distance: interpolation errs
                phi = phi * (1.0 + 400.0 * phi)
            write_plot_file(os.path.join(run, "plot_000100.h5"), r, z, [0.0],
                            {"phi_bar": phi[None], "eps_p": eps[None]}, 2)
            # the undeformed bar, 3.8 mm by 25.4 mm, as the first plot file
            phi0 = _box_sdf(r[None, :], z[:, None], 3.8e-3, z0, z0 + 25.4e-3)
            write_plot_file(os.path.join(run, "plot_000000.h5"), r, z, [0.0],
                            {"phi_bar": phi0[None], "eps_p": 0 * phi0[None]}, 2, 0.0, 0)
            res = measure_run(run)
            print(case)
            check("initial length (mm)", res["initial"]["length_mm"], 25.4, 0.02)
            check("initial radius (mm)", res["initial"]["radius_mm"], 3.8, 0.02)
            check("length (mm)", res["length_mm"], 21.5, 0.02)
            check("radius (mm)", res["radius_mm"], 7.0, 0.02)
            check("peak eps_p", res["peak_eps_p"], 3.0, 0.02)
        # 3D quarter bar (symmetry planes x = 0, y = 0) and a full bar off the origin with an
        # elliptic foot (semi-axes 7.0 mm along x, 6.5 mm along y)
        for case, quarter in (("3d_quarter", True), ("3d_full", False)):
            run = os.path.join(tmp, case)
            os.mkdir(run)
            if quarter:
                xc = yc = 0.0
                x, y = _centres(0, 10e-3, h3), _centres(0, 10e-3, h3)
            else:
                xc, yc = 0.43e-3, -0.29e-3
                x, y = _centres(-9e-3, 9e-3, h3), _centres(-9e-3, 9e-3, h3)
            z = _centres(0, 24e-3, h3)
            zz, yy, xx = np.meshgrid(z, y, x, indexing="ij")
            sx = 1.0 if quarter else 6.5 / 7.0  # squeeze y so the foot is an ellipse
            rr = np.hypot(xx - xc, (yy - yc) / sx)
            phi, eps = _mushroom(rr, zz, 0.0)
            write_plot_file(os.path.join(run, "plot_000100.h5"), x, y, z,
                            {"phi_bar": phi, "eps_p": eps}, 3)
            res = measure_run(run)
            print(case)
            check("length (mm)", res["length_mm"], 21.5, 0.02)
            check("radius (mm)", res["radius_mm"], 7.0, 0.02)
            check("axis x (mm)", res["centre_mm"][0], MM * xc, 0.01)
            check("axis y (mm)", res["centre_mm"][1], MM * yc, 0.01)
            check("foot half-width x (mm)", res["half_width_mm"]["x"], 7.0, 0.03)
            check("foot half-width y (mm)", res["half_width_mm"]["y"], 7.0 * sx, 0.03)
        # user errors: a body that is not there, a folder without plot files
        for what, call, needle in (
                ("missing body", lambda: measure_run(os.path.join(tmp, "2d_floor"), "rod"),
                 "level sets in the file: phi_bar"),
                ("no plot files", lambda: measure_run(tmp), "no plot_NNNNNN.h5 files")):
            try:
                call()
                message = "no error"
            except (TaylorError, SabreDataError) as exc:
                message = str(exc)
            ok = needle in message
            print("  %-34s %s  %s" % (what, message, "ok" if ok else "FAILED"))
            if not ok:
                failures.append(what)
    if failures:
        print("self-test FAILED: %s" % ", ".join(failures))
        return False
    print("self-test passed")
    return True
