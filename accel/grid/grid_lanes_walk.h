#pragma once
// The per-lane packet walk of a uniform grid (each lane stepping its own
// 3D-DDA, dda_packet.h) and the packet's entry into the grid, shared by the
// grid's and the two-level grid's packet traversals. Included only by
// their .cpp files.
#include <bit>
#include <cstdint>

#include "accel/cell_kernel_variants.h"
#include "accel/grid/dda_packet.h"
#include "accel/grid/grid.h"
#include "accel/packet_intersector.h"
#include "kernels/aabb.h"
#include "kernels/ray_packet.h"

namespace raypack::grid_lanes {

// Each round: lanes standing in empty cells just step; of the lanes in
// cells with references, the first one's cell is tested for every lane that
// stands in it, and those lanes step too. A lane stops where its single-ray
// walk stops: when its current cell ends past its tfar, or at the grid's
// boundary (or, for occlusion, at its first hit). `entry`: where each lane
// starts, inside the grid's box.
template <int K, bool AnyHit, SlabMethod Slabs>
void dda_walk(const Grid& grid, const PacketRecordIntersector<vfloat<K>>& isect, RayPacket<K>& ray,
              HitPacket<K>& hit, vmask<K> active, const vfloat<K>& entry, vmask<K>& occluded) {
    using M = vmask<K>;
    GridDdaPacket<K, Slabs> dda(grid.geometry, ray, entry);
    const std::uint32_t* begin = grid.cell_begin.data();
    const std::uint32_t* refs = grid.refs.data();
    alignas(64) std::int32_t cell[K];
    for (;;) {
        dda.cells(cell);
        std::uint32_t walking = mask_bits(active), full = 0;
        for (std::uint32_t bits = walking; bits; bits &= bits - 1) {
            const int l = std::countr_zero(bits);
            if (begin[cell[l]] != begin[cell[l] + 1]) full |= 1u << l;
        }
        if (full) {
            const std::int32_t c = cell[std::countr_zero(full)];
            std::uint32_t here = 0;
            for (std::uint32_t bits = full; bits; bits &= bits - 1) {
                const int l = std::countr_zero(bits);
                if (cell[l] == c) here |= 1u << l;
            }
            walking &= ~(full & ~here);  // lanes in other full cells wait for a later round
            M testing = mask_from_bits<K>(here);
            for (std::uint32_t k = begin[c]; k < begin[c + 1]; ++k) {
                const M m = isect.intersect(testing, ray, hit, refs[k]);
                if constexpr (AnyHit) {
                    occluded = occluded | m;
                    testing = testing & !m;
                    active = active & !m;
                    if (none(testing)) break;
                }
            }
        }
        const M step = active & mask_from_bits<K>(walking);
        const typename GridDdaPacket<K, Slabs>::Crossing x = dda.crossing();
        const M beyond = step & (x.t > ray.tfar);
        active = active & !beyond;
        active = active & !dda.advance(x, step & !beyond);
        if (none(active)) return;
    }
}

/// The lanes of `valid` that meet the grid's box, and their entry distances.
template <int K, SlabMethod Slabs>
RAYPACK_INLINE vmask<K> enter_grid(const Grid& grid, const RayPacket<K>& ray, const vmask<K>& valid, vfloat<K>& entry) {
    const GridGeometry& g = grid.geometry;
    const SlabRay<vfloat<K>> slab = make_slab_ray(ray.org, ray.rdir, ray.tnear, ray.tfar);
    return intersect_box<Slabs, vfloat<K>>(valid, slab, splat<vfloat<K>>(g.bounds.lo), splat<vfloat<K>>(g.bounds.hi),
                                           entry);
}

}  // namespace raypack::grid_lanes
