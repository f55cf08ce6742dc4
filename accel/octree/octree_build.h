#pragma once
// Top-down octree construction: a node is split into its eight octants while
// it holds more than leaf_size references and is shallower than max_depth;
// each primitive goes into the octants it really meets (exact
// triangle-box overlap, Akenine-Moeller 2001, through PrimitiveBoxOverlap).
#include <span>

#include "accel/grid/primitive_box_overlap.h"
#include "accel/octree/octree.h"

namespace raypack {

/// Widening of every node box for placement. It covers the rounding of the
/// parametric traversal, whose plane distances are averages of averages
/// (one rounding per level): a ray then never leaves a node, within
/// rounding, before a primitive it could hit there is also in the next one.
float octree_placement_margin(const Box3f& bounds);

/// The padded cube around `bounds` (the root's box).
Box3f octree_cube(const Box3f& bounds, float margin);

/// Octree over the primitives with bounds `boxes` (empty or non-finite boxes
/// are left out). `exact` refines the box test; null places by boxes only.
Octree build_octree(std::span<const Box3f> boxes, const PrimitiveBoxOverlap* exact, const OctreeConfig& config);

}  // namespace raypack
