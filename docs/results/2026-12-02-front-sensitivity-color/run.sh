#!/usr/bin/env bash
# Colour clean-state front position at w_h = 100 um, 10 and 30 m/min: one mechanical or
# magnetic parameter changed at a time against the two-speed study's settings (§5.1: "the
# front position of a color DI-unit depends highly on mechanical toner parameters").
# Usage: run.sh NIPDEM OUTDIR [PRESET [VARIANT ...]]   (default: color, every variant)
set -euo pipefail
nipdem=$1; out=$2; preset=${3:-color}; shift $(( $# < 3 ? $# : 3 ))
S=(--set collision.stiffness_scale=0.01
   --set geometry.window_x_min_m=-400e-6 --set geometry.window_x_max_m=700e-6)
declare -A V=(
  [base]=""
  [roller_mu_x1.5]="collision.toner_roller.mu_s=0.87 collision.toner_roller.mu_d=0.60"
  [roller_mu_x0.5]="collision.toner_roller.mu_s=0.29 collision.toner_roller.mu_d=0.20"
  [drum_mu_x0.5]="collision.toner_drum.mu_s=0.265 collision.toner_drum.mu_d=0.17"
  [toner_mu_x0.5]="collision.toner_toner.mu_s=0.235 collision.toner_toner.mu_d=0.095"
  [toner_mu_x1.5]="collision.toner_toner.mu_s=0.705 collision.toner_toner.mu_d=0.285"
  [toner_mu_x2]="collision.toner_toner.mu_s=0.94 collision.toner_toner.mu_d=0.38"
  [r_10]="adhesion.cohesion_ratio=10"
  [r_100]="adhesion.cohesion_ratio=100"
  [roller_adh_x10]="adhesion.roller_force_N=1e-9"
  [shape_single]="toner.cluster=single"
  [shape_quad4]="toner.cluster=quad4"
  [shape_penta5]="toner.cluster=penta5"
  [shape_hexa6]="toner.cluster=hexa6"
  [shape_boulder3]="toner.cluster=boulder3"
  [layer_15um]="inflow.layer_thickness_m=15e-6"
  [layer_30um]="inflow.layer_thickness_m=30e-6"
  [layer_45um]="inflow.layer_thickness_m=45e-6"
  [pits_empty]="inflow.roller_pits=empty"
  [no_dipole]="magnet.dipole_dipole=false"
)
names=("$@"); [ ${#names[@]} -eq 0 ] && names=($(printf '%s\n' "${!V[@]}" | sort))
for name in "${names[@]}"; do
  [ -n "${V[$name]+x}" ] || { echo "run.sh: unknown variant '$name'" >&2; exit 2; }
  extra=()
  case "${V[$name]}" in *inflow.layer_thickness_m*) ;; *) extra+=(--set inflow.layer_thickness_m=60e-6) ;; esac
  for kv in ${V[$name]}; do extra+=(--set "$kv"); done
  mkdir -p "$out/$name"
  for seed in 1 2; do
    d="$out/$name/s$seed"
    [ -f "$d/front-position.json" ] && continue
    "$nipdem" experiment front-position --preset "$preset" --seed "$seed" --gap 100e-6 \
      --sleeve-speed 10,30 "${S[@]}" "${extra[@]}" --min-time 1.5e-3 --max-time 4e-3 \
      --jobs 2 --quiet --out "$d" --json > "$d.json.tmp" && mv "$d.json.tmp" "$d.stdout.json"
    echo "$name s$seed done $(date +%T)"
  done
done
