#!/bin/bash
# screen2.sh NAME PRESET TIME RLIST PITS [--set ...]
name=$1; preset=$2; t=$3; rl=$4; pits=$5; shift 5
sets=()
for s in "$@"; do sets+=(--set "$s"); done
/usr/bin/time -f "%e s wall %U s user" ./nipdem-17a5062 experiment reduction --preset $preset --r $rl --time $t --pits $pits \
  --set collision.stiffness_scale=0.01 "${sets[@]}" --jobs 1 --out scr/$name --json > scr/$name.json 2> scr/$name.log
