#include "accel/bvh/bvh_builders.h"

#include <stdexcept>

#include "accel/bvh/binned_sah_builder.h"
#include "accel/bvh/morton_builder.h"
#include "accel/bvh/spatial_split_builder.h"
#include "accel/bvh/sweep_sah_builder.h"
#include "accel/names.h"

namespace raypack {

std::span<const char* const> bvh_builder_names() {
    static constexpr const char* names[] = {"binned", "sweep", "morton", "sbvh"};
    return names;
}

std::string bvh_builder_list() { return names_joined(bvh_builder_names()); }

bool is_bvh_builder(std::string_view name) {
    for (const char* n : bvh_builder_names())
        if (name == n) return true;
    return false;
}

Bvh2 build_bvh2(std::string_view builder, std::span<const Box3f> boxes, const BvhBuildConfig& config) {
    if (builder == "binned") return build_binned_sah(boxes, config);
    if (builder == "sweep") return build_sweep_sah(boxes, config);
    if (builder == "morton") return build_morton(boxes, config);
    if (builder == "sbvh") return build_spatial_split(boxes, config);
    throw std::invalid_argument("unknown BVH builder '" + std::string(builder) + "' (expected " + bvh_builder_list() +
                                ")");
}

}  // namespace raypack
