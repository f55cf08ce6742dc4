#include "accel/grid/grid_packet.h"

#include <algorithm>
#include <bit>
#include <limits>
#include <type_traits>

#include "accel/cell_kernel_variants.h"
#include "accel/grid/coherent_grid.h"
#include "accel/grid/coherent_grid_group.h"
#include "accel/grid/grid_lanes_walk.h"
#include "accel/outside_prims.h"
#include "accel/packet_driver.h"
#include "accel/packet_intersector.h"
#include "kernels/aabb.h"
#include "kernels/ray_packet.h"

namespace raypack {

bool grid_packets_exact(const Grid& grid) {
    for (int r : grid.geometry.res)
        if (r >= (1 << 24)) return false;
    return true;
}

template <int K, bool AnyHit>
void grid_trace_packets(const Grid& grid, const Scene& scene, KernelChoice kernels,
                        const TriangleEdgeRecord* triangle_edges, bool coherent,
                        std::span<const Rayf> rays, std::span<Hitf> hits) {
    using F = vfloat<K>;
    const PacketRecordIntersector<F> isect{&scene, kernels, triangle_edges};
    // The slab form is chosen once for all packets, rdir once per packet.
    with_slab_form(kernels.slabs, [&]<SlabMethod Slabs>(SlabTag<Slabs>) {
        // Coherent packets walk slice by slice; packets that are not, or
        // that diverge on the way, step their lanes' own DDAs.
        auto go_on_alone = [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> active, vfloat<K> entry,
                               vmask<K>& occluded) {
            if (coherent) {
                const int k = coherent_grid::major_axis<K>(ray, active);
                if (k >= 0 && coherent_grid::trace<K, AnyHit>(grid, isect, k, ray, hit, active, entry, occluded))
                    return;
            }
            grid_lanes::dda_walk<K, AnyHit, Slabs>(grid, isect, ray, hit, active, entry, occluded);
        };
        auto trace_one = [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
            intersect_outside<K, AnyHit>(grid.outside, isect, ray, hit, valid, occluded);
            if (grid.empty()) return;
            vfloat<K> entry;
            const vmask<K> active = grid_lanes::enter_grid<K, Slabs>(grid, ray, valid, entry);
            if (any(active)) go_on_alone(ray, hit, active, entry, occluded);
        };
        if (!coherent) {
            trace_in_packets<K, AnyHit>(rays, hits, kernels.rcp, trace_one);
            return;
        }
        // Rays from several points walk in smaller groups than rays from
        // one point, each group a walk sized for it (the work per slice
        // grows with G).
        constexpr int G = coherent_grid::kOnePointGroupPackets<K>;
        constexpr int kSpreadGroup = coherent_grid::kGroupRays / K;
        static_assert(G >= 2 && G <= 32 && kSpreadGroup >= 2 && kSpreadGroup <= G,
                      "a group's packets are bits of a 32-bit word");
        auto trace_group = [&]<int GG>(std::integral_constant<int, GG>, LoadedPacket<K>* p, int count) {
            coherent_grid::GroupLanes<K, GG> lanes;
            coherent_grid::enter_group<K, GG, Slabs>(grid, p, count, lanes);
            const int k = lanes.count > 1 ? coherent_grid::group_major_axis<K, GG>(lanes) : -1;
            if (k >= 0 && coherent_grid::trace_group<K, GG, AnyHit>(grid, isect, k, lanes)) return;
            for (int q = 0; q < lanes.count; ++q) {
                LoadedPacket<K>& one = *lanes.packet[q];
                if (any(lanes.active[q])) go_on_alone(one.ray, one.hit, lanes.active[q], lanes.entry[q], one.occluded);
            }
        };
        // A group led by a packet from one point (camera rays) holds G
        // packets; others kSpreadGroup (their walks split a group that does
        // not leave one point, all the same).
        trace_in_sized_groups<K, G, AnyHit>(
            rays, hits, kernels.rcp, [&](const LoadedPacket<K>& p) { return one_origin<K>(p) ? G : kSpreadGroup; },
            trace_one,
            [&](LoadedPacket<K>* p, int count) {
                if (count == 1) return trace_one(p[0].ray, p[0].hit, p[0].valid, p[0].occluded);
                for (int q = 0; q < count; ++q)
                    intersect_outside<K, AnyHit>(grid.outside, isect, p[q].ray, p[q].hit, p[q].valid, p[q].occluded);
                if (grid.empty()) return;
                if (coherent_grid::from_one_point<K>(p, count)) {
                    trace_group(std::integral_constant<int, G>{}, p, count);
                } else {
                    for (int q = 0; q < count; q += kSpreadGroup)
                        trace_group(std::integral_constant<int, kSpreadGroup>{}, p + q,
                                    std::min(kSpreadGroup, count - q));
                }
            });
    });
}

#if defined(__SSE4_2__)
template void grid_trace_packets<4, false>(const Grid&, const Scene&, KernelChoice, const TriangleEdgeRecord*,
                                           bool, std::span<const Rayf>, std::span<Hitf>);
template void grid_trace_packets<4, true>(const Grid&, const Scene&, KernelChoice, const TriangleEdgeRecord*,
                                          bool, std::span<const Rayf>, std::span<Hitf>);
#endif
#if defined(__AVX2__)
template void grid_trace_packets<8, false>(const Grid&, const Scene&, KernelChoice, const TriangleEdgeRecord*,
                                           bool, std::span<const Rayf>, std::span<Hitf>);
template void grid_trace_packets<8, true>(const Grid&, const Scene&, KernelChoice, const TriangleEdgeRecord*,
                                          bool, std::span<const Rayf>, std::span<Hitf>);
#endif
#if defined(__AVX512BW__)
template void grid_trace_packets<16, false>(const Grid&, const Scene&, KernelChoice, const TriangleEdgeRecord*,
                                            bool, std::span<const Rayf>, std::span<Hitf>);
template void grid_trace_packets<16, true>(const Grid&, const Scene&, KernelChoice, const TriangleEdgeRecord*,
                                           bool, std::span<const Rayf>, std::span<Hitf>);
#endif

}  // namespace raypack
