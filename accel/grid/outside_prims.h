#pragma once
// The primitives a grid keeps out of its cells (Grid::outside,
// GridConfig::large_primitives_outside), tested by every ray before the
// walk: their hits shorten it. Shared by the uniform and the two-level
// grid, single rays and packets.
#include <cstdint>

#include "accel/grid/grid.h"
#include "accel/packet_intersector.h"
#include "accel/primitive_intersector.h"
#include "kernels/ray_packet.h"

namespace raypack {

/// One ray; true if any hit. AnyHit stops at the first. `tests` counts them.
template <bool AnyHit>
RAYPACK_INLINE bool intersect_outside(const Grid& grid, const PrimitiveIntersector<float>& isect, Rayf& ray, Hitf& hit,
                                      std::uint64_t* tests) {
    bool found = false;
    for (const std::uint32_t prim : grid.outside) {
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
template <int K, bool AnyHit>
RAYPACK_INLINE void intersect_outside(const Grid& grid, const PacketRecordIntersector<vfloat<K>>& isect,
                                      RayPacket<K>& ray, HitPacket<K>& hit, vmask<K>& valid, vmask<K>& occluded) {
    for (const std::uint32_t prim : grid.outside) {
        const vmask<K> m = isect.intersect(valid, ray, hit, prim);
        if constexpr (AnyHit) {
            occluded = occluded | m;
            valid = valid & !m;
        }
    }
}

}  // namespace raypack
