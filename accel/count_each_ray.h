#pragma once
// Accel::count_traversal for the structures whose counting walk is their
// own traversal with counters (grid, octree, k-d tree): each ray through
// intersect_counting / occluded_counting, answers in the interface's form,
// the structure's own counters mapped onto TraversalCounts by their
// `add_to`.
#include <cstdint>
#include <span>

#include "accel/accel.h"
#include "kernels/ray.h"

namespace raypack {

template <class Counters, class Structure>
bool count_each_ray(const Structure& s, std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                    TraversalCounts& counts) {
    Counters counters;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        if (!any_hit) {
            hits[i] = s.intersect_counting(rays[i], counters);
            continue;
        }
        hits[i] = Hitf{};
        if (s.occluded_counting(rays[i], counters)) hits[i].prim = 0;  // found() = occluded
    }
    counters.add_to(counts);
    return true;
}

}  // namespace raypack
