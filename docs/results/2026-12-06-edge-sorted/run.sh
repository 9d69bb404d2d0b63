#!/usr/bin/env bash
# Issue 18, must-show "the black 50-line edge study <= 60 min wall on the 2 cores": the committed
# black edge command of ../2026-12-06-edge-dt0.08 (examples/print_line_black.toml, stiffness 0.03,
# dt = 0.08 t_n, run.seed 7: the same 50 realization seeds) with the engine's spatial body order
# (4260d29). The order changes the order of the force sums, so every line is a new realization of
# the same physics: compare.sh compares it line by line with ../2026-12-06-edge-dt0.08/black.
#   run.sh [NIPDEM_BINARY]      resumable: the realizations already in black/ are kept
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
exec "$here/../2026-12-06-edge-dt0.08/run.sh" "${1:-$here/../../../build/nipdem}" "$here"
