#!/usr/bin/env bash
# Issue 18, must-show "the black 50-line edge study <= 60 min wall on the 2 cores ... where the time
# step changed, the study rerun and compared": the committed black edge command (`edge_black` of
# ../2026-12-05-calibrated-chapter5/run.sh, examples/print_line_black.toml, stiffness 0.03) with
# dt = 0.08 t_n instead of the default 0.04, 50 lines on the 2 cores. The same run.seed (7), so
# the same 50 realization seeds as ../2026-12-05-calibrated-chapter5/edge50/black_k0.03 (0.04):
# a paired comparison, compare.py (writes compare.json and compare.png).
#   run.sh [NIPDEM_BINARY [STUDY_DIR]]   resumable: the realizations already in STUDY_DIR/black/ are kept
# STUDY_DIR (default: this folder) is a sibling results folder that reruns the same command with
# another build (../2026-12-06-edge-sorted/run.sh).
set -euo pipefail
bin=${1:-$(cd "$(dirname "$0")" && pwd)/../../../build/nipdem}
cd "${2:-$(dirname "$0")}"
ex=../../../examples
t0=$(date +%s)
"$bin" experiment edge-sharpness --config $ex/print_line_black.toml --line-start 0.1e-3 --line-length 0.15e-3 \
  --margin 300e-6 --extra-time 0 --realizations 50 --jobs 2 --set run.dt_fraction_of_contact_time=0.08 \
  --out black --json > black.json.tmp 2> black.err
mv black.json.tmp black.json
echo "black 50 lines $(( $(date +%s) - t0 )) s wall, $("$bin" version | head -1), started $(date -u -d @$t0 +%FT%TZ)" >> walltimes.txt
