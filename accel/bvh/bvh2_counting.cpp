// Bvh2Accel::count_traversal: the single-ray traversal itself
// (bvh2_traversal.h), instantiated with counters; the timed instantiation
// carries none.
#include "accel/bvh/bvh2_accel.h"
#include "accel/bvh/bvh2_traversal.h"

namespace raypack {

bool Bvh2Accel::count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                                TraversalCounts& counts) const {
    const PrimitiveIntersector<float> isect{scene_, kernels_};
    auto run = [&]<SlabMethod Slabs>() {
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Rayf ray = rays[i];
            Hitf hit;
            bool found = false;
            if (!bvh_.nodes.empty())
                found = any_hit ? trace_bvh2_subtree<true, Slabs>(bvh_, isect, 0, ray, hit, CountTraversal{counts})
                                : trace_bvh2_subtree<false, Slabs>(bvh_, isect, 0, ray, hit, CountTraversal{counts});
            hits[i] = found ? hit : Hitf{};
        }
    };
    if (kernels_.slabs == SlabMethod::Plain) run.template operator()<SlabMethod::Plain>();
    else run.template operator()<SlabMethod::Robust>();
    return true;
}

}  // namespace raypack
