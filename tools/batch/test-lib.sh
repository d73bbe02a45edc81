# shellcheck shell=bash
# Pieces shared by tools/batch/test-slurm and tools/batch/test-pbs: the deck both run, the
# uninterrupted reference run, the retry of a chain that the machine ran too fast to cut,
# and the bit-for-bit comparison of final plot files.

# a 2D implosion (many blocks, reflections everywhere) a few seconds long on 2 ranks
test_deck=decks/implosion_2d.nml
test_overrides=("run.t_end=0.2" "output.plot_dt=0" "output.checkpoint_every=0")

test_fail() { echo "FAIL: $*" >&2; exit 1; }

# test_reference DIR NP: the uninterrupted run, with t_end doubled (up to 7 times: a quiet
# machine runs the release build fast) until it takes at least
# 10 s (SABRE keeps 5 s and three longest steps in hand before a wall_limit, and a try
# spends a second starting: a shorter run is not cut in two reliably);
# sets ref_wall (whole seconds, rounded) and test_overrides[0] (the t_end used)
test_reference() {
  local dir=$1 np=$2 t0 t1 t_end=${test_overrides[0]#run.t_end=} k
  for k in 1 2 3 4 5 6 7 8; do
    test_overrides[0]="run.t_end=$t_end"
    t0=$(date +%s.%N)
    mpirun --oversubscribe -np "$np" "$SABRE" "$test_deck" "${test_overrides[@]}" \
      "run.out_dir='$dir'" run.overwrite=.true. > "$dir.log" 2>&1 \
      || test_fail "the reference run failed: $dir.log"
    t1=$(date +%s.%N)
    ref_wall=$("$PYTHON" -c "import sys; print(round(float(sys.argv[2]) - float(sys.argv[1])))" \
      "$t0" "$t1")
    [ "$ref_wall" -lt 10 ] || return 0
    t_end=$("$PYTHON" -c "import sys; print(2 * float(sys.argv[1]))" "$t_end")
  done
  test_fail "the reference run stays under 10 s up to t_end = $t_end"
}

# one_try DIR: whether the chain in DIR finished in its first try. A chain's wall_limit is
# calibrated on the reference's wall time; a machine much less loaded than it was for the
# reference (in CI on 2026-12-04 the reference took 12 s and the same run 1.8 s a minute
# later) finishes the run before the limit, and the chain is not tested.
one_try() {
  [ -f "$1/batch.log" ] && [ "$(wc -l < "$1/batch.log")" -eq 1 ]
}

# longer_reference DIR NP: the run made twice as long (t_end), and its reference again
longer_reference() {
  echo "the chain finished in one try (the machine faster than for the reference); again" \
    "with twice ${test_overrides[0]}"
  test_overrides[0]="run.t_end=$("$PYTHON" -c "import sys; print(2 * float(sys.argv[1]))" \
    "${test_overrides[0]#run.t_end=}")"
  rm -rf "$1"
  test_reference "$1" "$2"
}

# test_identical REF DIR: the final plot files hold bit-identical fields, time and step
test_identical() {
  "$PYTHON" - "$SABRE_ROOT/tools" "$1" "$2" <<'EOF' || test_fail "$2 is not bit-identical to $1"
import sys
sys.path.insert(0, sys.argv[1])
from sabre_py.h5io import last_plot_file
from sabre_py.regress import identical_fields
a, b = last_plot_file(sys.argv[2]), last_plot_file(sys.argv[3])
why = identical_fields(a, b)
if why:
    print("differs: " + why)
    sys.exit(1)
print("bit-identical: %s and %s" % (a, b))
EOF
}

# test_tries DIR MIN: batch.log has at least MIN tries, all but the last stopped cleanly,
# the last complete, and batch.done is there
test_tries() {
  local dir=$1 min=$2 n
  [ -f "$dir/batch.log" ] || test_fail "no $dir/batch.log"
  n=$(wc -l < "$dir/batch.log")
  [ "$n" -ge "$min" ] || test_fail "$n tries in $dir/batch.log, expected at least $min"
  [ "$(head -n $((n - 1)) "$dir/batch.log" | grep -vc ' stopped after ')" -eq 0 ] \
    || test_fail "a try before the last did not stop cleanly: $dir/batch.log"
  tail -n 1 "$dir/batch.log" | grep -q ' exit 0 complete ' \
    || test_fail "the last try did not complete: $dir/batch.log"
  [ -f "$dir/batch.done" ] || test_fail "no $dir/batch.done"
  sed 's/^/  /' "$dir/batch.log"
}
