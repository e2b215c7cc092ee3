#!/usr/bin/env bash
# Regenerates docs/sweeps/: the speed-versus-accuracy reports of the shipped scenes, each run by
# the double build and compared with a float build. Run from anywhere after the README's demo or
# test command has installed the packages:   bash docs/sweeps.sh
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
jobs="$(nproc 2>/dev/null || echo 2)"
[ -f build/CMakeCache.txt ] || cmake -S . -B build -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$jobs" --target cdlab
[ -f build-float/CMakeCache.txt ] ||
  cmake -S . -B build-float -DCMAKE_BUILD_TYPE=Release -DCDLAB_USE_FLOAT=ON
cmake --build build-float -j "$jobs" --target cdlab

sweep() {
  local name="$1"
  shift
  echo "== docs/sweeps/$name"
  build/bin/cdlab sweep "$@" --float-binary build-float/bin/cdlab --out "docs/sweeps/$name"
}
# BEGIN sweeps
sweep coursework scenes/coursework.yaml \
  --vary broadphase=brute,sphere,sap,hgrid,tree,obb --vary world.time_step=0.004167,0.008333,0.033333
sweep crowd scenes/crowd.yaml --vary broadphase=sap,sap1,grid,hash,hgrid,tree,octree,obb
# END sweeps
echo "== reports in docs/sweeps/*/report.md"
