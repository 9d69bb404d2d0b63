#!/usr/bin/env bash
# Side-by-side timing of nipdem and LAMMPS on the same 2D packing (bench/README.md).
# Alternates LAMMPS (1 rank, then 2 MPI ranks) and nipdem (1, then 2 OpenMP threads) for
# ROUNDS rounds so that load from other jobs on a shared machine hits both alike, then prints
# the throughputs and nipdem/LAMMPS ratios per round and their medians, plus the physics
# cross-check (final kinetic energy, contacts per disc).
#
# Usage: bench/run_lammps_compare.sh [STEPS=20000] [ROUNDS=3]
# Needs: lmp (Debian package lammps), mpirun (openmpi-bin), build/bench/bench_lammps_packing.
# Env:   BUILD (default build), WORK (scratch dir, default /tmp/nipdem_lammps_compare),
#        PACKING (default /work/shared/bench/lammps-2d-packing),
#        YIELD=1: waiting threads/ranks sleep instead of spinning (OMP_WAIT_POLICY=passive for
#        nipdem, --mca mpi_yield_when_idle 1 for LAMMPS): much faster on a machine shared with
#        other jobs, where a spinning thread waits for one that is descheduled.
set -euo pipefail
STEPS=${1:-20000}
ROUNDS=${2:-3}
HERE=$(cd "$(dirname "$0")/.." && pwd)
BUILD=${BUILD:-$HERE/build}
PACKING=${PACKING:-/work/shared/bench/lammps-2d-packing}
WORK=${WORK:-/tmp/nipdem_lammps_compare}
NIP=$BUILD/bench/bench_lammps_packing
MPIOPT=()
if [ "${YIELD:-0}" = 1 ]; then export OMP_WAIT_POLICY=passive; MPIOPT=(--mca mpi_yield_when_idle 1); fi
N=30000

command -v lmp >/dev/null || { echo "lmp not found (apt-get install -y lammps openmpi-bin)" >&2; exit 2; }
[ -x "$NIP" ] || { echo "$NIP not built" >&2; exit 2; }
mkdir -p "$WORK"
cp "$PACKING/params.inc" "$PACKING/bench_lammps_hooke.in" "$WORK/"
[ -f "$WORK/packing.data" ] || gzip -dc "$PACKING/packing.data.gz" > "$WORK/packing.data"

# LAMMPS: throughput of the timed (second) run from its "Loop time"; KE after it; contacts.
run_lammps() {  # $1 = ranks
  local log="$WORK/log.np$1"
  (cd "$WORK" && if [ "$1" = 1 ]; then
     lmp -in bench_lammps_hooke.in -var data packing.data -var nsteps "$STEPS" -log "$log" -screen none
   else
     mpirun --allow-run-as-root "${MPIOPT[@]}" -np "$1" lmp -in bench_lammps_hooke.in -var data packing.data -var nsteps "$STEPS" \
       -log "$log" -screen none
   fi) >/dev/null
  local loop ke z
  loop=$(grep "^Loop time" "$log" | sed -n 2p | awk '{print $4}')
  ke=$(awk -v s=$((1000 + STEPS)) '$1 == s && $2 == 30000 {print $3; exit}' "$log")
  z=$(grep CONTACTS_PER_PARTICLE "$log" | grep -v print | awk '{print $2}')
  echo "$(awk -v n=$N -v s="$STEPS" -v t="$loop" 'BEGIN{printf "%.4g", n*s/t}') $loop $ke $z"
}
run_nipdem() {  # $1 = threads
  local out
  out=$("$NIP" --steps "$STEPS" --threads "$1")
  local rate wall ke z
  rate=$(echo "$out" | awk '/^RESULT/ {for (i=1;i<=NF;i++) if ($i ~ /^disc_steps_per_s=/) {sub(/.*=/,"",$i); print $i}}')
  wall=$(echo "$out" | awk '/^RESULT/ {for (i=1;i<=NF;i++) if ($i ~ /^wall_s=/) {sub(/.*=/,"",$i); print $i}}')
  ke=$(echo "$out" | awk '/final:/ {for (i=1;i<=NF;i++) if ($i ~ /^ke_translational_J=/) {sub(/.*=/,"",$i); print $i}}')
  z=$(echo "$out" | awk '/final:/ {for (i=1;i<=NF;i++) if ($i ~ /^contacts_per_disc=/) {sub(/.*=/,"",$i); print $i}}')
  echo "$rate $wall $ke $z"
}

echo "nipdem $(git -C "$HERE" rev-parse --short=12 HEAD) vs $(lmp -h | grep -m1 'Large-scale' | sed 's/.*Simulator - //'); $STEPS timed steps after 1000 warm-up, $ROUNDS rounds; $(date -u +%FT%TZ)"
echo "YIELD=${YIELD:-0} OMP_WAIT_POLICY=${OMP_WAIT_POLICY:-unset}"
echo "load before: $(cut -d' ' -f1-3 /proc/loadavg)"
printf "%-6s %-22s %-12s %-10s %-14s %-8s\n" round run disc_steps/s wall_s KE_final_J contacts
r1=(); r2=()
for r in $(seq 1 "$ROUNDS"); do
  read -r l1 lw1 lke1 lz1 < <(run_lammps 1)
  printf "%-6s %-22s %-12s %-10s %-14s %-8s\n" "$r" "lammps 1 rank" "$l1" "$lw1" "$lke1" "$lz1"
  read -r n1 nw1 nke1 nz1 < <(run_nipdem 1)
  printf "%-6s %-22s %-12s %-10s %-14s %-8s\n" "$r" "nipdem 1 thread" "$n1" "$nw1" "$nke1" "$nz1"
  read -r l2 lw2 lke2 lz2 < <(run_lammps 2)
  printf "%-6s %-22s %-12s %-10s %-14s %-8s\n" "$r" "lammps 2 ranks (mpi)" "$l2" "$lw2" "$lke2" "$lz2"
  read -r n2 nw2 nke2 nz2 < <(run_nipdem 2)
  printf "%-6s %-22s %-12s %-10s %-14s %-8s\n" "$r" "nipdem 2 threads" "$n2" "$nw2" "$nke2" "$nz2"
  a=$(awk -v a="$n1" -v b="$l1" 'BEGIN{printf "%.3f", a/b}')
  b=$(awk -v a="$n2" -v b="$l2" 'BEGIN{printf "%.3f", a/b}')
  r1+=("$a"); r2+=("$b")
  echo "round $r ratio nipdem/LAMMPS: 1 core $a, 2 cores $b"
done
median() { printf "%s\n" "$@" | sort -g | awk '{a[NR]=$1} END{print (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2}'; }
echo "MEDIAN ratio nipdem/LAMMPS: 1 core $(median "${r1[@]}"), 2 cores $(median "${r2[@]}")"
echo "load after: $(cut -d' ' -f1-3 /proc/loadavg)"
