#pragma once
// The BVH2 builders by name, for AccelConfig::builder and the CLI.
#include <span>
#include <string>
#include <string_view>

#include "accel/bvh/build_config.h"
#include "accel/bvh/bvh2.h"

namespace raypack {

/// binned, sweep, morton, sbvh.
std::span<const char* const> bvh_builder_names();
/// The same names joined by '|', for help and error messages.
std::string bvh_builder_list();
bool is_bvh_builder(std::string_view name);

/// Builds with the named builder over boxes[i], i = primitive number.
/// Throws std::invalid_argument for an unknown name.
Bvh2 build_bvh2(std::string_view builder, std::span<const Box3f> boxes, const BvhBuildConfig& config);

}  // namespace raypack
