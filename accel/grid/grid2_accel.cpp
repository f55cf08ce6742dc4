#include "accel/grid/grid2_accel.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <vector>

#include "accel/cell_accel_impl.h"
#include "accel/cell_kernel_variants.h"
#include "accel/grid/coherent_grid.h"
#include "accel/grid/coherent_grid_group.h"
#include "accel/grid/dda.h"
#include "accel/grid/grid_lanes_walk.h"
#include "accel/grid/grid_packet.h"
#include "accel/outside_prims.h"
#include "accel/packet_driver.h"
#include "accel/packet_widths.h"

namespace raypack {

Grid2Accel::Grid2Accel(const Scene& scene, const AccelConfig& config, const TwoLevelGridConfig& grid_config)
    : scene_(&scene), kernels_(config.kernels) {
    const std::size_t n = scene.primitive_count();
    std::vector<Box3f> boxes(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { boxes[i] = primitive_bounds(scene, std::uint32_t(i)); });
    std::vector<std::uint32_t> outside = take_large_primitives(boxes);
    grid_ = build_two_level_grid(boxes, PrimitiveBoxOverlap{&scene}, grid_config);
    grid_.top.outside = std::move(outside);
    packets_exact_ = grid_packets_exact(grid_.top) &&
                     std::all_of(grid_.cells.begin(), grid_.cells.end(), [](const Grid& g) { return grid_packets_exact(g); });
    std::size_t references = 0, empty = 0, cells = 0;
    for (const Grid& g : grid_.cells) {
        references += g.refs.size();
        cells += g.geometry.cells();
        for (std::size_t c = 0; c < g.geometry.cells(); ++c) empty += g.cell_begin[c] == g.cell_begin[c + 1];
    }
    const std::size_t top_empty = grid_.top.geometry.cells() - grid_.cells.size();
    stats_.name = "grid2";
    stats_.builder = "two-level";
    stats_.nodes = grid_.top.geometry.cells() + cells;
    stats_.leaves = cells - empty;
    stats_.empty_leaves = empty + top_empty;
    make_triangle_edges(scene, kernels_);
    stats_.bytes = grid_.bytes() + triangle_edge_bytes();
    stats_.depth = 2;
    stats_.refs_per_prim = n ? double(references) / double(n) : 0.0;
}

namespace {

/// Per-ray mailbox, direct-mapped on the primitive number: a primitive
/// spanning top cells is in several cells' grids.
struct Mailbox {
    static constexpr std::uint32_t kSize = 16;
    std::uint32_t slot[kSize];
    Mailbox() { std::fill(slot, slot + kSize, kNoPrim); }
    /// True if prim was already tested; records it otherwise.
    bool seen(std::uint32_t prim) {
        std::uint32_t& s = slot[prim & (kSize - 1)];
        if (s == prim) return true;
        s = prim;
        return false;
    }
};

}  // namespace

// The top grid's cells front to back (as GridAccel::trace); in each
// non-empty one, its grid's cells over the part of the ray inside the cell,
// testing every primitive there (once per ray, by the mailbox). A hit ends
// the walk once the current top cell ends past it: every later cell, at
// either level, lies beyond.
template <bool AnyHit, bool Counting, SlabMethod Slabs>
bool Grid2Accel::walk(Rayf& ray, Hitf& hit, GridRayCounters* counters) const {
    if constexpr (Counting) ++counters->rays;
    const PrimitiveIntersector<float> isect{scene_, kernels_, triangle_edges()};
    const Grid& top = grid_.top;
    bool found = intersect_outside<AnyHit>(top.outside, isect, ray, hit, Counting ? &counters->prim_tests : nullptr);
    if (AnyHit && found) return true;
    if (grid_.empty()) return found;
    const Vec3f inv_dir = ray_reciprocal(ray.dir, kernels_.rcp);
    float entry;
    const SlabRay<float> slab = make_slab_ray(ray.org, inv_dir, ray.tnear, ray.tfar);
    if (!intersect_box<Slabs, float>(true, slab, top.geometry.bounds.lo, top.geometry.bounds.hi, entry)) return found;
    Mailbox mailbox;
    GridDda top_dda(top.geometry, ray.org, ray.dir, inv_dir, entry, SlabTag<Slabs>{});
    while (const std::optional<DdaSegment> cell = top_dda.next()) {
        const std::uint32_t index = grid_.cell_grid[cell->cell];
        if constexpr (Counting) {
            ++counters->cells_visited;
            counters->empty_cells_visited += index == TwoLevelGrid::kNoGrid;
        }
        if (index != TwoLevelGrid::kNoGrid) {
            const Grid& sub = grid_.cells[index];
            // The ray's stretch in this top cell, clipped to the cell's grid.
            float sub_entry;
            const SlabRay<float> part =
                make_slab_ray(ray.org, inv_dir, std::max(cell->t_enter, ray.tnear), std::min(cell->t_exit, ray.tfar));
            if (!sub.empty() &&
                intersect_box<Slabs, float>(true, part, sub.geometry.bounds.lo, sub.geometry.bounds.hi, sub_entry)) {
                GridDda dda(sub.geometry, ray.org, ray.dir, inv_dir, sub_entry, SlabTag<Slabs>{});
                while (const std::optional<DdaSegment> seg = dda.next()) {
                    const std::uint32_t first = sub.cell_begin[seg->cell], last = sub.cell_begin[seg->cell + 1];
                    if constexpr (Counting) {
                        ++counters->cells_visited;
                        counters->empty_cells_visited += first == last;
                    }
                    for (std::uint32_t k = first; k < last; ++k) {
                        const std::uint32_t prim = sub.refs[k];
                        if (mailbox.seen(prim)) {
                            if constexpr (Counting) ++counters->mailbox_skips;
                            continue;
                        }
                        if constexpr (Counting) ++counters->prim_tests;
                        if (isect.intersect(prim, ray, hit)) {
                            found = true;
                            if constexpr (AnyHit) return true;
                        }
                    }
                    if (seg->t_exit > ray.tfar || seg->t_exit > cell->t_exit) break;
                }
            }
        }
        if (cell->t_exit > ray.tfar) break;
    }
    return found;
}

// Packets whose rays share a major direction walk the top grid slice by
// slice (coherent_grid.h), in groups where consecutive packets share it
// (coherent_grid_group.h); in each non-empty top cell the lanes that cross
// its grid walk that grid the same way, a group's packets together (or, if
// they spread there, each packet alone, and its lanes each their own DDA).
// Lanes the top walk gives up on, and packets that are not coherent, finish
// one ray at a time from where they are.
template <int K, bool AnyHit, SlabMethod Slabs>
bool Grid2Accel::visit_top_cell(const PacketRecordIntersector<vfloat<K>>& isect, int k, std::uint32_t c,
                                RayPacket<K>& ray, HitPacket<K>& hit, vmask<K>& active, const vfloat<K>& entry,
                                vmask<K>& occluded) const {
    using F = vfloat<K>;
    const Grid& sub = grid_.cells[grid_.cell_grid[c]];
    if (sub.empty()) return false;
    if (sub.geometry.cells() == 1) {
        // A grid of one cell: its primitives against the active lanes, no walk.
        for (const std::uint32_t prim : sub.refs) {
            const vmask<K> m = isect.intersect(active, ray, hit, prim);
            if constexpr (AnyHit) {
                occluded = occluded | m;
                active = active & !m;
                if (none(active)) return true;
            }
        }
        return false;
    }
    const SlabRay<F> slab = make_slab_ray(ray.org, ray.rdir, entry, ray.tfar);
    F sub_entry;
    vmask<K> sub_active = intersect_box<Slabs, F>(active, slab, splat<F>(sub.geometry.bounds.lo),
                                                  splat<F>(sub.geometry.bounds.hi), sub_entry);
    if (none(sub_active)) return false;
    if (!coherent_grid::trace<K, AnyHit>(sub, isect, k, ray, hit, sub_active, sub_entry, occluded))
        grid_lanes::dda_walk<K, AnyHit, Slabs>(sub, isect, ray, hit, sub_active, sub_entry, occluded);
    if constexpr (AnyHit) {
        active = active & !occluded;
        return none(active);
    }
    return false;
}

template <int K, int G, bool AnyHit, SlabMethod Slabs>
bool Grid2Accel::visit_top_cell_group(const PacketRecordIntersector<vfloat<K>>& isect, int k, std::uint32_t c,
                                      std::uint32_t here, std::uint32_t& walking,
                                      coherent_grid::GroupLanes<K, G>& lanes) const {
    using F = vfloat<K>;
    const Grid& sub = grid_.cells[grid_.cell_grid[c]];
    here &= walking;
    if (!sub.empty() && sub.geometry.cells() > 1 && std::popcount(here) > 1) {
        // The packets' lanes that cross c's grid, where they enter it.
        coherent_grid::GroupLanes<K, G> inner;
        int slot[G];
        for (std::uint32_t bits = here; bits; bits &= bits - 1) {
            const int q = std::countr_zero(bits);
            LoadedPacket<K>& one = *lanes.packet[q];
            const SlabRay<F> slab = make_slab_ray(one.ray.org, one.ray.rdir, lanes.entry[q], one.ray.tfar);
            F entry;
            const vmask<K> a = intersect_box<Slabs, F>(lanes.active[q], slab, splat<F>(sub.geometry.bounds.lo),
                                                       splat<F>(sub.geometry.bounds.hi), entry);
            if (none(a)) continue;
            slot[inner.count] = q;
            inner.packet[inner.count] = &one;
            inner.active[inner.count] = a;
            inner.entry[inner.count++] = entry;
        }
        if (inner.count > 1 && coherent_grid::group_major_axis<K, G>(inner) == k) {
            if (!coherent_grid::trace_group<K, G, AnyHit>(sub, isect, k, inner))
                for (int i = 0; i < inner.count; ++i) {  // spread too far apart: each packet on alone
                    LoadedPacket<K>& one = *inner.packet[i];
                    if (any(inner.active[i]) &&
                        !coherent_grid::trace<K, AnyHit>(sub, isect, k, one.ray, one.hit, inner.active[i],
                                                         inner.entry[i], one.occluded))
                        grid_lanes::dda_walk<K, AnyHit, Slabs>(sub, isect, one.ray, one.hit, inner.active[i],
                                                               inner.entry[i], one.occluded);
                }
            if constexpr (AnyHit)
                for (int i = 0; i < inner.count; ++i) {
                    const int q = slot[i];
                    lanes.active[q] = lanes.active[q] & !lanes.packet[q]->occluded;
                    if (none(lanes.active[q])) walking &= ~(1u << q);
                }
            return walking == 0;
        }
        here = 0;  // the packets not in `inner` miss c's grid
        for (int i = 0; i < inner.count; ++i) here |= 1u << slot[i];
    }
    for (std::uint32_t bits = here; bits; bits &= bits - 1) {
        const int q = std::countr_zero(bits);
        LoadedPacket<K>& one = *lanes.packet[q];
        if (visit_top_cell<K, AnyHit, Slabs>(isect, k, c, one.ray, one.hit, lanes.active[q], lanes.entry[q],
                                             one.occluded))
            walking &= ~(1u << q);
    }
    return walking == 0;
}

template <int K, bool AnyHit, SlabMethod Slabs>
void Grid2Accel::trace_packet(const PacketRecordIntersector<vfloat<K>>& isect, RayPacket<K>& ray,
                              HitPacket<K>& hit, vmask<K> active, vfloat<K> entry, vmask<K>& occluded) const {
    const int k = coherent_grid::major_axis<K>(ray, active);
    if (k >= 0 && coherent_grid::walk<K>(grid_.top, k, ray, active, entry, [&](std::uint32_t c) RAYPACK_INLINE_LAMBDA {
            return visit_top_cell<K, AnyHit, Slabs>(isect, k, c, ray, hit, active, entry, occluded);
        }))
        return;
    finish_alone<K, AnyHit, Slabs>(ray, hit, active, entry, occluded);
}

template <int K, bool AnyHit, SlabMethod Slabs>
void Grid2Accel::finish_alone(RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> active, const vfloat<K>& entry,
                              vmask<K>& occluded) const {
    using F = vfloat<K>;
    alignas(64) float org[3][K], dir[3][K], start[K], tfar[K], t[K], u[K], v[K];
    for (int a = 0; a < 3; ++a) ray.org[a].store_aligned(org[a]), ray.dir[a].store_aligned(dir[a]);
    entry.store_aligned(start), ray.tfar.store_aligned(tfar);
    hit.t.store_aligned(t), hit.u.store_aligned(u), hit.v.store_aligned(v);
    std::uint32_t blocked = 0;
    for (std::uint32_t bits = mask_bits(active); bits; bits &= bits - 1) {
        const int l = std::countr_zero(bits);
        Rayf r;
        r.org = {org[0][l], org[1][l], org[2][l]};
        r.dir = {dir[0][l], dir[1][l], dir[2][l]};
        r.tnear = start[l];
        r.tfar = tfar[l];
        Hitf h{t[l], hit.prim[l], u[l], v[l]};
        if (!walk<AnyHit, false, Slabs>(r, h, nullptr)) continue;
        if constexpr (AnyHit) {
            blocked |= 1u << l;
        } else {
            t[l] = h.t, u[l] = h.u, v[l] = h.v, tfar[l] = r.tfar;
            hit.prim[l] = h.prim;
        }
    }
    if constexpr (AnyHit) {
        occluded = occluded | mask_from_bits<K>(blocked);
    } else {
        hit.t = load_lanes<F>(t), hit.u = load_lanes<F>(u), hit.v = load_lanes<F>(v);
        ray.tfar = load_lanes<F>(tfar);
    }
}

template <bool AnyHit>
void Grid2Accel::trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
    with_packet_width(width, "grid2", [&]<int K>() {
        using F = vfloat<K>;
        const PacketRecordIntersector<F> isect{scene_, kernels_, triangle_edges()};
        with_slab_form(kernels_.slabs, [&]<SlabMethod Slabs>(SlabTag<Slabs>) {
            auto trace_one = [&](RayPacket<K>& ray, HitPacket<K>& hit, vmask<K> valid, vmask<K>& occluded) {
                intersect_outside<K, AnyHit>(grid_.top.outside, isect, ray, hit, valid, occluded);
                if (grid_.empty()) return;
                F entry;
                const vmask<K> active = grid_lanes::enter_grid<K, Slabs>(grid_.top, ray, valid, entry);
                if (any(active)) trace_packet<K, AnyHit, Slabs>(isect, ray, hit, active, entry, occluded);
            };
            constexpr int G = coherent_grid::kGroupRays / K;
            trace_in_groups_or_alone<K, G, AnyHit>(
                rays, hits, kernels_.rcp, [](const LoadedPacket<K>&) { return true; }, trace_one,
                [&](LoadedPacket<K>* p, int count) {
                    for (int q = 0; q < count; ++q)
                        intersect_outside<K, AnyHit>(grid_.top.outside, isect, p[q].ray, p[q].hit, p[q].valid,
                                                     p[q].occluded);
                    if (grid_.empty()) return true;
                    coherent_grid::GroupLanes<K, G> lanes;
                    coherent_grid::enter_group<K, G, Slabs>(grid_.top, p, count, lanes);
                    const int k = lanes.count > 1 ? coherent_grid::group_major_axis<K, G>(lanes) : -1;
                    if (k >= 0 && coherent_grid::walk_group<K, G>(
                                      grid_.top, k, lanes,
                                      [&](std::uint32_t c, std::uint32_t here, std::uint32_t& walking,
                                          std::uint32_t& changed) {
                                          changed |= here;  // as far as this walk knows
                                          return visit_top_cell_group<K, G, AnyHit, Slabs>(isect, k, c, here,
                                                                                           walking, lanes);
                                      }))
                        return true;
                    for (int q = 0; q < lanes.count; ++q) {
                        LoadedPacket<K>& one = *lanes.packet[q];
                        if (any(lanes.active[q]))
                            trace_packet<K, AnyHit, Slabs>(isect, one.ray, one.hit, lanes.active[q], lanes.entry[q],
                                                           one.occluded);
                    }
                    return true;
                });
        });
    });
}

template class CellAccel<Grid2Accel, GridRayCounters>;

}  // namespace raypack
