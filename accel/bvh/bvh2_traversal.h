#pragma once
// One ray through a BVH2 from any node down: the reference single-ray
// traversal (Bvh2Accel from the root), and the lane-by-lane finish of a
// packet whose rays have drifted apart (bvh2_packet.cpp).
#include <cstdint>

#include "accel/accel.h"
#include "accel/bvh/bvh2.h"
#include "accel/primitive_intersector.h"
#include "kernels/aabb.h"

namespace raypack {

/// What the timed traversal counts: nothing (the calls compile away).
struct NoTraversalCounts {
    void node() {}
    void prim() {}
};

/// What count_traversal counts: nodes entered and primitives tested.
struct CountTraversal {
    TraversalCounts& counts;
    void node() { ++counts.nodes; }
    void prim() { ++counts.prims; }
};

/// Closest hit (or, AnyHit, any hit) of `ray` among the primitives below
/// `root`; shrinks ray.tfar to each hit. Returns whether it found one.
/// Depth-first, nearer child first, with an explicit stack. `count` sees
/// each node entered and each primitive tested.
template <bool AnyHit, class Count = NoTraversalCounts>
inline bool trace_bvh2_subtree(const Bvh2& bvh, const PrimitiveIntersector<float>& isect, std::uint32_t root,
                               Rayf& ray, Hitf& hit, Count count = {}) {
    const Vec3f inv_dir = reciprocal(ray.dir);
    const Bvh2Node* nodes = bvh.nodes.data();
    float entry;
    if (!intersect_aabb(ray.org, inv_dir, nodes[root].box, ray.tnear, ray.tfar, entry)) return false;
    std::uint32_t stack[kBvhMaxDepth + 1];
    int sp = 0;
    std::uint32_t current = root;
    bool found = false;
    for (;;) {
        count.node();
        const Bvh2Node& node = nodes[current];
        if (node.is_leaf()) {
            for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
                count.prim();
                if (isect.intersect(bvh.prim_index[k], ray, hit)) {
                    found = true;
                    if constexpr (AnyHit) return true;
                }
            }
        } else {
            const std::uint32_t left = current + 1, right = node.first;
            float t_left, t_right;
            const bool hit_left = intersect_aabb(ray.org, inv_dir, nodes[left].box, ray.tnear, ray.tfar, t_left);
            const bool hit_right = intersect_aabb(ray.org, inv_dir, nodes[right].box, ray.tnear, ray.tfar, t_right);
            if (hit_left && hit_right) {
                const bool left_first = t_left <= t_right;
                stack[sp++] = left_first ? right : left;
                current = left_first ? left : right;
                continue;
            }
            if (hit_left || hit_right) {
                current = hit_left ? left : right;
                continue;
            }
        }
        // Pop, skipping nodes the ray can no longer reach before its closest hit.
        for (;;) {
            if (sp == 0) return found;
            current = stack[--sp];
            if (intersect_aabb(ray.org, inv_dir, nodes[current].box, ray.tnear, ray.tfar, entry)) break;
        }
    }
}

}  // namespace raypack
