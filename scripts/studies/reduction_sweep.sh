#!/usr/bin/env bash
# Issue 17 reduction sweep: one preset, one seed, one roller adhesion force, r = 0..3, 100 ms,
# 7.1 um equal-volume roughness cut, stiffness_scale 0.01, one core. Resumes: finished r points
# in OUT/reduction/realizations are kept.
#   scripts/studies/reduction_sweep.sh PRESET SEED F_ADH_N OUT [NIPDEM_BINARY]
# stdout: the experiment's JSON; stderr: progress; appends "preset seed F rc wall" to
# $(dirname OUT)/walltimes.txt. R_LIST=a,b,... replaces the r list (e.g. R_LIST=1.5,2 for the
# third-seed check of the calibrated r, docs/reduction.md).
set -euo pipefail
[[ $# -ge 4 ]] || { echo "usage: $0 PRESET SEED F_ADH_N OUT [BINARY]" >&2; exit 2; }
preset=$1 seed=$2 force=$3 out=$4
bin=${5:-$(dirname "$0")/../../build/nipdem}
start=$(date +%s)
rc=0
"$bin" experiment reduction --preset "$preset" --seed "$seed" --r "${R_LIST:-0,1,3,0.5,0.25,0.75,1.5}" --time 0.1 \
  --set adhesion.roller_force_N="$force" --set geometry.roughness.height_m=7.1e-6 \
  --set collision.stiffness_scale=0.01 --jobs 1 --out "$out" --json || rc=$?
echo "$preset seed $seed F=$force rc=$rc wall $(( $(date +%s) - start )) s ($(git -C "$(dirname "$0")" rev-parse --short HEAD 2>/dev/null || echo ?))" \
  >> "$(dirname "$out")/walltimes.txt"
exit $rc
