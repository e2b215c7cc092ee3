// app/lab/bench/bench_broadphase_rounds.h -- `cdlab bench broadphase --rounds R`: a table's rows run
// again, interleaved, and each figure becomes the median over the rounds.
#pragma once

#include <vector>

#include "bench_rows.h"

namespace app {

/// Rounds 2..R of one table (round 1 is the pass that made `rows`): every usable row runs again
/// with its method, in reverse order on even rounds. A row that fails or disagrees with the
/// reference in any round keeps that round's result and so drops out of the ratios. Each row
/// that stays usable gets its per-round results in `rounds` and, as its figures, their medians
/// (peak memory: the largest; frames: the fewest; a budget stop in any round shows).
/// With --interleave, instead: rounds 1..R all measured together (measureTogether), and the
/// first pass that made `rows` gives no figure.
void runRounds(const TableRun& run, std::vector<Row>& rows);

/// Each row's ratio to the best usable peer of the same round, under each rule (rows without
/// rounds are left alone).
void setRoundRatios(std::vector<Row>& rows);

}  // namespace app
