#!/usr/bin/env bash
# Issue 18, must-show "the black 50-line edge study <= 60 min wall on the 2 cores", measured
# directly: the committed black edge command of ../2026-12-06-edge-dt0.08 (the same 50 seeds) run
# whole with the build of f77f673 (after the twenty-second speed pass), on an otherwise idle
# 2-vCPU machine. Every speed pass since ../2026-12-06-edge-sorted kept the output bits, so the
# lines must be the same as that study's but for their wall_s: compare.sh checks that.
#   run.sh [NIPDEM_BINARY]      resumable: the realizations already in black/ are kept
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
exec "$here/../2026-12-06-edge-dt0.08/run.sh" "${1:-$here/../../../build/nipdem}" "$here"
