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

/// One ray against one box by the slab test `--slabs` names: Robust (Ize
/// 2013, never culls a box the exact ray meets) or Plain (one FMA per plane,
/// lo * rdir - org * rdir: faster, may lose hits on adversarial rays).
template <SlabMethod Slabs>
RAYPACK_INLINE bool bvh2_box(const Rayf& ray, const Vec3f& inv_dir, const Vec3f& org_rdir, const Box3f& box,
                             float& entry) {
    if constexpr (Slabs == SlabMethod::Robust) {
        return intersect_aabb(ray.org, inv_dir, box, ray.tnear, ray.tfar, entry);
    } else {
        const SlabRay<float> slab{ray.org, inv_dir, org_rdir, ray.tnear, ray.tfar};
        return intersect_box<SlabMethod::Plain, float>(true, slab, box.lo, box.hi, entry);
    }
}

/// Closest hit (or, AnyHit, any hit) of `ray` among the primitives below
/// `root`; shrinks ray.tfar to each hit. Returns whether it found one.
/// Depth-first, nearer child first, with an explicit stack. `count` sees
/// each node entered and each primitive tested. The reciprocal direction is
/// computed here, by isect.kernels.rcp, as load_packet computes it, so a
/// packet lane finishing alone (bvh2_packet.cpp) keeps its bits.
template <bool AnyHit, SlabMethod Slabs = SlabMethod::Robust, class Count = NoTraversalCounts>
inline bool trace_bvh2_subtree(const Bvh2& bvh, const PrimitiveIntersector<float>& isect, std::uint32_t root,
                               Rayf& ray, Hitf& hit, Count count = {}) {
    const Vec3f inv_dir = reciprocal(ray.dir, isect.kernels.rcp);
    Vec3f org_rdir{};
    if constexpr (Slabs == SlabMethod::Plain)
        org_rdir = {ray.org.x * inv_dir.x, ray.org.y * inv_dir.y, ray.org.z * inv_dir.z};
    const Bvh2Node* nodes = bvh.nodes.data();
    auto box = [&](std::uint32_t n, float& entry) {
        return bvh2_box<Slabs>(ray, inv_dir, org_rdir, nodes[n].box, entry);
    };
    float entry;
    if (!box(root, entry)) return false;
    std::uint32_t stack[kBvhMaxDepth + 1];
    int sp = 0;
    std::uint32_t current = root;
    bool found = false;
    for (;;) {
        count.node();
        const Bvh2Node& node = nodes[current];
        if (node.is_leaf()) {
            count.leaf();
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
            const bool hit_left = box(left, t_left);
            const bool hit_right = box(right, t_right);
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
            if (box(current, entry)) break;
        }
    }
}

}  // namespace raypack
