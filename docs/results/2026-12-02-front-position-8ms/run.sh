#!/usr/bin/env bash
set -euo pipefail
S="--set collision.stiffness_scale=0.01 --set inflow.layer_thickness_m=60e-6 --set geometry.window_x_min_m=-400e-6 --set geometry.window_x_max_m=700e-6"
for preset in color black; do for seed in 1 2 3; do
  /work/main/build/nipdem experiment front-position --preset $preset --seed $seed --gap 100e-6,150e-6,200e-6 \
    --sleeve-speed 10,30 $S --min-time 8e-3 --max-time 10e-3 --jobs 2 --out $preset/seed_s$seed --json > $preset.s$seed.json 2> $preset.s$seed.err
  echo "$preset s$seed done $(date +%T)"
done; done
