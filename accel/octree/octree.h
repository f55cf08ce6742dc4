#pragma once
// An adaptive octree over the scene's bounding cube: inner nodes have eight
// children stored consecutively, leaves are ranges of one array of primitive
// references. The node boxes are implicit (the cube halved at every level),
// which is what the parametric traversal of Revelles, Urena & Lastra ("An
// Efficient Parametric Algorithm for Octree Traversal", WSCG 2000) needs.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "kernels/aabb.h"

namespace raypack {

/// Deepest level any build goes to (the traversal stacks are this deep).
inline constexpr int kOctreeMaxDepth = 24;

struct OctreeConfig {
    /// Subdivide while a node holds more than this many references ...
    int leaf_size = 8;
    /// ... and is shallower than this (the root is depth 0; at most kOctreeMaxDepth).
    int max_depth = 12;
    /// A split is not made if this many of the children would hold every
    /// reference of the node: it would only duplicate them (see octree_build.cpp).
    int full_children_stop = 2;
    /// Place triangles by exact triangle-box overlap and spheres by their
    /// distance to the box; false places every primitive by its box only.
    bool exact_overlap = true;
    /// Packets of one direction octant walk the tree in groups
    /// (octree_packet.cpp, trace_group); false: each packet alone.
    bool packet_groups = true;
    /// To the groups, an inner node holding at most this many references is
    /// a leaf (Octree::group_leaves): they cull its primitives by their
    /// boxes at once instead of walking down to the leaves of leaf_size
    /// that single rays want (0: none).
    int group_leaf_size = 24;
};

/// 8 bytes. Inner: `first` is the index of child 0, the eight children follow
/// in the order of Revelles et al. (bit 4 = upper half in x, 2 = y, 1 = z),
/// and `count` is kInner with bit c set for each child c that is not an
/// empty leaf, so that walks skip empty children without reading them,
/// and kGroupLeaf if Octree::group_leaves holds its references.
/// Leaf: refs[first .. first + count].
struct OctreeNode {
    static constexpr std::uint32_t kInner = 0xFFFFFE00u;
    /// Inner nodes: set when the node is a leaf to groups (Octree::group_leaves).
    static constexpr std::uint32_t kGroupLeaf = 0x100u;
    std::uint32_t first = 0;
    std::uint32_t count = 0;

    bool is_leaf() const { return count < kInner; }
    /// Inner nodes: the children that are not empty leaves (bit c: child c).
    std::uint32_t occupied() const { return count & 0xFFu; }
    /// Inner nodes: whether groups of packets take it as a leaf.
    bool group_leaf() const { return (count & kGroupLeaf) != 0; }
};
static_assert(sizeof(OctreeNode) == 8, "octree nodes are two 32-bit words");

struct Octree {
    Box3f cube;                        ///< the root's box, a cube
    std::vector<OctreeNode> nodes;     ///< nodes[0] is the root; empty if there is nothing to trace
    std::vector<std::uint32_t> refs;   ///< primitive numbers, ascending within each leaf
    /// The box of each reference's primitive, for groups of packets that
    /// cull a leaf's primitives before testing them (octree_packet.cpp).
    std::vector<Box3f> ref_boxes;
    float margin = 0;                  ///< boxes were widened by this for placement
    int depth = 0;                     ///< deepest leaf
    /// Per node: for the highest inner nodes of at most
    /// OctreeConfig::group_leaf_size references, their references
    /// (group_refs[first .. first + count], boxes in group_ref_boxes), which
    /// groups of packets test as one leaf; other nodes count = kInner.
    std::vector<OctreeNode> group_leaves;
    std::vector<std::uint32_t> group_refs;
    std::vector<Box3f> group_ref_boxes;
    /// Primitives in no leaf, tested by every ray first (accel/outside_prims.h).
    std::vector<std::uint32_t> outside;

    bool empty() const { return nodes.empty(); }  ///< no leaf holds anything (`outside` may)
    std::size_t bytes() const {
        return (nodes.size() + group_leaves.size()) * sizeof(OctreeNode) +
               (refs.size() + group_refs.size() + outside.size()) * sizeof(std::uint32_t) +
               (ref_boxes.size() + group_ref_boxes.size()) * sizeof(Box3f);
    }
};

}  // namespace raypack
