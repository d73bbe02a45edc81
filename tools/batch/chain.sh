# shellcheck shell=bash
# The restart chain of SABRE's batch jobs (manual/user-guide.md "Running on batch queues"),
# sourced by tools/batch/sabre.slurm and tools/batch/sabre.pbs. One try of a chain:
#   1. out_dir from the deck (or a run.out_dir= override); the try number;
#   2. the newest complete checkpoint in out_dir when the try continues a run;
#   3. run.wall_limit from the time the queue has left for the job, less SABRE_MARGIN;
#   4. SABRE under the launcher, in the background, so that the queue's warning signal
#      (USR1, USR2) or time-limit signal (TERM) reaches the shell and is passed on to it
#      (a TERM as USR1);
#   5. its verdict: exit 0 is a complete run; exit 75 (or a run.log that ends with SABRE's
#      "stopped cleanly" line) is a clean stop with a checkpoint, and the chain goes on
#      through the queue's own function (requeue, or a resubmission) unless SABRE_MAX_TRIES
#      tries have run; anything else is a failure and ends the chain.
# Every try appends one line to out_dir/batch.log and keeps its run.log as run.tryN.log; a
# complete run writes out_dir/batch.done. A first try that does not continue clears them.
# The queue-specific parts are functions the job script defines before calling chain_run:
#   queue_time_left   seconds the job has left (empty: unknown)
#   queue_continue    put the next try in the queue (its argument: the next try number)
#   queue_job_id      the job's id, for batch.log
# Environment (all optional): SABRE_ROOT (repository; default the submit folder), SABRE (the
# solver; default $SABRE_ROOT/bin/sabre), SABRE_LAUNCH (launcher command line), SABRE_MARGIN
# (seconds kept free before the queue's limit; default 120), SABRE_WALL_LIMIT (seconds; given
# to the solver as it stands, 0 for none), SABRE_MAX_TRIES (default 10), SABRE_CONTINUE=1
# (the first try also continues from the newest checkpoint in out_dir).

# exit status of a run that stopped cleanly before its end (modules/core/m_signals.f90)
readonly chain_exit_stopped=75

chain_log() { echo "sabre-batch: $*" >&2; }

# out_dir: the last run.out_dir= of the arguments, else the deck's &run out_dir
chain_out_dir() {
  local deck=$1 arg dir=""
  shift
  for arg in "$@"; do
    case $arg in run.out_dir=*) dir=${arg#run.out_dir=} ;; esac
  done
  if [ -z "$dir" ]; then
    dir=$(sed -n "s/^[^!]*\\bout_dir *= *['\"]\\([^'\"]*\\)['\"].*/\\1/p" "$deck" | tail -n 1)
  fi
  dir=${dir#[\'\"]}
  dir=${dir%[\'\"]}
  [ -n "$dir" ] || dir=out
  echo "$dir"
}

# the checkpoint with the highest step in $1 that opens as a whole HDF5 file (h5py, when
# there is one: a file cut short by a kill fails to open); empty when there is none
chain_newest_checkpoint() {
  local dir=$1 f best="" best_step=-1 step
  local -a found=()
  for f in "$dir"/chk_*.h5; do
    [ -e "$f" ] || continue
    step=${f##*/chk_}
    step=${step%.h5}
    [[ $step =~ ^[0-9]+$ ]] || continue
    found+=("$((10#$step)) $f")
  done
  [ ${#found[@]} -gt 0 ] || return 0
  while read -r step f; do
    if chain_checkpoint_whole "$f"; then
      best=$f
      best_step=$step
      break
    fi
    chain_log "checkpoint $f does not open; trying an older one"
  done < <(printf '%s\n' "${found[@]}" | sort -k1,1nr)
  [ "$best_step" -ge 0 ] && echo "$best"
  return 0
}

chain_checkpoint_whole() {
  local py=${PYTHON:-/usr/bin/python3}
  [ -x "$py" ] || return 0
  "$py" -c 'import h5py' 2>/dev/null || return 0
  "$py" - "$1" <<'EOF' 2>/dev/null
import sys, h5py
with h5py.File(sys.argv[1], "r") as f:
    int(f.attrs["step"])
    f.visit(lambda name: None)
EOF
}

# "[D-]HH:MM:SS", "MM:SS" or seconds -> seconds; nothing for UNLIMITED and the like
chain_seconds() {
  local t=$1 days=0 h=0 m=0 s=0
  [[ $t =~ ^[0-9:-]+$ ]] || return 0
  if [[ $t == *-* ]]; then days=${t%%-*}; t=${t#*-}; fi
  IFS=: read -r -a parts <<< "$t"
  case ${#parts[@]} in
    1) s=${parts[0]} ;;
    2) m=${parts[0]}; s=${parts[1]} ;;
    3) h=${parts[0]}; m=${parts[1]}; s=${parts[2]} ;;
    *) return 0 ;;
  esac
  echo $(( ((10#$days * 24 + 10#$h) * 60 + 10#$m) * 60 + 10#$s ))
}

# the wall_limit to give the solver: SABRE_WALL_LIMIT as it stands, else the queue's time
# left less SABRE_MARGIN (half the time left when the margin is longer than that)
chain_wall_limit() {
  local left margin=${SABRE_MARGIN:-120} limit
  if [ -n "${SABRE_WALL_LIMIT:-}" ]; then
    echo "$SABRE_WALL_LIMIT"
    return 0
  fi
  left=$(queue_time_left || true)
  [ -n "$left" ] || return 0
  limit=$((left - margin))
  [ "$limit" -gt 0 ] || limit=$((left / 2))
  echo "$limit"
}

# a signal to the batch shell goes on to the launcher as SIGUSR1 or SIGUSR2: mpirun and srun
# pass those on to every rank, while both end the run at once on a SIGTERM (mpirun after
# odls_base_sigkill_timeout, srun "forcing job termination"); SABRE treats all three alike
chain_launcher_pid=""
chain_forward() {
  local sig=$1 pass=USR1
  [ "$sig" = USR2 ] && pass=USR2
  chain_log "caught SIG$sig: passing SIG$pass on to the solver"
  [ -n "$chain_launcher_pid" ] && kill -s "$pass" "$chain_launcher_pid" 2>/dev/null
  return 0
}

# chain_run TRY DECK [group.var=value ...]: one try of the chain
chain_run() {
  local try=$1 deck=$2
  shift 2
  local root=${SABRE_ROOT:-$PWD}
  local sabre=${SABRE:-$root/bin/sabre}
  local max_tries=${SABRE_MAX_TRIES:-10}
  local out chk="" limit rc=0 started verdict
  local -a args=("$@") launch
  out=$(chain_out_dir "$deck" "$@")
  if [ "$try" -eq 1 ] && [ "${SABRE_CONTINUE:-0}" != 1 ]; then
    # a new chain: the records of an earlier one in this folder go
    rm -f "$out/batch.log" "$out/batch.done" "$out"/run.try*.log
  fi
  if [ "$try" -gt 1 ] || [ "${SABRE_CONTINUE:-0}" = 1 ]; then
    chk=$(chain_newest_checkpoint "$out")
    if [ -n "$chk" ]; then
      args+=("run.restart='$chk'")
    elif [ "$try" -gt 1 ]; then
      # the earlier tries stopped before their first checkpoint: their results are ours
      args+=("run.overwrite=.true.")
    fi
  fi
  limit=$(chain_wall_limit)
  [ -n "$limit" ] && args+=("run.wall_limit=$limit")
  read -r -a launch <<< "${SABRE_LAUNCH:-}"
  chain_log "try $try of at most $max_tries, job $(queue_job_id): ${chk:-fresh start}," \
    "wall_limit ${limit:-none}"
  started=$(date +%s)
  trap 'chain_forward USR1' USR1
  trap 'chain_forward USR2' USR2
  trap 'chain_forward TERM' TERM
  "${launch[@]}" "$sabre" "$deck" "${args[@]}" &
  chain_launcher_pid=$!
  # a trapped signal ends `wait` early: wait again until the solver has gone (an ended but
  # unreaped launcher still answers kill -0, so the last wait has its own exit status)
  while :; do
    rc=0
    wait "$chain_launcher_pid" || rc=$?
    kill -0 "$chain_launcher_pid" 2>/dev/null || break
  done
  trap - USR1 USR2 TERM
  if [ "$rc" -eq 0 ]; then
    verdict=complete
  elif [ "$rc" -eq "$chain_exit_stopped" ] || { chain_fresh_log "$out/run.log" "$started" &&
      grep -q 'stopped cleanly at step' "$out/run.log"; }; then
    # (the run log decides for a launcher whose exit status hides SABRE's)
    verdict=stopped
  else
    verdict=failed
  fi
  mkdir -p "$out"
  if chain_fresh_log "$out/run.log" "$started"; then cp "$out/run.log" "$out/run.try$try.log"; fi
  printf '%s try %d job %s start %s exit %d %s after %d s\n' "$(date -u +%FT%TZ)" "$try" \
    "$(queue_job_id)" "${chk:-fresh}" "$rc" "$verdict" $(( $(date +%s) - started )) \
    >> "$out/batch.log"
  case $verdict in
    complete)
      echo "complete after $try tries" > "$out/batch.done"
      chain_log "run complete after $try tries: $out"
      return 0 ;;
    stopped)
      if [ "$try" -ge "$max_tries" ]; then
        chain_log "stopped cleanly, but $max_tries tries have run (SABRE_MAX_TRIES):" \
          "continue by hand with SABRE_CONTINUE=1"
        return 1
      fi
      chain_log "stopped cleanly: try $((try + 1)) goes into the queue"
      queue_continue $((try + 1))
      return 0 ;;
    *)
      chain_log "the solver failed (exit $rc): the chain ends; see $out/run.log"
      return 1 ;;
  esac
}

# whether run log $1 was written since time $2 (a solver that failed before opening it
# leaves the last try's)
chain_fresh_log() {
  [ -f "$1" ] && [ "$(stat -c %Y "$1")" -ge "$2" ]
}
