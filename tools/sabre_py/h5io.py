"""Readers for SABRE output files (DESIGN.md section 7).

plot_NNNNNN.h5 / chk_NNNNNN.h5 layout:
  root attributes  time (float64), step (int), ndim (int), cells (int[3], x,y,z),
                   lo, hi (float64[3])
  /grid/x, /grid/y, /grid/z   cell centres (nx), (ny), (nz)
  /fields/<name>   float64, h5py shape (nz, ny, nx)       (plot files)
  /state/q1..q5    conserved variables, same shape          (checkpoints)

Every reader raises SabreDataError with a message naming the file and what is wrong,
so the tools can print it and exit non-zero instead of a traceback.
"""
import csv
import glob
import os
import re

import numpy as np

try:
    import h5py
except ImportError as exc:  # pragma: no cover - depends on the interpreter
    raise SystemExit("error: the h5py module is missing; run the tools with "
                     "/usr/bin/python3 (Debian's, which has h5py): %s" % exc)


class SabreDataError(Exception):
    """A SABRE output file is missing, unreadable or lacks an expected item."""


_NUMBERED = re.compile(r"^(plot|chk)_(\d+)\.h5$")


def numbered_files(out_dir, prefix="plot"):
    """Sorted (by step number) list of OUT_DIR/<prefix>_NNNNNN.h5."""
    if not os.path.isdir(out_dir):
        raise SabreDataError("output folder not found: %s" % out_dir)
    found = []
    for path in glob.glob(os.path.join(out_dir, prefix + "_*.h5")):
        m = _NUMBERED.match(os.path.basename(path))
        if m and m.group(1) == prefix:
            found.append((int(m.group(2)), path))
    found.sort()
    return [p for _, p in found]


def last_plot_file(out_dir):
    files = numbered_files(out_dir, "plot")
    if not files:
        raise SabreDataError("no plot_*.h5 files in %s" % out_dir)
    return files[-1]


class GridFile:
    """One plot or checkpoint file read into memory (fields loaded lazily)."""

    def __init__(self, path):
        self.path = path
        if not os.path.isfile(path):
            raise SabreDataError("file not found: %s" % path)
        try:
            self._h5 = h5py.File(path, "r")
        except OSError as exc:
            raise SabreDataError("cannot open %s as HDF5: %s" % (path, exc))
        h = self._h5
        # scalars may come as 1-element arrays (Fortran writers often do that)
        self.time = float(np.ravel(self._attr("time"))[0])
        self.step = int(np.ravel(self._attr("step"))[0])
        self.ndim = int(np.ravel(self._attr("ndim", 0))[0])
        cells = self._attr("cells", None)
        self.x = self._grid("x")
        self.y = self._grid("y")
        self.z = self._grid("z")
        self.shape = (self.z.size, self.y.size, self.x.size)  # (nz, ny, nx)
        if cells is not None:
            cells = tuple(int(c) for c in np.ravel(cells))
            if len(cells) == 3 and cells[::-1] != self.shape:
                raise SabreDataError("%s: attribute cells=%s disagrees with /grid sizes "
                                     "(nx,ny,nz)=%s" % (path, list(cells),
                                                        list(self.shape[::-1])))
        self.lo = self._vec_attr("lo", [self._lo_edge(a) for a in (self.x, self.y, self.z)])
        self.hi = self._vec_attr("hi", [self._hi_edge(a) for a in (self.x, self.y, self.z)])
        group = "fields" if "fields" in h else ("state" if "state" in h else None)
        self.group = group
        self.field_names = sorted(h[group].keys()) if group else []

    # -- helpers -------------------------------------------------------------
    def _attr(self, name, default=KeyError):
        if name in self._h5.attrs:
            return self._h5.attrs[name]
        if default is KeyError:
            raise SabreDataError("%s: root attribute '%s' is missing" % (self.path, name))
        return default

    def _vec_attr(self, name, default):
        v = self._attr(name, None)
        if v is None:
            return np.array(default, dtype=float)
        return np.array(np.ravel(v), dtype=float)

    def _grid(self, axis):
        key = "grid/" + axis
        if key not in self._h5:
            raise SabreDataError("%s: dataset /%s is missing" % (self.path, key))
        return np.asarray(self._h5[key][()], dtype=float).ravel()

    @staticmethod
    def _lo_edge(c):
        return c[0] - 0.5 * (c[1] - c[0]) if c.size > 1 else c[0] - 0.5

    @staticmethod
    def _hi_edge(c):
        return c[-1] + 0.5 * (c[-1] - c[-2]) if c.size > 1 else c[0] + 0.5

    # -- public --------------------------------------------------------------
    def field(self, name):
        """Field `name` as float64 array of shape (nz, ny, nx)."""
        if self.group is None:
            raise SabreDataError("%s: has neither /fields nor /state" % self.path)
        if name not in self._h5[self.group]:
            raise SabreDataError("%s: field '%s' not found; available: %s"
                                 % (self.path, name, ", ".join(self.field_names) or "none"))
        a = np.asarray(self._h5[self.group][name][()])
        if a.shape != self.shape:
            raise SabreDataError("%s: /%s/%s has shape %s, expected (nz,ny,nx)=%s"
                                 % (self.path, self.group, name, a.shape, self.shape))
        return a

    def fields(self):
        return {n: self.field(n) for n in self.field_names}

    def edges(self, axis):
        """Cell edges along axis 'x'|'y'|'z' (from lo/hi, uniform grid)."""
        i = "xyz".index(axis)
        c = (self.x, self.y, self.z)[i]
        return np.linspace(self.lo[i], self.hi[i], c.size + 1)

    def close(self):
        self._h5.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def read_history(path):
    """history.csv -> (column names, float array of shape (rows, columns))."""
    if not os.path.isfile(path):
        raise SabreDataError("history file not found: %s" % path)
    with open(path, newline="") as f:
        rows = [r for r in csv.reader(f) if r and not r[0].lstrip().startswith("#")]
    if not rows:
        raise SabreDataError("%s is empty (no header line)" % path)
    names = [c.strip() for c in rows[0]]
    data = []
    for lineno, r in enumerate(rows[1:], start=2):
        if len(r) != len(names):
            raise SabreDataError("%s line %d: %d values, header has %d columns"
                                 % (path, lineno, len(r), len(names)))
        try:
            data.append([float(v) for v in r])
        except ValueError as exc:
            raise SabreDataError("%s line %d: %s" % (path, lineno, exc))
    arr = np.array(data, dtype=float).reshape(len(data), len(names))
    return names, arr


def history_column(names, data, name, path="history.csv"):
    if name not in names:
        raise SabreDataError("%s: column '%s' not found; available: %s"
                             % (path, name, ", ".join(names)))
    return data[:, names.index(name)]
