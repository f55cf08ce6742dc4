#pragma once
// A k-d tree: binary space partition by axis-aligned planes, with pbrt's
// 8-byte nodes (Pharr, Jakob & Humphreys, "Physically Based Rendering",
// KdTreeNode / KdTreeAggregate) and SAH costs stated explicitly.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "kernels/aabb.h"

namespace raypack {

struct KdTreeConfig {
    /// SAH costs, relative to each other: visiting one inner node against
    /// one ray-primitive test. 1 : 2, near Wald & Havran's 15 : 20 (2006)
    /// rather than pbrt's 1 : 80 (its tests are virtual calls): swept 1-640
    /// on camera, shadow and diffuse rays in packets of 16 (Zen 5, session
    /// 32), 1 : 2 was 1.02-1.10x faster than 1 : 80 on teapot, balls, gears,
    /// mount and tetra; single camera rays, which want smaller leaves, lost
    /// up to 13% (mount) (docs/structures.md).
    float traversal_cost = 1.0f;
    float intersection_cost = 2.0f;
    /// Fraction of the intersection term forgiven when one child is empty
    /// (pbrt's emptyBonus): cuts off empty space eagerly.
    float empty_bonus = 0.5f;
    /// Depth limit; -1 means round(8 + 1.3 log2 N), as pbrt.
    int max_depth = -1;
    /// Clip triangles to the node's voxel for tight child bounds ("perfect
    /// splits", Havran's thesis 2000; Wald & Havran 2006); false uses their
    /// bounding boxes clipped to the voxel.
    bool perfect_splits = true;
    /// Packets of rays from one point walk the tree in groups
    /// (kdtree_trace_packets); false: every packet alone.
    bool packet_groups = true;
};

/// 8 bytes, as pbrt's KdTreeNode. Inner node: `word` holds the split
/// position, `bits` the axis (low 2 bits) and the index of the above child
/// (upper 30 bits; the below child follows its parent). Leaf: low bits 3,
/// upper 30 bits the primitive count, and `word` the primitive itself when
/// there is one, else the offset of its primitives in KdTree::prim_index.
/// Empty leaves have no node (half the leaves a camera packet reaches were
/// empty: each cost a visit and a pop): a child index of 0, which no child
/// has, stands for empty space; an empty below child is written as the
/// above child following its parent. Only a split with both sides empty
/// stays, as an empty leaf.
struct KdNode {
    std::uint32_t word = 0;
    std::uint32_t bits = 3;

    static KdNode inner(int axis, float split, std::uint32_t above) {
        return {std::bit_cast<std::uint32_t>(split), (above << 2) | std::uint32_t(axis)};
    }
    static KdNode leaf(std::uint32_t count, std::uint32_t first_or_prim) { return {first_or_prim, (count << 2) | 3u}; }

    bool is_leaf() const { return (bits & 3u) == 3u; }
    int axis() const { return int(bits & 3u); }
    float split() const { return std::bit_cast<float>(word); }
    /// Children of the inner node at index `self`; 0 = empty space.
    std::uint32_t below_child(std::uint32_t self) const { return above_child() == self + 1 ? 0 : self + 1; }
    std::uint32_t above_child() const { return bits >> 2; }
    std::uint32_t prim_count() const { return bits >> 2; }
};
static_assert(sizeof(KdNode) == 8, "KdNode: 8 bytes (split or primitive word + flags word)");

/// Deepest tree the traversal stacks hold.
inline constexpr int kKdMaxDepth = 60;

struct KdTree {
    std::vector<KdNode> nodes;               ///< depth-first; root at 0
    std::vector<std::uint32_t> prim_index;   ///< primitives of leaves with more than one
    Box3f bounds;                            ///< the root voxel
    /// Distance by which traversal widens every split plane (and the root
    /// box), so that hits the kernels report within rounding error of a
    /// plane are found on either side: see kdtree_margin().
    float margin = 0;
    int depth = 0;
    std::size_t leaves = 0;        ///< leaves of the SAH build, empty ones included
    std::size_t empty_leaves = 0;  ///< leaves without primitives (most have no node)
    std::size_t references = 0;  ///< primitive references over all leaves
    double sah_cost = 0;         ///< expected cost of a random ray, in traversal-cost units

    /// Primitives in no leaf, tested by every ray first (accel/outside_prims.h).
    std::vector<std::uint32_t> outside;

    bool empty() const { return nodes.empty(); }  ///< no leaf holds anything (`outside` may)
    std::size_t bytes() const {
        return nodes.size() * sizeof(KdNode) + (prim_index.size() + outside.size()) * sizeof(std::uint32_t);
    }
    /// Primitives of leaf `n`.
    const std::uint32_t* leaf_prims(const KdNode& n) const {
        return n.prim_count() == 1 ? &n.word : prim_index.data() + n.word;
    }
};

/// 1e-5 of the largest extent plus 8 ulps of the largest coordinate: covers
/// the rounding of plane distances and of the primitive kernels near planes
/// for ray origins up to ~20 scene sizes away (as the grid's placement
/// margin).
float kdtree_margin(const Box3f& bounds);

}  // namespace raypack
