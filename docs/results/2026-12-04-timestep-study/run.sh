#!/usr/bin/env bash
# Issue 18 item 4: front position over 2 ms against the time step, both integrators, 3 seeds,
# both presets, one gap (150 um), the presets' sleeve speeds, the 8 ms study's settings.
# Resumes: a point whose JSON exists is skipped.   run.sh [NIPDEM_BINARY]
set -euo pipefail
bin=${1:-$(dirname "$0")/../../../build/nipdem}
cd "$(dirname "$0")"
S="--set collision.stiffness_scale=0.01 --set inflow.layer_thickness_m=60e-6 --set geometry.window_x_min_m=-400e-6 --set geometry.window_x_max_m=700e-6"
mkdir -p runs
for preset in color black; do for integ in velocity_verlet newmark_explicit; do for frac in 0.02 0.04 0.08 0.12; do for seed in 1 2 3; do
  name=${preset}_${integ}_${frac}_s${seed}
  [[ -s runs/$name.json ]] && continue
  t0=$(date +%s)
  "$bin" experiment front-position --preset $preset --seed $seed $S --set run.integrator=$integ \
    --set run.dt_fraction_of_contact_time=$frac --min-time 2e-3 --max-time 2e-3 --out runs/$name --json --quiet \
    > runs/$name.json.tmp 2> runs/$name.err && mv runs/$name.json.tmp runs/$name.json
  echo "$name $(( $(date +%s) - t0 )) s" >> walltimes.txt
done; done; done; done
