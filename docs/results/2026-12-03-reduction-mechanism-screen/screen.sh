#!/bin/bash
# screen.sh NAME PRESET TIME RLIST [--set ...]
name=$1; preset=$2; t=$3; rl=$4; shift 4
sets=()
for s in "$@"; do sets+=(--set "$s"); done
/usr/bin/time -f "%e s wall %U s user" ./nipdem-17a5062 experiment reduction --preset $preset --r $rl --time $t \
  --set collision.stiffness_scale=0.01 "${sets[@]}" --jobs 1 --out scr/$name --json > scr/$name.json 2> scr/$name.log
