#pragma once
// What a traversal counts as it walks, as a policy of the timed walk itself
// (`count_traversal`): the timed path passes NoTraversalCounts, whose calls
// compile away, so the counts are those of the very walk that is timed.
#include <cstdint>

#include "kernels/ray.h"

namespace raypack {

/// Work of tracing rays one at a time, as Havran and Sixta count it for the
/// SPD scenes (1999; docs/structures.md): traversal steps (nodes or grid
/// cells entered, inner and leaf: N_TS), elementary cells (leaves or grid
/// cells) entered (N_ETS), the empty ones among them (N_EETS), and
/// ray-primitive tests run (N_IT). Independent of the machine.
struct TraversalCounts {
    std::uint64_t nodes = 0;         ///< N_TS
    std::uint64_t prims = 0;         ///< N_IT
    std::uint64_t leaves = 0;        ///< N_ETS
    std::uint64_t empty_leaves = 0;  ///< N_EETS
};

/// What the timed traversal counts: nothing.
struct NoTraversalCounts {
    void node() {}
    void leaf() {}
    void prim() {}
    template <int M>
    void block(const std::uint32_t (&)[M]) {}
};

/// What count_traversal counts: nodes entered, leaves among them, and
/// primitives tested (a block's padding lanes, prim = kNoPrim, are not
/// primitives). A BVH has no empty leaves.
struct CountTraversal {
    TraversalCounts& counts;
    void node() { ++counts.nodes; }
    void leaf() { ++counts.leaves; }
    void prim() { ++counts.prims; }
    template <int M>
    void block(const std::uint32_t (&prim)[M]) {
        for (std::uint32_t p : prim) counts.prims += p != kNoPrim;
    }
};

}  // namespace raypack
