#include "accel/grid/grid_accel.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <stdexcept>
#include <string>
#include <vector>

#include "accel/cell_accel_impl.h"
#include "accel/cell_kernel_variants.h"
#include "accel/grid/dda.h"
#include "accel/grid/grid_build.h"
#include "accel/grid/grid_packet.h"
#include "accel/outside_prims.h"

namespace raypack {

GridAccel::GridAccel(const Scene& scene, const AccelConfig& config, const GridConfig& grid_config)
    : scene_(&scene),
      kernels_(config.kernels),
      mailbox_(grid_config.mailbox),
      coherent_packets_(grid_config.coherent_packets) {
    const std::size_t n = scene.primitive_count();
    std::vector<Box3f> boxes(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { boxes[i] = primitive_bounds(scene, std::uint32_t(i)); });
    std::vector<std::uint32_t> outside;
    if (grid_config.large_primitives_outside) outside = take_large_primitives(boxes);
    const PrimitiveBoxOverlap exact{&scene};
    grid_ = build_grid(boxes, grid_config.exact_overlap ? &exact : nullptr, grid_config);
    grid_.outside = std::move(outside);
    for (std::size_t c = 0; c < grid_.geometry.cells(); ++c) empty_cells_ += grid_.cell_begin[c] == grid_.cell_begin[c + 1];
    stats_.name = "grid";
    stats_.builder = "uniform";
    stats_.nodes = grid_.geometry.cells();
    stats_.leaves = grid_.geometry.cells() - empty_cells_;
    make_triangle_edges(scene, kernels_);
    stats_.bytes = grid_.bytes() + triangle_edge_bytes();
    stats_.depth = 1;
    stats_.refs_per_prim = references_per_primitive();
    stats_.empty_leaves = empty_cells_;
}

double GridAccel::references_per_primitive() const {
    const std::size_t n = scene_->primitive_count();
    return n ? double(grid_.refs.size()) / double(n) : 0.0;
}

double GridAccel::empty_cell_fraction() const {
    const std::size_t cells = grid_.geometry.cells();
    return cells ? double(empty_cells_) / double(cells) : 0.0;
}

// Walk the cells front to back and test every primitive in each. Any hit the
// kernels report is a genuine hit in [tnear, tfar] and shrinks tfar, even if
// it lies beyond the current cell (a primitive spanning cells); the walk
// stops once the current cell ends past tfar, since no later cell can then
// hold a nearer hit (as pbrt-v1's GridAccel). The mailbox only saves time:
// re-testing a primitive gives the same answer as before.
// Slabs: the form of the root clip and of the DDA's cell-plane crossings
// (dda.h); --rcp picks how inv_dir is computed.
template <bool AnyHit, bool Counting, bool Mailbox, SlabMethod Slabs>
bool GridAccel::trace(Rayf& ray, Hitf& hit, GridRayCounters* counters) const {
    if constexpr (Counting) ++counters->rays;
    const PrimitiveIntersector<float> isect{scene_, kernels_, triangle_edges()};
    bool found = intersect_outside<AnyHit>(grid_.outside, isect, ray, hit, Counting ? &counters->prim_tests : nullptr);
    if (AnyHit && found) return true;
    if (grid_.empty()) return found;
    const Vec3f inv_dir = ray_reciprocal(ray.dir, kernels_.rcp);
    float entry;
    const SlabRay<float> slab = make_slab_ray(ray.org, inv_dir, ray.tnear, ray.tfar);
    if (!intersect_box<Slabs, float>(true, slab, grid_.geometry.bounds.lo, grid_.geometry.bounds.hi, entry))
        return found;
    const std::uint32_t* begin = grid_.cell_begin.data();
    const std::uint32_t* refs = grid_.refs.data();
    // Direct-mapped on the primitive number: a collision only costs a re-test.
    constexpr std::uint32_t kMailboxSize = 16;
    std::uint32_t mailbox[Mailbox ? kMailboxSize : 1];
    if constexpr (Mailbox) std::fill(mailbox, mailbox + kMailboxSize, kNoPrim);
    GridDda dda(grid_.geometry, ray.org, ray.dir, inv_dir, entry, SlabTag<Slabs>{});
    for (;;) {
        // Empty cells (most of them) in a tight loop of their own, which keeps
        // the DDA's state in registers (gcc spills it around the kernel
        // calls below): 10-25% faster on every shared scene but balls.
        std::optional<DdaSegment> seg;
        std::uint32_t first, last;
        do {
            seg = dda.next();
            if (!seg) return found;
            first = begin[seg->cell];
            last = begin[seg->cell + 1];
            if constexpr (Counting) {
                ++counters->cells_visited;
                counters->empty_cells_visited += first == last;
            }
        } while (first == last && !(seg->t_exit > ray.tfar));
        for (std::uint32_t k = first; k < last; ++k) {
            const std::uint32_t prim = refs[k];
            if constexpr (Mailbox) {
                std::uint32_t& slot = mailbox[prim & (kMailboxSize - 1)];
                if (slot == prim) {
                    if constexpr (Counting) ++counters->mailbox_skips;
                    continue;
                }
                slot = prim;
            }
            if constexpr (Counting) ++counters->prim_tests;
            if (isect.intersect(prim, ray, hit)) {
                found = true;
                if constexpr (AnyHit) return true;
            }
        }
        if (seg->t_exit > ray.tfar) break;
    }
    return found;
}

template <bool AnyHit>
void GridAccel::trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
    with_packet_width(width, "grid", [&]<int K>() {
        grid_trace_packets<K, AnyHit>(grid_, *scene_, kernels_, triangle_edges(), coherent_packets_, rays, hits);
    });
}

bool GridAccel::packets_exact() const { return grid_packets_exact(grid_); }

template class CellAccel<GridAccel, GridRayCounters>;

}  // namespace raypack
