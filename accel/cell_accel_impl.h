#pragma once
// CellAccel's members (accel/cell_accel.h), for the .cpp files that
// instantiate them: grid_accel.cpp, kdtree_accel.cpp, octree_accel.cpp.
#include "accel/cell_accel.h"
#include "accel/count_each_ray.h"
#include "accel/packet_widths.h"

namespace raypack {

template <class Derived, class Counters>
void CellAccel<Derived, Counters>::intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const {
    with_slab_form(self().slab_method(), [&]<SlabMethod Slabs>(SlabTag<Slabs>) {
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Rayf ray = rays[i];
            Hitf hit;
            self().template walk<false, false, Slabs>(ray, hit, nullptr);
            hits[i] = hit;
        }
    });
}

template <class Derived, class Counters>
void CellAccel<Derived, Counters>::occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const {
    with_slab_form(self().slab_method(), [&]<SlabMethod Slabs>(SlabTag<Slabs>) {
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Rayf ray = rays[i];
            Hitf hit;
            occluded[i] = self().template walk<true, false, Slabs>(ray, hit, nullptr) ? 1 : 0;
        }
    });
}

/// The counting walk picks the slab form per ray (it is never timed).
template <class Derived, class Counters>
template <bool AnyHit>
bool CellAccel<Derived, Counters>::counting_walk(Rayf& ray, Hitf& hit, Counters& counters) const {
    if (self().slab_method() == SlabMethod::Plain)
        return self().template walk<AnyHit, true, SlabMethod::Plain>(ray, hit, &counters);
    return self().template walk<AnyHit, true, SlabMethod::Robust>(ray, hit, &counters);
}

template <class Derived, class Counters>
Hitf CellAccel<Derived, Counters>::intersect_counting(const Rayf& ray_in, Counters& counters) const {
    Rayf ray = ray_in;
    Hitf hit;
    counting_walk<false>(ray, hit, counters);
    return hit;
}

template <class Derived, class Counters>
bool CellAccel<Derived, Counters>::occluded_counting(const Rayf& ray_in, Counters& counters) const {
    Rayf ray = ray_in;
    Hitf hit;
    return counting_walk<true>(ray, hit, counters);
}

template <class Derived, class Counters>
bool CellAccel<Derived, Counters>::count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                                                   TraversalCounts& counts) const {
    return count_each_ray<Counters>(*this, rays, any_hit, hits, counts);
}

template <class Derived, class Counters>
bool CellAccel<Derived, Counters>::supports_packet(int width) const {
    return packet_width_compiled(width);
}

template <class Derived, class Counters>
void CellAccel<Derived, Counters>::intersect_packets(int width, std::span<const Rayf> rays,
                                                     std::span<Hitf> hits) const {
    if (width == 1 || !self().packets_exact()) return intersect(rays, hits);
    self().template trace_packets<false>(width, rays, hits);
}

template <class Derived, class Counters>
void CellAccel<Derived, Counters>::occluded_packets(int width, std::span<const Rayf> rays,
                                                    std::span<std::uint8_t> occluded_out) const {
    if (width == 1 || !self().packets_exact()) return occluded(rays, occluded_out);
    occlusion_in_slices(rays, occluded_out, [&](std::span<const Rayf> slice, std::span<Hitf> hits) {
        self().template trace_packets<true>(width, slice, hits);
    });
}

}  // namespace raypack
