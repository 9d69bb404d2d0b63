#!/usr/bin/env bash
# Issue 18, must-show "the black 50-line edge study <= 60 min wall on the 2 cores": the committed
# black edge command of ../2026-12-06-edge-dt0.08 (examples/print_line_black.toml, stiffness 0.03,
# dt = 0.08 t_n, run.seed 7: the same 50 realization seeds) with the engine's spatial body order
# (4260d29). The order changes the order of the force sums, so every line is a new realization of
# the same physics: compare.sh compares it line by line with ../2026-12-06-edge-dt0.08/black.
#   run.sh [NIPDEM_BINARY]      resumable: the realizations already in black/ are kept
set -euo pipefail
bin=${1:-$(cd "$(dirname "$0")" && pwd)/../../../build/nipdem}
cd "$(dirname "$0")"
ex=../../../examples
t0=$(date +%s)
"$bin" experiment edge-sharpness --config $ex/print_line_black.toml --line-start 0.1e-3 --line-length 0.15e-3 \
  --margin 300e-6 --extra-time 0 --realizations 50 --jobs 2 --set run.dt_fraction_of_contact_time=0.08 \
  --out black --json > black.json.tmp 2> black.err
mv black.json.tmp black.json
echo "black 50 lines $(( $(date +%s) - t0 )) s wall, $("$bin" version | head -1), started $(date -u -d @$t0 +%FT%TZ)" >> walltimes.txt
