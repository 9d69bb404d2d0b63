#!/usr/bin/env bash
# Line-by-line comparison of this study (spatial body order) with ../2026-12-06-edge-dt0.08/black
# (the same command and seeds, bodies in insertion order): compare.json and compare.png here.
set -euo pipefail
cd "$(dirname "$0")"
/usr/bin/python3 ../2026-12-06-edge-dt0.08/compare.py black ../2026-12-06-edge-dt0.08/black . \
  "insertion order (f91aec8)" "spatial order (4260d29)"
