"""Pieces of the regression runner (regress/run): the case list, gold files, the
quantities extracted from a run, and the comparisons.  No process is started here.

Case list (regress/cases.txt), one case a line, '#' starts a comment line, a trailing
backslash continues a line:

    name  kind  np  deck  [option=value ...] [group.var=value ...]
    name  command  [option=value ...] -- shell command ...

kinds: run | ranks | restart | command.  Options (keys without a dot):
    abs=1e-12 rel=1e-10       default tolerances written to the gold file
    tol:QUANTITY=ABS,REL      tolerance for one quantity (e.g. tol:l1.rho=1e-9,0)
    fields=rho,u,p            fields whose min/max/sum are checked (default: all)
    exact=riemann:x0,rhoL,uL,pL,rhoR,uR,pR[,gamma]   add l1.rho, l1.u, l1.p
    chk=NNNNNN                checkpoint step a restart case restarts from
    timeout=600               seconds per solver run (or for the command)
Tokens group.var=value are deck overrides given to the solver verbatim (so string
values keep their Fortran quotes: run.title='sod'); values cannot contain spaces.

Gold file (regress/gold/<name>.txt): '#' comment lines, then one line per quantity
    <quantity> <value %.17g> <abs_tol> <rel_tol>
pass when |got - expected| <= max(abs_tol, rel_tol * |expected|); any NaN fails.
"""
import math
import os
import re
import time

import numpy as np

from .h5io import GridFile, SabreDataError, history_column, last_plot_file, read_history
from .riemann import RiemannError, exact, parse_spec

KINDS = ("run", "ranks", "restart", "command")
DEFAULT_ABS = 1e-12
DEFAULT_REL = 1e-10
DEFAULT_TIMEOUT = 600.0
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.+-]*$")
_OPTIONS = ("abs", "rel", "fields", "exact", "chk", "timeout")


class CaseError(Exception):
    """A malformed line in the case list."""


class CheckFailure(Exception):
    """A case failed for a reason other than a quantity mismatch."""


class Case:
    def __init__(self, name, kind, lineno):
        self.name, self.kind, self.lineno = name, kind, lineno
        self.np = 1
        self.deck = None
        self.overrides = []
        self.command = None
        self.abs_tol = DEFAULT_ABS
        self.rel_tol = DEFAULT_REL
        self.tol = {}            # quantity -> (abs, rel)
        self.fields = None       # None = every field in the plot file
        self.exact = None        # (x0, left, right, gamma)
        self.chk = None          # 'NNNNNN'
        self.timeout = DEFAULT_TIMEOUT

    def tolerance(self, quantity):
        return self.tol.get(quantity, (self.abs_tol, self.rel_tol))

    def describe(self):
        if self.kind == "command":
            return "%-8s %s" % (self.kind, self.command)
        return "%-8s np=%d %s %s" % (self.kind, self.np, self.deck, " ".join(self.overrides))


def _logical_lines(path):
    """(first line number, text) for each non-comment line, continuations joined."""
    with open(path) as f:
        raw = f.read().splitlines()
    out, buf, start = [], "", None
    for i, line in enumerate(raw, start=1):
        stripped = line.strip()
        if not buf and (not stripped or stripped.startswith("#")):
            continue
        if start is None:
            start = i
        if stripped.endswith("\\"):
            buf += stripped[:-1] + " "
            continue
        buf += stripped
        out.append((start, buf))
        buf, start = "", None
    if buf:
        out.append((start, buf))
    return out


def _float(value, what, where):
    try:
        v = float(value)
    except ValueError:
        raise CaseError("%s: %s must be a number, got %r" % (where, what, value))
    if not v >= 0.0:
        raise CaseError("%s: %s must be >= 0, got %r" % (where, what, value))
    return v


def _apply_option(case, key, value, where):
    if key == "abs":
        case.abs_tol = _float(value, "abs", where)
    elif key == "rel":
        case.rel_tol = _float(value, "rel", where)
    elif key == "timeout":
        case.timeout = _float(value, "timeout", where)
    elif key == "fields":
        case.fields = [f for f in value.split(",") if f]
    elif key == "chk":
        if not value.isdigit():
            raise CaseError("%s: chk must be the checkpoint step digits (chk=000010), "
                            "got %r" % (where, value))
        case.chk = "%06d" % int(value)
    elif key == "exact":
        kind, _, spec = value.partition(":")
        if kind != "riemann":
            raise CaseError("%s: exact= supports only riemann:x0,rhoL,uL,pL,rhoR,uR,pR"
                            "[,gamma]; got %r" % (where, value))
        try:
            case.exact = parse_spec(spec)
        except RiemannError as exc:
            raise CaseError("%s: %s" % (where, exc))
    elif key.startswith("tol:"):
        parts = value.split(",")
        if len(parts) != 2 or not key[4:]:
            raise CaseError("%s: tol:QUANTITY=ABS,REL expected, got %s=%s"
                            % (where, key, value))
        case.tol[key[4:]] = (_float(parts[0], key + " abs", where),
                             _float(parts[1], key + " rel", where))
    else:
        raise CaseError("%s: unknown option %r (options: %s, tol:QUANTITY; deck "
                        "overrides look like group.var=value)"
                        % (where, key, ", ".join(_OPTIONS)))


def parse_cases(path):
    """Read the case list; raise CaseError naming file and line on any problem."""
    if not os.path.isfile(path):
        raise CaseError("case list not found: %s" % path)
    cases, seen = [], {}
    for lineno, text in _logical_lines(path):
        where = "%s:%d" % (path, lineno)
        if " -- " in " %s " % text:
            head, _, command = (" %s " % text).partition(" -- ")
            tokens, command = head.split(), command.strip()
        else:
            tokens, command = text.split(), None
        if len(tokens) < 2:
            raise CaseError("%s: expected 'name kind ...', got %r" % (where, text))
        name, kind = tokens[0], tokens[1]
        if not _NAME.match(name):
            raise CaseError("%s: case name %r: use letters, digits, _ . + -" % (where, name))
        if kind not in KINDS:
            raise CaseError("%s: kind %r is not one of %s" % (where, kind, ", ".join(KINDS)))
        if name in seen:
            raise CaseError("%s: case %r already defined on line %d" % (where, name,
                                                                         seen[name]))
        seen[name] = lineno
        case = Case(name, kind, lineno)
        rest = tokens[2:]
        if kind == "command":
            if command is None:  # no '--': everything after the kind is the command
                command, rest = text.split(None, 2)[2] if len(tokens) > 2 else "", []
            if not command:
                raise CaseError("%s: command case %r has no command" % (where, name))
            case.command = command
        else:
            if command is not None:
                raise CaseError("%s: ' -- ' is only for command cases" % where)
            if len(rest) < 2:
                raise CaseError("%s: %s case needs 'np deck' after the kind" % (where, kind))
            if not rest[0].isdigit() or int(rest[0]) < 1:
                raise CaseError("%s: np must be a positive integer, got %r" % (where, rest[0]))
            case.np, case.deck, rest = int(rest[0]), rest[1], rest[2:]
        for tok in rest:
            key, eq, value = tok.partition("=")
            if not eq:
                raise CaseError("%s: %r is neither option=value nor group.var=value"
                                % (where, tok))
            if "." in key and not key.startswith("tol:"):
                if kind == "command":
                    raise CaseError("%s: deck overrides make no sense for a command case"
                                    % where)
                case.overrides.append(tok)
            else:
                _apply_option(case, key, value, where)
        if kind == "restart" and case.chk is None:
            raise CaseError("%s: restart case %r needs chk=NNNNNN" % (where, name))
        cases.append(case)
    return cases


# -- gold files ----------------------------------------------------------------------

def read_gold(path):
    """-> list of (quantity, value, abs_tol, rel_tol) in file order."""
    rows = []
    with open(path) as f:
        for lineno, line in enumerate(f, start=1):
            s = line.strip()
            if not s or s.startswith("#"):
                continue
            parts = s.split()
            try:
                if len(parts) != 4:
                    raise ValueError("4 columns expected")
                rows.append((parts[0], float(parts[1]), float(parts[2]), float(parts[3])))
            except ValueError as exc:
                raise CheckFailure("%s:%d: bad gold line %r (%s)" % (path, lineno, s, exc))
    return rows


def write_gold(path, case, quantities, version):
    lines = ["# gold for regression case '%s' (%s), written by regress/run --generate"
             % (case.name, case.kind),
             "# code version: %s" % version,
             "# date: %s" % time.strftime("%Y-%m-%d %H:%M:%S %z"),
             "# quantity value abs_tol rel_tol   (pass: |got-exp| <= max(abs, rel*|exp|))"]
    for q, v in quantities.items():
        a, r = case.tolerance(q)
        lines.append("%s %.17g %.6g %.6g" % (q, v, a, r))
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write("\n".join(lines) + "\n")
    os.replace(tmp, path)


def compare(quantities, gold_rows):
    """-> list of failure strings (empty = pass)."""
    fails = []
    for q, exp, a, r in gold_rows:
        if q not in quantities:
            fails.append("%s missing from this run (in gold)" % q)
            continue
        got = quantities[q]
        tol = max(a, r * abs(exp))
        if math.isnan(got) or math.isnan(exp) or not abs(got - exp) <= tol:
            fails.append("%s got %.17g expected %.17g tol %.3g (abs %.3g rel %.3g)"
                         % (q, got, exp, tol, a, r))
    known = {row[0] for row in gold_rows}
    for q in quantities:
        if q not in known:
            fails.append("%s is new (not in gold): run regress/run --generate" % q)
    return fails


# -- quantities ------------------------------------------------------------------------

def field_quantities(out_dir, case):
    """min/max/sum of each field of the last plot file, the final history row's totals,
    and the L1 errors against an exact solution when the case asks for them."""
    path = last_plot_file(out_dir)
    q = {}
    with GridFile(path) as g:
        names = g.field_names if case.fields is None else case.fields
        q["plot.step"] = float(g.step)
        q["plot.time"] = float(g.time)
        for n in names:
            a = g.field(n)
            q[n + ".min"] = float(np.min(a))
            q[n + ".max"] = float(np.max(a))
            q[n + ".sum"] = math.fsum(a.ravel().tolist())
        if case.exact is not None:
            x0, left, right, gamma = case.exact
            xs = np.broadcast_to(g.x[None, None, :], g.shape)
            ex = dict(zip(("rho", "u", "p"), exact(xs, g.time, x0, left, right, gamma)))
            for n in ("rho", "u", "p"):
                q["l1." + n] = float(np.mean(np.abs(g.field(n) - ex[n])))
    hist = os.path.join(out_dir, "history.csv")
    names, data = read_history(hist)
    if data.shape[0] == 0:
        raise SabreDataError("%s has no rows" % hist)
    for col in ("mass", "total_energy"):
        q["history." + col] = float(history_column(names, data, col, hist)[-1])
    return q


def identical_fields(path_a, path_b):
    """None if the two plot files hold bit-identical fields (and time, step), else a
    sentence saying what differs first."""
    with GridFile(path_a) as a, GridFile(path_b) as b:
        if a.step != b.step:
            return "final steps differ: %d (%s) vs %d (%s)" % (a.step, path_a, b.step, path_b)
        if np.float64(a.time).view(np.uint64) != np.float64(b.time).view(np.uint64):
            return "final times differ: %r vs %r" % (a.time, b.time)
        if a.field_names != b.field_names:
            return "field lists differ: %s vs %s" % (a.field_names, b.field_names)
        for n in a.field_names:
            fa, fb = a.field(n), b.field(n)
            if fa.dtype != fb.dtype or fa.shape != fb.shape:
                return "field %s: dtype/shape differ" % n
            ba = fa.view(np.uint8).reshape(fa.shape + (-1,))
            bb = fb.view(np.uint8).reshape(fb.shape + (-1,))
            if not np.array_equal(ba, bb):
                diff = np.argwhere(np.any(ba != bb, axis=-1))
                k, j, i = (int(v) for v in diff[0])
                return ("field %s differs in %d cells, first at (i,j,k)=(%d,%d,%d): "
                        "%r vs %r" % (n, len(diff), i, j, k, float(fa[k, j, i]),
                                      float(fb[k, j, i])))
    return None
