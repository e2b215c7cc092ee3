// app/query_command.cpp -- `cdlab query`'s flags (the query itself: lab/query.h).
#include <CLI/CLI.hpp>
#include <iostream>
#include <memory>

#include "command.h"
#include "query.h"

namespace app {

Command addQueryCommand(CLI::App& cli) {
    auto query = std::make_shared<QueryOptions>();
    CLI::App* cmd = cli.add_subcommand(
        "query",
        "mesh against mesh through every BVH volume type: answer, triangle pairs, "
        "BV and triangle tests, build and query time side by side");
    cmd->add_option("mesh_a", query->mesh_a, "mesh A (any format assimp reads)")->required();
    cmd->add_option("mesh_b", query->mesh_b, "mesh B (omitted with --self)");
    cmd->add_option("--bv", query->bv, "volume type or all")->capture_default_str();
    cmd->add_option("--pose-b", query->pose_b,
                    "B's pose in A's frame: x,y,z,qw,qx,qy,qz (default identity)");
    cmd->add_flag("--json", query->json, "machine-readable output");
    cmd->add_option("--unit-cost-tests", query->unit_cost_tests,
                    "volume tests and refitted nodes each unit cost is timed over (triangle "
                    "tests: half as many); fewer measure faster and less precisely")
        ->check(CLI::Range(std::int64_t{2}, std::int64_t{1000000000}))
        ->capture_default_str();
    cmd->add_flag("--self", query->self,
                  "self-collision of mesh A: its intersecting non-adjacent triangle pairs "
                  "through each tree against itself and the brute-force loop (exit 1 if they "
                  "differ)");
    return {cmd, [query](RunMode mode) {
                query->dry_run = mode == RunMode::DryRun;
                return runQuery(*query, std::cout, std::cerr);
            }};
}

}  // namespace app
