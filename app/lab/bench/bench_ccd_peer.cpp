// app/lab/bench/bench_ccd_peer.cpp -- Tight-Inclusion behind cdlab's CcdOutput, for `cdlab bench ccd`.
// Wang, Ferguson, Schneider, Jiang, Attene, Panozzo, "A Large-scale Benchmark and an
// Inclusion-based Algorithm for Continuous Collision Detection", ACM TOG 40(5), 2021.
#include "bench_ccd_peer.h"

#ifdef CDLAB_HAVE_TIGHT_INCLUSION
#include <tight_inclusion/ccd.hpp>
#endif

namespace app {

#ifdef CDLAB_HAVE_TIGHT_INCLUSION
namespace {

using Scalar = ticcd::Scalar;

ticcd::Vector3 toTi(const collision::Vec3& p) { return p.cast<Scalar>(); }

collision::CcdOutput fromTi(bool hit, Scalar toi) {
    collision::CcdOutput out;
    out.state = hit ? collision::CcdState::Hit : collision::CcdState::Separated;
    out.t = out.t_upper = hit ? static_cast<collision::Real>(toi) : collision::Real(1);
    return out;
}

// The arguments of Tight-Inclusion's own sample-query run (app/main.cpp there).
constexpr Scalar kMinSeparation = 0;
constexpr Scalar kTolerance = 1e-6;
constexpr Scalar kTMax = 1;
constexpr long kMaxIterations = 1'000'000;
const ticcd::Array3 kErr(-1, -1, -1);  // -1: filter computed from the query itself

}  // namespace

bool tightInclusionBuiltIn() { return true; }

collision::CcdOutput tightInclusionVertexFace(const collision::VertexFaceCcdInput& in) {
    Scalar toi = 0;
    Scalar output_tolerance = kTolerance;
    const bool hit = ticcd::vertexFaceCCD(
        toTi(in.t0[0]), toTi(in.t0[1]), toTi(in.t0[2]), toTi(in.t0[3]), toTi(in.t1[0]),
        toTi(in.t1[1]), toTi(in.t1[2]), toTi(in.t1[3]), kErr, kMinSeparation, toi, kTolerance,
        kTMax, kMaxIterations, output_tolerance);
    return fromTi(hit, toi);
}

collision::CcdOutput tightInclusionEdgeEdge(const collision::EdgeEdgeCcdInput& in) {
    Scalar toi = 0;
    Scalar output_tolerance = kTolerance;
    const bool hit = ticcd::edgeEdgeCCD(
        toTi(in.t0[0]), toTi(in.t0[1]), toTi(in.t0[2]), toTi(in.t0[3]), toTi(in.t1[0]),
        toTi(in.t1[1]), toTi(in.t1[2]), toTi(in.t1[3]), kErr, kMinSeparation, toi, kTolerance,
        kTMax, kMaxIterations, output_tolerance);
    return fromTi(hit, toi);
}

#else

bool tightInclusionBuiltIn() { return false; }

collision::CcdOutput tightInclusionVertexFace(const collision::VertexFaceCcdInput&) {
    return collision::CcdOutput{};
}

collision::CcdOutput tightInclusionEdgeEdge(const collision::EdgeEdgeCcdInput&) {
    return collision::CcdOutput{};
}

#endif

}  // namespace app
