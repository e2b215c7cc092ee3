// app/lab/checkers_step.h -- the checkers of `cdlab check` that watch every step (checkers_step.cpp):
// broad-phase agreement (of extra instances, and of the broad phase in use), energy, tunnelling,
// times of impact; and the number format of all rows.
#pragma once

#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "checkers.h"

namespace app {

/// `v` with `digits` significant digits, as every row prints measured values.
inline std::string formatDouble(double v, int digits = 3) {
    std::ostringstream s;
    s.precision(digits);
    s << v;
    return s.str();
}

std::unique_ptr<Checker> makeBroadPhaseChecker(const std::vector<std::string>& names);
/// `expect.broadphases_in_use`: the world's own broad phase, whichever is in use, against its
/// reference on every state it detects.
std::unique_ptr<Checker> makeBroadPhaseInUseChecker(const std::vector<std::string>& names);
std::unique_ptr<Checker> makeEnergyChecker(const engine::Expectations& ex,
                                           const engine::World& world);
std::unique_ptr<Checker> makeTunnelChecker(const std::vector<engine::TunnelExpectation>& expect,
                                           const engine::World& world);
std::unique_ptr<Checker> makeToiChecker(const std::vector<engine::ToiExpectation>& expect);

}  // namespace app
