#include "accel/bvh/bvh2_finalize.h"

#include <algorithm>

namespace raypack {

Bvh2 finalize_bvh2(std::span<const Bvh2Node> slots, std::vector<std::uint32_t> prim_index) {
    Bvh2 bvh;
    bvh.prim_index = std::move(prim_index);
    if (slots.empty()) return bvh;
    bvh.nodes.reserve(slots.size());
    // Depth-first copy with an explicit stack of (slot, parent to patch, depth).
    struct Pending {
        std::uint32_t slot;
        std::uint32_t parent;  // output node whose `first` becomes this node's index; ~0u for the root
        int depth;
    };
    std::vector<Pending> stack{{0, ~0u, 1}};
    while (!stack.empty()) {
        const Pending p = stack.back();
        stack.pop_back();
        const std::uint32_t out = std::uint32_t(bvh.nodes.size());
        if (p.parent != ~0u) bvh.nodes[p.parent].first = out;
        const Bvh2Node& node = slots[p.slot];
        bvh.nodes.push_back(node);
        bvh.depth = std::max(bvh.depth, p.depth);
        if (node.is_leaf()) {
            ++bvh.leaves;
            continue;
        }
        // The left child must come out next: push it last.
        stack.push_back({node.first, out, p.depth + 1});
        stack.push_back({p.slot + 1, ~0u, p.depth + 1});
    }
    return bvh;
}

double sah_cost(const Bvh2& bvh, float traversal_cost, float intersection_cost) {
    if (bvh.nodes.empty()) return 0;
    const double root_area = std::max(double(bvh.nodes[0].box.half_area()), 1e-30);
    double cost = 0;
    for (const Bvh2Node& n : bvh.nodes) {
        const double rel = double(n.box.half_area()) / root_area;
        cost += n.is_leaf() ? intersection_cost * double(n.count) * rel : traversal_cost * rel;
    }
    return cost;
}

}  // namespace raypack
