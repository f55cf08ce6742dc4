#pragma once
// raypack bench --tradeoff: for every variant of the triangle test, the
// sphere test, the secondary-ray offset, the slab test, the reciprocal, the
// precision of the primitive tests and the BVH builder, its throughput and
// the errors it causes (docs/accuracy.md).
#include <string>

namespace raypack::app {

struct TradeoffPlan {
    bool quick = false;  ///< small inputs: every family in well under two minutes
    int repeat = 9;      ///< timed passes per throughput figure (median reported), one thread
    std::string json, csv;
};

/// Runs every family, prints the table, writes JSON/CSV if asked; exit status.
int run_tradeoff(const TradeoffPlan& plan);

}  // namespace raypack::app
