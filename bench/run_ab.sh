#!/usr/bin/env bash
# Alternated A/B timing of one benchmark program built twice (a baseline beside the new one):
# runs A, B, A, B, ... ROUNDS times with the same arguments so that load from other jobs on
# the shared machine hits both alike, and prints each round's value of KEY (a key=value field
# of the programs' RESULT line) and the ratio B/A per round with their median.
#   bench/run_ab.sh A_BINARY B_BINARY ROUNDS KEY -- ARGS...
# e.g. bench/run_ab.sh /work/base/build/bench/bench_nip build/bench/bench_nip 3 disc_steps_per_s_magnet \
#        -- --dense-file /tmp/dense.bin --half-width 2.6e-3 --steps 2000 --threads 1
set -euo pipefail
[ $# -ge 5 ] && [ "$5" = "--" ] || { echo "usage: $0 A B ROUNDS KEY -- ARGS..." >&2; exit 2; }
A=$1 B=$2 ROUNDS=$3 KEY=$4
shift 5
# KEY = cpu_magnet / cpu_nomagnet (bench_nip): disc-steps per CPU second of that run, from its
# discs=, cpu= and the header's steps= (robust on a loaded machine for 1 thread); KEY = cpu_rate:
# the same from a RESULT line's disc_steps_per_s, wall_s and cpu_s (bench_lammps_packing).
value() {
  case "$KEY" in
    cpu_magnet|cpu_nomagnet)
      local tag; [ "$KEY" = cpu_magnet ] && tag="knife \\+ dipole-dipole:" || tag="magnet.field=none:"
      "$@" | awk -v tag="$tag" '
        /^bench_nip/ {for (i=1;i<=NF;i++) if ($i ~ /^steps=/) {sub(/.*=/,"",$i); steps=$i}}
        $0 ~ tag && !done {for (i=1;i<=NF;i++) {if ($i ~ /^discs=/) {d=$i; sub(/.*=/,"",d)} if ($i ~ /^cpu=/) {c=$i; sub(/.*=/,"",c)}}
                           printf "%.4g\n", d*steps/c; done=1}' ;;
    cpu_rate)  # any RESULT line with disc_steps_per_s, wall_s and cpu_s (bench_lammps_packing)
      "$@" | awk '/^RESULT/ {for (i=1;i<=NF;i++) {split($i, kv, "="); v[kv[1]]=kv[2]} printf "%.4g\n", v["disc_steps_per_s"]*v["wall_s"]/v["cpu_s"]}' ;;
    *) "$@" | awk -v k="$KEY" '/^RESULT/ {for (i=1;i<=NF;i++) if (index($i, k"=")==1) {sub(/.*=/,"",$i); print $i}}' ;;
  esac
}
echo "A=$A"; echo "B=$B"; echo "args: $*"; echo "key: $KEY; $(date -u +%FT%TZ); load $(cut -d' ' -f1-3 /proc/loadavg)"
ratios=()
for r in $(seq 1 "$ROUNDS"); do
  a=$(value "$A" "$@"); b=$(value "$B" "$@")
  q=$(awk -v a="$a" -v b="$b" 'BEGIN{printf "%.3f", b/a}')
  ratios+=("$q")
  echo "round $r: A $a  B $b  B/A $q  (load $(cut -d' ' -f1 /proc/loadavg))"
done
printf "%s\n" "${ratios[@]}" | sort -g | awk '{a[NR]=$1} END{printf "MEDIAN B/A %s over %d rounds\n", (NR%2) ? a[(NR+1)/2] : (a[NR/2]+a[NR/2+1])/2, NR}'
