#!/usr/bin/env bash
# Restarts the study lanes after a stop (each stop ends them; every step resumes where it was):
# one lane per core at nice 19, each on the binary its studies started with.
#   lanes.sh [LANE ...]          default: black color
# The binary is BIN (default /work/study-bin/nipdem); if it is missing it is built from commit
# STUDY_COMMIT (default e06c2a3, the binary of the steps so far: walltimes.txt) in a worktree, so a
# resumed step keeps its binary (docs/results/README.md: later builds differ in the last bits).
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)
repo=$(git -C "$here" rev-parse --show-toplevel)
bin=${BIN:-/work/study-bin/nipdem}
commit=${STUDY_COMMIT:-e06c2a3}
if [[ ! -x $bin ]]; then
  src=$(mktemp -d)/src
  git -C "$repo" worktree add --detach "$src" "$commit" >/dev/null
  cmake -S "$src" -B "$src/build" -DCMAKE_BUILD_TYPE=Release -DNIPDEM_BUILD_TESTS=OFF >/dev/null
  cmake --build "$src/build" -j"$(nproc)" --target nipdem_cli >/dev/null
  mkdir -p "$(dirname "$bin")"
  cp "$src/build/nipdem" "$bin"
  git -C "$repo" worktree remove --force "$src"
fi
# JOBS=N gives each started lane N cores (run.sh)
lanes=("$@")
(( ${#lanes[@]} )) || lanes=(black color)
for lane in "${lanes[@]}"; do
  if pgrep -f "run.sh $lane " >/dev/null; then echo "lane $lane is running already"; continue; fi
  (cd "$here" && nohup nice -n 19 ./run.sh "$lane" "$bin" >/dev/null 2>&1 &)
  echo "lane $lane started on $("$bin" version | head -1)"
done
