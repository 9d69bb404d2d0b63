#!/usr/bin/env bash
# Two threads against one, with the OpenMP wait settings to compare, rounds alternated (the
# machine is shared and noisy: each round runs every variant once, in the same order).
#   bench/run_threads.sh [--contended] ROUNDS WAITS -- BENCH_BINARY ARGS...
# WAITS: comma-separated settings for the 2-thread runs: passive, active, spinN (GOMP_SPINCOUNT=N),
#        or default (nipdem's own choice, core/wait_policy.hpp). The 1-thread reference runs with
#        the program's default.
# --contended: a busy loop at normal priority holds one core during the runs (a second job on a
#        2-core machine), to see what the engine's thread choice makes of it.
# BENCH_BINARY is bench_lammps_packing or bench_nip; ARGS must not contain --threads/--run-threads
# (added here: 1 thread, then 2 threads with the engine's measured choice, --run-threads 0).
# e.g. bench/run_threads.sh 3 passive,spin10000 -- build/bench/bench_lammps_packing --steps 3000
#      bench/run_threads.sh 3 passive,spin10000 -- build/bench/bench_nip --dense-file dense.bin --steps 4000
# Prints per round each variant's disc-steps per wall second, the thread count the engine ran at
# the end, and its ratio to the 1-thread run; then the median ratio of each variant.
set -euo pipefail
contended=0
if [ "${1:-}" = "--contended" ]; then contended=1; shift; fi
[ $# -ge 4 ] && [ "$3" = "--" ] || { echo "usage: $0 [--contended] ROUNDS WAITS -- BENCH_BINARY ARGS..." >&2; exit 2; }
ROUNDS=$1 WAITS=$2
shift 3
IFS=, read -r -a waits <<<"$WAITS"
# disc-steps per wall second and the threads running at the end, from either benchmark's output
rate() {
  "$@" 2>&1 | awk '
    /knife \+ dipole-dipole:/ && !n {for (i=1;i<=NF;i++) {split($i, kv, "="); if (kv[1]=="disc_steps_per_s") v=kv[2]; if (kv[1]=="threads_running") t=kv[2]}; n=1}
    /thread use:/ {for (i=1;i<=NF;i++) if ($(i+1)=="threads" && $(i+2)=="at") t=$i}
    /^RESULT nipdem/ {for (i=1;i<=NF;i++) {split($i, kv, "="); if (kv[1]=="disc_steps_per_s") v=kv[2]}}
    END {if (v == "") {print "FAILED"; exit 1}; print v, (t == "" ? "?" : t)}'
}
env_of() {
  case $1 in
    passive) echo "OMP_WAIT_POLICY=passive" ;;
    active) echo "OMP_WAIT_POLICY=active" ;;
    spin*) echo "GOMP_SPINCOUNT=${1#spin}" ;;
    default) echo "NIPDEM_UNUSED=1" ;;
    *) echo "unknown wait setting $1 (passive, active, spinN, default)" >&2; exit 2 ;;
  esac
}
busy=""
if [ $contended = 1 ]; then
  (while :; do :; done) >/dev/null 2>&1 &
  busy=$!
  trap 'kill $busy 2>/dev/null' EXIT
fi
echo "$(date -u +%FT%TZ) $([ $contended = 1 ] && echo contended || echo free) rounds=$ROUNDS: $*"
declare -A ratios
for r in $(seq 1 "$ROUNDS"); do
  read -r one t1 < <(rate "$@" --threads 1)
  line="round $r: 1 thread $one"
  for w in "${waits[@]}"; do
    read -r two t2 < <(rate env "$(env_of "$w")" "$@" --threads 2 --run-threads 0)
    q=$(awk -v a="$one" -v b="$two" 'BEGIN{printf "%.3f", b/a}')
    ratios[$w]+="$q "
    line+=" | $w: $two (ran $t2) $q"
  done
  echo "$line  (load $(cut -d' ' -f1 /proc/loadavg))"
done
for w in "${waits[@]}"; do
  echo "${ratios[$w]}" | tr ' ' '\n' | grep . | sort -g |
    awk -v w="$w" '{a[NR]=$1} END{printf "MEDIAN 2 threads / 1 thread, %s: %s over %d rounds\n", w, (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2, NR}'
done
