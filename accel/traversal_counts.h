#pragma once
// What a traversal counts as it walks, as a policy of the timed walk itself
// (`count_traversal`): the timed path passes NoTraversalCounts, whose calls
// compile away, so the counts are those of the very walk that is timed.
#include <cstdint>

#include "kernels/ray.h"

namespace raypack {

/// Work of tracing rays one at a time: nodes (or grid cells) entered, inner
/// and leaf, and ray-primitive tests run. The figures papers compare
/// structures by, independent of the machine.
struct TraversalCounts {
    std::uint64_t nodes = 0;
    std::uint64_t prims = 0;
};

/// What the timed traversal counts: nothing.
struct NoTraversalCounts {
    void node() {}
    void prim() {}
    template <int M>
    void block(const std::uint32_t (&)[M]) {}
};

/// What count_traversal counts: nodes entered and primitives tested (a
/// block's padding lanes, prim = kNoPrim, are not primitives).
struct CountTraversal {
    TraversalCounts& counts;
    void node() { ++counts.nodes; }
    void prim() { ++counts.prims; }
    template <int M>
    void block(const std::uint32_t (&prim)[M]) {
        for (std::uint32_t p : prim) counts.prims += p != kNoPrim;
    }
};

}  // namespace raypack
