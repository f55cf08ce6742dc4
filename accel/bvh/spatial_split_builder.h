#pragma once
// Split BVH (Stich, Friedrich, Dietrich, "Spatial Splits in Bounding Volume
// Hierarchies", HPG 2009): each node weighs the best binned object split
// against the best spatial split, which cuts the references straddling a
// plane in two (config.split_reference clips them exactly). Spatial splits
// are tried only where the object split's children overlap by more than
// alpha times the root's area, and only while the references stay within
// the budget. Leaves hold references, so prim_index may list a primitive
// in several leaves.
#include <span>

#include "accel/bvh/build_config.h"
#include "accel/bvh/bvh2.h"

namespace raypack {

Bvh2 build_spatial_split(std::span<const Box3f> boxes, const BvhBuildConfig& config);

/// A ReferenceSplitter that clips boxes only (spheres, cones, or no geometry).
void split_box(const Box3f& box, int axis, float position, Box3f& left, Box3f& right);

}  // namespace raypack
