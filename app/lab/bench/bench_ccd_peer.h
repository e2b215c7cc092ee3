// app/lab/bench/bench_ccd_peer.h -- Tight-Inclusion (Wang et al. 2021) as a peer method of
// `cdlab bench ccd`, compiled in only when CMake found an installed copy
// (CDLAB_HAVE_TIGHT_INCLUSION); its headers stay inside bench_ccd_peer.cpp.
#pragma once

#include "collision/ccd/ccd.h"

namespace app {

/// What to set at configure time to compare with Tight-Inclusion (for messages).
inline constexpr const char* kTightInclusionHint =
    "configure with -DCDLAB_TIGHT_INCLUSION_ROOT=PREFIX (its include/tight_inclusion/ccd.hpp and "
    "lib/libtight_inclusion.a) or -Dtight_inclusion_DIR=DIR (its CMake package)";

/// True when this build links Tight-Inclusion.
bool tightInclusionBuiltIn();

/// Tight-Inclusion's vertex-face / edge-edge CCD, called as its sample-query app calls it:
/// minimum separation 0, tolerance 1e-6, t_max 1, at most 10^6 iterations, per-query error
/// filter (err = -1), breadth-first. Hit with t = its time of impact, else Separated. Without
/// the library: Failed.
collision::CcdOutput tightInclusionVertexFace(const collision::VertexFaceCcdInput& input);
collision::CcdOutput tightInclusionEdgeEdge(const collision::EdgeEdgeCcdInput& input);

}  // namespace app
