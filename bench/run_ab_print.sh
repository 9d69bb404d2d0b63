#!/usr/bin/env bash
# Alternated A/B CPU time of the production print workload (not a bench program: the whole
# `nipdem run` of a print-line configuration, charge model, electric force, magnet and
# dipole-dipole forces included): runs A, B, A, B, ... ROUNDS times and prints each run's user+sys
# CPU seconds and the round's speed ratio A/B (> 1: B is faster), then the median.
#   bench/run_ab_print.sh A_NIPDEM B_NIPDEM ROUNDS [CONFIG [END_TIME_S [--set KEY=V ...]]]
# defaults: examples/print_line_black.toml, 5e-4 s (about 45,000 steps, 15-20 s on one core).
set -euo pipefail
[ $# -ge 3 ] || { echo "usage: $0 A B ROUNDS [CONFIG [END_TIME_S [--set KEY=V ...]]]" >&2; exit 2; }
A=$1 B=$2 ROUNDS=$3
here=$(cd "$(dirname "$0")" && pwd)
CONFIG=${4:-$here/../examples/print_line_black.toml}
END=${5:-5e-4}
shift $(( $# < 5 ? $# : 5 ))
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
cpu() {  # cpu BINARY TAG [--set ...]: user+sys seconds of one run
  local bin=$1 tag=$2
  shift 2
  /usr/bin/time -o "$tmp/t_$tag" -f "%U %S" "$bin" run "$CONFIG" --set run.end_time_s="$END" "$@" --force --quiet \
    --out "$tmp/out_$tag" >/dev/null 2>&1 || { echo "run failed: $bin" >&2; exit 1; }
  awk '{printf "%.2f\n", $1 + $2}' "$tmp/t_$tag"
}
echo "A=$A"; echo "B=$B"; echo "config: $CONFIG, end time $END s; $(date -u +%FT%TZ); load $(cut -d' ' -f1-3 /proc/loadavg)"
ratios=()
for r in $(seq "$ROUNDS"); do
  a=$(cpu "$A" a "${@}"); b=$(cpu "$B" b "${@}")
  q=$(awk -v a="$a" -v b="$b" 'BEGIN {printf "%.3f", a / b}')
  ratios+=("$q")
  echo "round $r: A ${a} s  B ${b} s  A/B ${q}"
done
printf '%s\n' "${ratios[@]}" | sort -g | awk '{v[NR]=$1} END {m = NR % 2 ? v[(NR+1)/2] : (v[NR/2]+v[NR/2+1])/2; printf "MEDIAN A/B %.3f over %d rounds\n", m, NR}'
