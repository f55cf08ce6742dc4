#pragma once
// A few primitives far larger than the rest (a ground polygon under a small
// object: SPD balls and tree) make a spatial subdivision spend its cells or
// levels on empty space around the rest. The grids, the octree and the k-d
// tree keep them out of the structure and test them for every ray before
// the walk, whose hits then shorten it, as ray tracers have long kept
// unbounded or very large objects out of their bounding hierarchies
// (POV-Ray's infinite objects; Rayshade's unbounded list).
#include <cstdint>
#include <span>
#include <vector>

#include "accel/packet_intersector.h"
#include "accel/primitive_intersector.h"
#include "kernels/aabb.h"
#include "kernels/ray_packet.h"

namespace raypack {

/// The primitives to keep outside (at most kMaxOutside): the
/// smallest number m of the largest boxes (by surface area) whose removal
/// shrinks the box of the others to within 4/5 of the most that removing up
/// to kMaxOutside of them could, if that shrinks the box's area at least
/// kMinShrink-fold; none otherwise, or for fewer than kMinPrimitives
/// primitives. Unusable boxes (non-finite, empty) never count.
inline constexpr std::size_t kMaxOutside = 8;
inline constexpr float kMinShrink = 4.0f;
inline constexpr std::size_t kMinPrimitives = 32;
std::vector<std::uint32_t> large_primitives(std::span<const Box3f> boxes);

/// Empties the boxes of large_primitives(boxes), so that a builder leaves
/// them out, and returns them.
std::vector<std::uint32_t> take_large_primitives(std::span<Box3f> boxes);

/// One ray against the primitives `outside`; true if any hit. AnyHit stops
/// at the first. `tests` counts them.
template <bool AnyHit>
RAYPACK_INLINE bool intersect_outside(std::span<const std::uint32_t> outside, const PrimitiveIntersector<float>& isect,
                                      Rayf& ray, Hitf& hit, std::uint64_t* tests) {
    bool found = false;
    for (const std::uint32_t prim : outside) {
        if (tests) ++*tests;
        if (isect.intersect(prim, ray, hit)) {
            found = true;
            if constexpr (AnyHit) return true;
        }
    }
    return found;
}

/// A packet's `valid` lanes; for any hit, the lanes that hit move from
/// `valid` to `occluded`.
template <int K, bool AnyHit, class Intersector>
RAYPACK_INLINE void intersect_outside(std::span<const std::uint32_t> outside, const Intersector& isect,
                                      RayPacket<K>& ray, HitPacket<K>& hit, vmask<K>& valid, vmask<K>& occluded) {
    for (const std::uint32_t prim : outside) {
        const vmask<K> m = isect.intersect(valid, ray, hit, prim);
        if constexpr (AnyHit) {
            occluded = occluded | m;
            valid = valid & !m;
        }
    }
}

}  // namespace raypack
