#pragma once
// Settings every BVH builder reads, and the one place that decides between a
// leaf and a split, so that the four builders judge nodes the same way.
#include <cstdint>
#include <functional>

#include "kernels/aabb.h"

namespace raypack {

/// Splits one primitive reference at the plane `axis` = `position` inside
/// its current box `box` (a part of the primitive's box after earlier
/// splits). Fills the bounds of the parts on either side; a part that is
/// empty comes back empty (Box3f::empty()). Used by spatial splits only.
using ReferenceSplitter = std::function<void(std::uint32_t prim, const Box3f& box, int axis, float position,
                                             Box3f& left, Box3f& right)>;

struct BvhBuildConfig {
    int bins = 32;                    ///< SAH bins (binned object splits and spatial splits)
    int max_leaf_size = 4;            ///< a node this small may become a leaf ...
    float traversal_cost = 1.0f;      ///< ... when the SAH says a split costs more
    float intersection_cost = 1.0f;
    /// Spatial splits (Stich, Friedrich, Dietrich 2009): tried only where the
    /// children of the best object split overlap by more than alpha times the
    /// root's area, ...
    float spatial_alpha = 1e-5f;
    /// ... and while the references stay within this many times the primitives.
    float reference_budget = 1.3f;
    /// Clips a reference at a plane; without it spatial splits clip boxes.
    ReferenceSplitter split_reference;
};

/// The SAH terms (Goldsmith & Salmon 1987; MacDonald & Booth 1990) with the
/// leaf rule all builders share: a node of at most max_leaf_size primitives
/// becomes a leaf unless the best split is cheaper; larger nodes always split.
struct SahRule {
    float traversal_cost;
    float intersection_cost;
    int max_leaf_size;

    explicit SahRule(const BvhBuildConfig& c)
        : traversal_cost(c.traversal_cost), intersection_cost(c.intersection_cost), max_leaf_size(c.max_leaf_size) {}

    /// Cost of a split whose children have the given area-weighted counts
    /// (sum of half area * primitives), relative to the parent's half area.
    float split_cost(float weighted_children, float inv_parent_area) const {
        return traversal_cost + intersection_cost * weighted_children * inv_parent_area;
    }
    float leaf_cost(std::uint32_t n) const { return intersection_cost * float(n); }
    bool may_be_leaf(std::uint32_t n) const { return n <= std::uint32_t(max_leaf_size); }
    bool prefers_leaf(std::uint32_t n, float best_split_cost) const {
        return may_be_leaf(n) && leaf_cost(n) <= best_split_cost;
    }
};

}  // namespace raypack
