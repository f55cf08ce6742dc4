#pragma once
// The finalisation all BVH builders share: flatten the nodes a builder wrote
// into the depth-first Bvh2 layout, count leaves and depth, and the SAH cost
// every builder reports.
#include <span>
#include <vector>

#include "accel/bvh/bvh2.h"

namespace raypack {

/// `slots` holds the nodes as a builder wrote them: the root in slot 0, an
/// inner node's left child in the next slot and its right child's slot in
/// `first`; slots no node points to are ignored (a builder that reserves
/// room per subtree leaves holes). Returns the tree packed depth first.
Bvh2 finalize_bvh2(std::span<const Bvh2Node> slots, std::vector<std::uint32_t> prim_index);

/// SAH cost of a built tree, relative to one primitive test at the root.
double sah_cost(const Bvh2& bvh, float traversal_cost, float intersection_cost);

}  // namespace raypack
