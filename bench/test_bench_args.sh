#!/usr/bin/env bash
# Hostile arguments to the benchmark programs: each must exit 2 naming the option, never abort.
#   test_bench_args.sh BENCH_DIR
set -u
dir=$1
fail=0
check() {  # check OPTION CMD...: exit status 2 and the option named on stderr
  local opt=$1; shift
  "$@" >/dev/null 2>/tmp/bench_args_err.$$
  local rc=$?
  if [ $rc -ne 2 ] || ! grep -q -- "$opt" /tmp/bench_args_err.$$; then
    echo "FAIL: $* -> exit $rc: $(head -c 300 /tmp/bench_args_err.$$)"
    fail=1
  fi
}
check --run-threads "$dir/bench_nip" --run-threads abc
check --steps "$dir/bench_nip" --steps 12x
check --run-threads "$dir/bench_nip" --threads 1 --run-threads 2
check --dipole-skin "$dir/bench_nip" --dipole-skin 1e999
check --repeat "$dir/bench_nip" --repeat 0
check --steps "$dir/bench_nip" --steps -5
check --sort-cell "$dir/bench_nip" --sort-cell -1
check --sort-cell "$dir/bench_nip" --sort-cell nan
check --inner-skin "$dir/bench_nip" --inner-skin nan
check --inner-skin "$dir/bench_nip" --inner-skin 2
check --steps "$dir/bench_lammps_packing" --steps abc
check --tilt-deg "$dir/bench_lammps_packing" --tilt-deg nanx
check --steps "$dir/bench_print" --steps -
check --discs "$dir/bench_neighbor" --discs 1.5
rm -f /tmp/bench_args_err.$$
[ $fail = 0 ] && echo "all hostile benchmark arguments refused with exit 2"
exit $fail
