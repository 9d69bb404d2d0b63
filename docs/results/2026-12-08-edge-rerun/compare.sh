#!/usr/bin/env bash
# This rerun against ../2026-12-06-edge-sorted (the same command and seeds, 4260d29): every column of
# lines.csv but wall_s must be equal line by line (the speed passes since kept every output bit),
# and the summary (edge widths with their bootstrap intervals, printed toner) is written by
# ../2026-12-06-edge-dt0.08/compare.py to compare.json / compare.png here.
set -euo pipefail
cd "$(dirname "$0")"
ref=../2026-12-06-edge-sorted/black/lines.csv
if diff <(cut -d, -f1-3,5- "$ref") <(cut -d, -f1-3,5- black/lines.csv) > lines.diff; then
  echo "lines.csv: all $(($(wc -l < black/lines.csv) - 1)) lines equal to $ref but for wall_s"
  rm -f lines.diff
else
  echo "lines.csv differs from $ref (see lines.diff)"; exit 1
fi
/usr/bin/python3 ../2026-12-06-edge-dt0.08/compare.py black ../2026-12-06-edge-sorted/black . \
  "spatial order (4260d29)" "rerun (f77f673)"
