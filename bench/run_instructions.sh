#!/usr/bin/env bash
# Instructions per step of a benchmark, counted by valgrind's cachegrind (no timing noise: the
# machine is shared and its speed varies by several per cent between rounds, but the count does
# not). Runs the program twice, with --steps S1 and --steps S2 after --warmup 0, and prints
# (count(S2) - count(S1)) / (S2 - S1), so the set-up cancels. Threads run one at a time under
# valgrind: the count is the work of all threads, not its wall time.
#   bench/run_instructions.sh [S1=100] [S2=600] -- BENCH_BINARY ARGS...
# e.g. bench/run_instructions.sh -- build/bench/bench_lammps_packing --threads 2 --run-threads 1
# Needs valgrind (apt-get install valgrind). The program re-executes itself to set its OpenMP
# wait policy, hence --trace-children=yes.
set -euo pipefail
s1=100 s2=600
if [ "${1:-}" != "--" ]; then s1=$1; shift; fi
if [ "${1:-}" != "--" ]; then s2=$1; shift; fi
[ "${1:-}" = "--" ] && [ $# -ge 2 ] || { echo "usage: $0 [S1] [S2] -- BENCH_BINARY ARGS..." >&2; exit 2; }
shift
command -v valgrind >/dev/null || { echo "$0: valgrind not found (apt-get install valgrind)" >&2; exit 2; }
[ "$s2" -gt "$s1" ] 2>/dev/null || { echo "$0: S2 ($s2) must be an integer above S1 ($s1)" >&2; exit 2; }
count() {
  valgrind --tool=cachegrind --cache-sim=no --trace-children=yes --cachegrind-out-file=/dev/null \
    "$@" 2>&1 | awk '/I[ ]+refs:/ {gsub(",", "", $NF); n = $NF} END {if (n == "") exit 1; print n}'
}
a=$(count "$@" --warmup 0 --steps "$s1") || { echo "$0: no instruction count (did the program run?)" >&2; exit 1; }
b=$(count "$@" --warmup 0 --steps "$s2") || { echo "$0: no instruction count (did the program run?)" >&2; exit 1; }
[ "$b" -gt "$a" ] || { echo "$0: the count did not grow with the steps ($a, $b): does the program take --warmup and --steps?" >&2; exit 1; }
awk -v a="$a" -v b="$b" -v s1="$s1" -v s2="$s2" 'BEGIN {printf "instructions_per_step=%.6g (steps %d: %s, steps %d: %s)\n", (b - a) / (s2 - s1), s1, a, s2, b}'
