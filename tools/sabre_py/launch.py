"""The one way the Python tools start SABRE (and the commands regress/run runs).

    from sabre_py.launch import run_sabre, SabreRunError
    out = run_sabre('decks/sod.nml', 'out/sod', ["numerics.scheme='weno5'"], np=2)

The solver is `sabre`, else $SABRE, else <repo>/bin/sabre; with np > 1 the MPI launcher is
`mpirun`, else $MPIRUN, else mpirun (a string is split like a shell word list, so
MPIRUN="mpirun --mca btl self,vader" works), given -np N first (OpenCoarrays' cafrun takes
no other option before it) and --oversubscribe unless it is already there.  Open MPI is
allowed to run as root (OMPI_ALLOW_RUN_AS_ROOT, OMPI_ALLOW_RUN_AS_ROOT_CONFIRM).  Relative
paths are from the repository root, which is also the working folder of the run.  What the
solver prints goes to <out_dir>.log; a failed or timed-out run raises SabreRunError with
the command and the last lines of that log.
"""
import os
import shlex
import shutil
import signal
import subprocess

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.realpath(__file__))))
# Open MPI refuses to start as root without these (manual/user-guide.md)
MPI_ENV = {"OMPI_ALLOW_RUN_AS_ROOT": "1", "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM": "1"}


class SabreRunError(RuntimeError):
    """The solver (or a command) could not start, failed, or ran out of time."""


def sabre_path(sabre=None):
    """The solver executable `sabre`, $SABRE or <repo>/bin/sabre, as an absolute path."""
    path = sabre or os.environ.get("SABRE") or os.path.join(ROOT, "bin", "sabre")
    # a relative path: from the current folder, else from the repository root
    return os.path.abspath(path if os.path.exists(path) else os.path.join(ROOT, path))


def mpi_launcher(mpirun=None):
    """The MPI launcher as a word list: `mpirun`, $MPIRUN or mpirun."""
    words = mpirun if isinstance(mpirun, (list, tuple)) else shlex.split(
        mpirun or os.environ.get("MPIRUN") or "mpirun")
    return list(words)


def mpi_env(extra=None):
    """os.environ with Open MPI allowed to run as root, plus `extra`."""
    return dict(os.environ, **MPI_ENV, **(extra or {}))


def log_tail(path, n=6, prefix="\n    | "):
    """The last n lines of a log file, each after `prefix` ('' when it cannot be read)."""
    try:
        with open(path, errors="replace") as f:
            lines = f.read().splitlines()[-n:]
    except OSError:
        return ""
    return "".join(prefix + line for line in lines)


def first_error(path):
    """The solver's first ERROR line in a log (under mpirun it is not among the last), as
    '\n    ERROR ...', or ''."""
    try:
        with open(path, errors="replace") as f:
            for line in f:
                if line.startswith("ERROR"):
                    return "\n    " + line.rstrip()
    except OSError:
        pass
    return ""


def show(path):
    """path relative to the current folder when that is shorter."""
    r = os.path.relpath(path, os.getcwd())
    return path if r.startswith("../..") else r


def _kill(proc):
    """End the process group started for proc (mpirun and its ranks)."""
    for sig in (signal.SIGTERM, signal.SIGKILL):
        try:
            os.killpg(proc.pid, sig)
        except ProcessLookupError:
            return
        try:
            proc.wait(timeout=5)
            return
        except subprocess.TimeoutExpired:
            continue


def run_logged(cmd, log_path, timeout=None, env=None, shell=False, cwd=ROOT):
    """Run cmd (a word list, or a shell line with shell=True) in its own process group with
    stdout and stderr to log_path; return its exit status.  On timeout the whole group is
    ended and SabreRunError raised; on Ctrl-C it is ended too."""
    with open(log_path, "w") as log:
        proc = subprocess.Popen(cmd, cwd=cwd, stdout=log, stderr=subprocess.STDOUT,
                                stdin=subprocess.DEVNULL, shell=shell,
                                env=env or mpi_env(), start_new_session=True)
        try:
            return proc.wait(timeout=timeout)
        except subprocess.TimeoutExpired:
            _kill(proc)
            raise SabreRunError("timed out after %g s (log: %s)%s"
                                % (timeout, show(log_path), log_tail(log_path)))
        except KeyboardInterrupt:
            _kill(proc)
            raise


def sabre_command(deck, out_dir, overrides=(), np=1, sabre=None, mpirun=None,
                  launch_one=False):
    """The command line run_sabre runs: [launcher -np N --oversubscribe] sabre deck
    overrides run.out_dir='out_dir' run.overwrite=.true. (one rank without the launcher
    unless launch_one)."""
    cmd = [sabre_path(sabre), deck] + list(overrides) + ["run.out_dir='%s'" % out_dir,
                                                         "run.overwrite=.true."]
    if np > 1 or launch_one:
        launcher = mpi_launcher(mpirun)
        extra = [] if "--oversubscribe" in launcher else ["--oversubscribe"]
        cmd = launcher + ["-np", str(np)] + extra + cmd
    return cmd


def run_sabre(deck, out_dir, overrides=(), np=1, sabre=None, mpirun=None, timeout=None,
              env=None, log=None, verbose=False, launch_one=False):
    """Run SABRE on `deck` into `out_dir` (np ranks; overrides are group.var=value deck
    overrides) and return the absolute path of out_dir.  Output to `log` (default
    <out_dir>.log).  env: more environment variables.  launch_one: start one rank through
    the launcher too (a coarray build under cafrun).  Raises SabreRunError when the solver
    or the launcher is missing, the run times out or exits non-zero."""
    exe = sabre_path(sabre)
    if not os.access(exe, os.X_OK):
        raise SabreRunError("solver not found or not executable: %s (build it with 'make', "
                            "or set $SABRE)" % show(exe))
    if not os.path.isfile(os.path.join(ROOT, deck)):
        raise SabreRunError("deck not found: %s (paths are from the repo root)" % deck)
    if (np > 1 or launch_one) and not shutil.which(mpi_launcher(mpirun)[0]):
        raise SabreRunError("MPI launcher %r not found (set $MPIRUN)"
                            % mpi_launcher(mpirun)[0])
    folder = os.path.join(ROOT, out_dir)
    log = log or folder.rstrip(os.sep) + ".log"
    os.makedirs(os.path.dirname(os.path.abspath(log)), exist_ok=True)
    cmd = sabre_command(deck, out_dir, overrides, np, exe, mpirun, launch_one)
    if verbose:
        print("  $ " + " ".join(shlex.quote(c) for c in cmd), flush=True)
    rc = run_logged(cmd, log, timeout, mpi_env(env))
    if rc != 0:
        tail, error = log_tail(log), first_error(log)
        raise SabreRunError("solver exited with status %d on %d rank(s): %s (log: %s)%s%s"
                            % (rc, np, " ".join(shlex.quote(c) for c in cmd), show(log),
                               "" if error.strip() in tail else error, tail))
    return os.path.abspath(folder)
