#include "accel/bvh/build_from_scene.h"

#include <vector>

#include "accel/bvh/binned_sah_builder.h"

namespace raypack {

Bvh2 build_scene_bvh2(const Scene& scene, const AccelConfig& config) {
    const std::size_t n = scene.primitive_count();
    std::vector<Box3f> boxes(n);
    std::vector<Vec3f> centers(n);
    for (std::uint32_t i = 0; i < n; ++i) {
        boxes[i] = primitive_bounds(scene, i);
        centers[i] = boxes[i].center();
    }
    BinnedSahConfig bc;
    bc.bins = config.sah_bins;
    bc.max_leaf_size = config.max_leaf_size;
    bc.traversal_cost = config.traversal_cost;
    bc.intersection_cost = config.intersection_cost;
    return build_binned_sah(boxes, centers, bc);
}

}  // namespace raypack
