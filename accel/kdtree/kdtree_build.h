#pragma once
// SAH k-d tree construction in O(N log N) (Wald & Havran, "On building fast
// kd-Trees for Ray Tracing, and on doing that in O(N log N)", IEEE RT 2006):
// one event list sorted once at the root, a linear sweep per node for the
// best plane, and a split of the sorted list by classification, so that only
// the events of primitives straddling the plane are sorted again.
#include <cstdint>
#include <functional>
#include <span>

#include "accel/kdtree/kdtree.h"

namespace raypack {

/// Tight bounds of primitive `prim` within `voxel`; false if it does not
/// meet the voxel. The builder's only view of the primitives.
using KdClipFn = std::function<bool(std::uint32_t prim, const Box3f& voxel, Box3f& clipped)>;

/// Tree over primitives 0 .. boxes.size() - 1 (primitives with an empty or
/// non-finite box are left out). `clip` refines the bounds of primitives
/// that straddle a split plane; without it, their boxes are clipped.
KdTree build_kdtree(std::span<const Box3f> boxes, const KdClipFn& clip, const KdTreeConfig& config);

}  // namespace raypack
