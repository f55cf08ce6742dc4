#pragma once
// Per-pixel traversal cost of the primary rays, and its heat map: the
// picture papers use to show where a structure spends its time (e.g.
// Aila & Laine, "Understanding the Efficiency of Ray Traversal on GPUs",
// HPG 2009; Wald et al., Embree, SIGGRAPH 2014).
#include <cstdint>
#include <vector>

#include "accel/accel.h"
#include "render/image.h"
#include "scene/scene.h"

namespace raypack {

struct CostMap {
    int width = 0, height = 0;
    std::vector<std::uint32_t> cost;  ///< nodes entered + primitive tests of each pixel's camera ray
    std::vector<std::uint8_t> hit;    ///< 1 where the camera ray hits something
    std::uint32_t min = 0, max = 0;
};

/// The camera ray through each pixel centre, counted by Accel::count_traversal.
/// Throws std::runtime_error when the structure cannot count (Embree).
CostMap primary_ray_cost(const Scene& scene, const Accel& accel, int width, int height);

/// Rows the legend adds below the picture.
int cost_legend_height(int width);

/// The costs mapped linearly from min (dark) to max (yellow) through viridis,
/// with a colour scale bar below the picture labelled with min and max.
Image cost_heat_map(const CostMap& map);

}  // namespace raypack
