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
# Broad phases and time step on the coursework scene (reference: the same scene at dt / 10).
sweep coursework scenes/coursework.yaml \
  --vary broadphase=brute,sphere,sap,hgrid,tree,obb --vary world.time_step=0.004167,0.008333,0.033333
# Mesh hierarchies: the node volume of the mesh bodies' BVHs (Nv, Np and time per step).
sweep coursework_mesh_bvh scenes/coursework.yaml \
  --vary world.mesh_bvh=sphere,aabb,obb,obb4,kdop6,kdop14,kdop18,kdop26,rss,lss
sweep crowd scenes/crowd.yaml --vary broadphase=sap,sap1,grid,hash,hgrid,tree,octree,obb
# CCD against the time step: missed contacts and time-of-impact error against an exact-CCD
# reference.
sweep tunnel_sphere scenes/tunnel_sphere.yaml --reference world.ccd=conservative_advancement \
  --vary world.ccd=off,conservative_advancement --vary world.time_step=0.033333,0.004167,0.000521
sweep tunnel_bar scenes/tunnel_bar.yaml --reference world.ccd=conservative_advancement \
  --vary world.ccd=off,conservative_advancement --vary world.time_step=0.033333,0.004167,0.000521
# CCD tolerance (world.ccd_tolerance): time-of-impact error against a 1e-6 reference at dt / 10.
sweep tunnel_bar_ccd_tolerance scenes/tunnel_bar_ccd.yaml --reference world.ccd_tolerance=1e-6 \
  --vary world.ccd_tolerance=1e-6,1e-4,1e-3,1e-2,1e-1
# Integrators and time step with contact response: energy drift and contacts.
sweep bounce scenes/bounce.yaml \
  --vary world.integrator=explicit_euler,semi_implicit_euler,rk4 \
  --vary world.time_step=0.016667,0.008333,0.002083
sweep stack scenes/stack.yaml --vary world.time_step=0.033333,0.016667,0.004167
echo "== reports in docs/sweeps/*/report.md"
