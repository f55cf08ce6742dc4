#include "accel/brute/brute_force.h"

namespace raypack {

BruteForce::BruteForce(const Scene& scene, KernelChoice kernels) : scene_(&scene), kernels_(kernels) {
    stats_.name = "brute";
    stats_.builder = "none";
    stats_.leaves = 1;
}

void BruteForce::intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const {
    const PrimitiveIntersector<float> isect{scene_, kernels_};
    const auto n = std::uint32_t(scene_->primitive_count());
    for (std::size_t r = 0; r < rays.size(); ++r) {
        Rayf ray = rays[r];
        Hitf hit;
        for (std::uint32_t p = 0; p < n; ++p) isect.intersect(p, ray, hit);
        hits[r] = hit;
    }
}

void BruteForce::occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const {
    const PrimitiveIntersector<float> isect{scene_, kernels_};
    const auto n = std::uint32_t(scene_->primitive_count());
    for (std::size_t r = 0; r < rays.size(); ++r) {
        Rayf ray = rays[r];
        Hitf hit;
        std::uint8_t any = 0;
        for (std::uint32_t p = 0; p < n && !any; ++p) any = isect.intersect(p, ray, hit) ? 1 : 0;
        occluded[r] = any;
    }
}

bool BruteForce::count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                                 TraversalCounts& counts) const {
    const PrimitiveIntersector<float> isect{scene_, kernels_};
    const auto n = std::uint32_t(scene_->primitive_count());
    for (std::size_t r = 0; r < rays.size(); ++r) {
        Rayf ray = rays[r];
        Hitf hit;
        bool found = false;
        std::uint32_t p = 0;
        while (p < n && !(any_hit && found)) found |= isect.intersect(p++, ray, hit);
        counts.prims += p;
        hits[r] = found ? hit : Hitf{};
    }
    return true;
}

Hit<double> BruteForce::intersect_double(const Ray<double>& ray_in) const {
    const PrimitiveIntersector<double> isect{scene_, kernels_};
    Ray<double> ray = ray_in;
    Hit<double> hit;
    for (std::uint32_t p = 0; p < scene_->primitive_count(); ++p) isect.intersect(p, ray, hit);
    return hit;
}

}  // namespace raypack
