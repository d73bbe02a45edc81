"""run.json, the facts of a finished SABRE run (manual/user-guide.md, "run.json"): what the
tools read instead of run.log's wording; and the one reader of run.log, for the tests that
check what run.log says.

    from sabre_py.runjson import read_run, run_cost
    run = read_run('out/sod')              # a folder, or the path of its run.json
    run['cost']['cell_steps'], run['timings']['loop_seconds']
    cell_steps, loop_seconds, peak_mb = run_cost('out/sod')

Numbers the solver could not give (a per cent of a part that is off) are None.
`python3 -m sabre_py.runjson FOLDER ...` (from tools/) prints a line per run.
"""
import json
import os
import re


class RunJsonError(Exception):
    """run.json is missing, unreadable or not a SABRE run record."""


FORMAT = 'sabre run 1'


def read_run(path):
    """The run record of the folder `path` (or the file itself) as a dict."""
    if os.path.isdir(path):
        path = os.path.join(path, 'run.json')
    try:
        with open(path) as f:
            run = json.load(f)
    except OSError as e:
        raise RunJsonError(f'{path}: {e.strerror} (did the run finish?)') from e
    except ValueError as e:
        raise RunJsonError(f'{path}: not JSON ({e})') from e
    if not isinstance(run, dict) or run.get('format') != FORMAT:
        raise RunJsonError(f"{path}: not a SABRE run record (format {run.get('format')!r}, "
                           f'want {FORMAT!r})' if isinstance(run, dict) else
                           f'{path}: not a SABRE run record')
    return run


def loop_cost(path):
    """(cell-steps, time-loop wall seconds) of a run: the cost the studies plot."""
    run = read_run(path)
    return float(run['cost']['cell_steps']), float(run['timings']['loop_seconds'])


def peak_mb(path):
    """Peak resident memory over all ranks in MB (2^20 bytes)."""
    return float(read_run(path)['memory']['peak_resident_bytes']) / 2**20


def run_cost(path):
    """(cell-steps, time-loop wall seconds, peak resident MB over all ranks) of a run."""
    run = read_run(path)
    return (float(run['cost']['cell_steps']), float(run['timings']['loop_seconds']),
            float(run['memory']['peak_resident_bytes']) / 2**20)


def read_log(path):
    """The text of run.log of the folder `path` (or the file itself): for tests that check
    run.log's wording; tools read run.json."""
    if os.path.isdir(path):
        path = os.path.join(path, 'run.log')
    try:
        with open(path, errors='replace') as f:
            return f.read()
    except OSError as e:
        raise RunJsonError(f'{path}: {e.strerror} (did the run start?)') from e


def log_number(text, label):
    """The first number after the regular expression `label` in run.log's text; NaN if none."""
    m = re.search(label + r' *([-0-9.Ee+]+)', text)
    return float(m.group(1)) if m else float('nan')


def log_lines(text, prefix):
    """The lines of run.log's (or the solver's standard output's) text that start with
    prefix, e.g. 'progress: '."""
    return [ln for ln in text.splitlines() if ln.startswith(prefix)]


if __name__ == '__main__':
    import sys
    for p in sys.argv[1:] or ['.']:
        r = read_run(p)
        print(f"{p}: step {r['end']['step']}, t {r['end']['time']:.6g}, "
              f"{r['cost']['cell_steps']} cell-steps in {r['timings']['loop_seconds']:.3f} s")
