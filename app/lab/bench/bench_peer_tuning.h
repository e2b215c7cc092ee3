// app/lab/bench/bench_peer_tuning.h -- `cdlab bench broadphase --peers tuned|all`: each peer's grid of
// configurations run on a table, and the fastest of each chosen as the peer.
#pragma once

#include <vector>

#include "bench_rows.h"

namespace app {

/// The peers' tuning pass: each configuration runs the measured run's frames, stopped after at
/// most this many seconds of frame time (a stopped configuration is not ranked while one ran in
/// full: its median would cover only the frames before it slowed down).
constexpr double kTuneBudgetSeconds = 10;

/// Each peer's grid, every configuration on the measured run's frames; the fastest of each
/// peer, by its own measured median, is appended to `rows` as the peer (and, when another
/// configuration is the fastest at delivering exact pairs, that one too); every configuration's
/// row goes to `sweep`.
void tunePeers(const TableRun& run, std::vector<Row>& rows, std::vector<Row>& sweep);

/// Each usable row's ratios to the fastest usable row, by each figure.
void setRatios(std::vector<Row>& rows);

}  // namespace app
