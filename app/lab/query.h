// app/lab/query.h -- `cdlab query`: two meshes, B at a pose in A's frame, every BVH volume
// type side by side (answer, triangle pairs, BV and triangle tests, build and query time).
#pragma once

#include <cstdint>
#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <string_view>

#include "collision/math.h"

namespace app {

struct QueryOptions {
    std::filesystem::path mesh_a;
    std::filesystem::path mesh_b;
    std::string bv = "all";  ///< a BVH volume name (collision::bvhVolumeNames()) or "all"
    std::string pose_b;      ///< "x,y,z,qw,qx,qy,qz" (B's frame in A's); empty: identity
    bool json = false;       ///< machine-readable output on `out`
    bool self = false;       ///< self-collision of mesh_a alone (mesh_b must be empty)
    /// Volume tests and refitted nodes each unit cost (Cv, Cu) is timed over, triangle tests (Cp)
    /// half as many: the measurement's size, not the answer's (bvh_unit_costs.h).
    std::int64_t unit_cost_tests = 200000;
    /// Check the flags (--bv, --pose-b, --self) and import the meshes, then return 0 before any
    /// tree is built or query run (`cdlab --dry-run query ...`).
    bool dry_run = false;
};

/// Parses "x,y,z,qw,qx,qy,qz" into a pose (quaternion normalised). Returns nothing and sets
/// `error` for a wrong count, a non-number, a non-finite value or a zero quaternion.
std::optional<collision::Pose> parsePose(std::string_view text, std::string* error);

/// Exit codes: 0 success, 1 the volume types disagree on the pair list (a bug: reported),
/// 2 bad input (flag, unreadable or empty mesh). With `self`: the non-adjacent intersecting
/// triangle pairs of mesh_a through every requested tree against itself and through the
/// brute-force loop; exit 1 when a tree's pairs differ from the brute force's.
int runQuery(const QueryOptions& options, std::ostream& out, std::ostream& err);

}  // namespace app
