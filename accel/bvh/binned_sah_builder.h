#pragma once
// Binned SAH construction (Wald, "On fast Construction of SAH-based Bounding
// Volume Hierarchies", IEEE RT 2007). Sees only boxes and centres.
#include <span>

#include "accel/bvh/bvh2.h"

namespace raypack {

struct BinnedSahConfig {
    int bins = 32;
    int max_leaf_size = 4;           ///< a node this small may become a leaf ...
    float traversal_cost = 1.0f;     ///< ... when the SAH says a split costs more
    float intersection_cost = 1.0f;
};

Bvh2 build_binned_sah(std::span<const Box3f> boxes, std::span<const Vec3f> centers, const BinnedSahConfig& config);

/// SAH cost of a built tree, relative to one primitive test at the root.
double sah_cost(const Bvh2& bvh, float traversal_cost, float intersection_cost);

}  // namespace raypack
