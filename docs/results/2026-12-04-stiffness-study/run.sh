#!/usr/bin/env bash
# Issue 17 item 3: is the clean-state front position robust to the softening of k (§4.2.2)?
# Front position at stiffness_scale 0.01, 0.03, 0.1; w_h = 150 um, the presets' sleeve speeds,
# both presets (as calibrated: docs/reduction.md), 3 seeds, 8 ms; window and inflow as the 8 ms
# study (docs/results/2026-12-02-front-position-8ms). One point per invocation; resumes: a point
# whose JSON exists is skipped.        run.sh [NIPDEM_BINARY]
# run.sh long [NIPDEM_BINARY]: the 16 ms check of black at 0.03 and 0.1 (7 of 9 of the softer
# 8 ms runs were still drifting; runs/black_k*_s*_16ms), 3 seeds.
set -euo pipefail
long=0
if [[ ${1:-} == long ]]; then long=1; shift; fi
bin=${1:-$(dirname "$0")/../../../build/nipdem}
cd "$(dirname "$0")"
S="--set inflow.layer_thickness_m=60e-6 --set geometry.window_x_min_m=-400e-6 --set geometry.window_x_max_m=700e-6"
mkdir -p runs
if (( long )); then
  for seed in 1 2 3; do for k in 0.03 0.1; do
    name=black_k${k}_s${seed}_16ms
    [[ -s runs/$name.json ]] && continue
    t0=$(date +%s)
    "$bin" experiment front-position --preset black --seed $seed $S --set collision.stiffness_scale=$k \
      --gap 150e-6 --min-time 16e-3 --max-time 16e-3 --out runs/$name --json --quiet \
      > runs/$name.json.tmp 2> runs/$name.err && mv runs/$name.json.tmp runs/$name.json
    echo "$name $(( $(date +%s) - t0 )) s $("$bin" version 2>/dev/null | head -1)" >> walltimes.txt
  done; done
  exit 0
fi
for seed in 1 2 3; do for preset in color black; do for k in 0.01 0.03 0.1; do
  name=${preset}_k${k}_s${seed}
  [[ -s runs/$name.json ]] && continue
  t0=$(date +%s)
  "$bin" experiment front-position --preset $preset --seed $seed $S --set collision.stiffness_scale=$k \
    --gap 150e-6 --min-time 8e-3 --max-time 8e-3 --out runs/$name --json --quiet \
    > runs/$name.json.tmp 2> runs/$name.err && mv runs/$name.json.tmp runs/$name.json
  echo "$name $(( $(date +%s) - t0 )) s $("$bin" version 2>/dev/null | head -1)" >> walltimes.txt
done; done; done
