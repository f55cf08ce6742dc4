// Bvh2Accel::count_traversal: the single-ray traversal of bvh2_accel.cpp
// step for step (nearer child first, the same pops and culls), counting the
// nodes it enters and the primitives it tests. Kept apart so the timed path
// carries no counters.
#include "accel/bvh/bvh2_accel.h"

namespace raypack {
namespace {

struct Bvh2CountingWalk {
    const Bvh2& bvh;
    const PrimitiveIntersector<float>& isect;
    TraversalCounts& counts;

    bool trace(bool any_hit, Rayf& ray, Hitf& hit) const {
        if (bvh.nodes.empty()) return false;
        const Vec3f inv_dir = reciprocal(ray.dir);
        const Bvh2Node* nodes = bvh.nodes.data();
        auto enters = [&](std::uint32_t node, float& t) {
            return intersect_aabb(ray.org, inv_dir, nodes[node].box, ray.tnear, ray.tfar, t);
        };
        float entry;
        if (!enters(0, entry)) return false;
        std::uint32_t stack[kBvhMaxDepth + 1];
        int sp = 0;
        std::uint32_t current = 0;
        bool found = false;
        for (;;) {
            ++counts.nodes;
            const Bvh2Node& node = nodes[current];
            if (node.is_leaf()) {
                for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
                    ++counts.prims;
                    found |= isect.intersect(bvh.prim_index[k], ray, hit);
                    if (any_hit && found) return true;
                }
            } else {
                const std::uint32_t left = current + 1, right = node.first;
                float t_left, t_right;
                const bool hit_left = enters(left, t_left), hit_right = enters(right, t_right);
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
            do {
                if (sp == 0) return found;
                current = stack[--sp];
            } while (!enters(current, entry));
        }
    }
};

}  // namespace

bool Bvh2Accel::count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                                TraversalCounts& counts) const {
    const PrimitiveIntersector<float> isect{scene_, kernels_};
    const Bvh2CountingWalk walk{bvh_, isect, counts};
    for (std::size_t i = 0; i < rays.size(); ++i) {
        Rayf ray = rays[i];
        Hitf hit;
        hits[i] = walk.trace(any_hit, ray, hit) ? hit : Hitf{};
    }
    return true;
}

}  // namespace raypack
