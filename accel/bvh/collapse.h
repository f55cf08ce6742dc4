#pragma once
// Collapse a binary BVH into an N-wide one, then pack its leaves into SoA
// blocks of M primitives. Each wide node starts from a binary node's two
// children and repeatedly opens the child with the largest surface area
// until it has N (Wald, Benthin, Boulos 2008; Embree's BVHN builders;
// tinybvh's BVH8_CPU::ConvertFrom).
#include "accel/bvh/bvh2.h"
#include "accel/bvh/wide_bvh.h"
#include "scene/scene.h"

namespace raypack {

struct CollapseConfig {
    /// SAH costs of the wide tree: one N-wide node test and one M-wide block
    /// test. A binary subtree becomes a leaf when its blocks cost less than
    /// its nodes and leaves would, counting 1/(N-1) of a wide node per binary
    /// inner node (an N-wide node replaces N-1 binary ones).
    float node_cost = 1.0f;
    float block_cost = 1.0f;
    int max_leaf_prims = 8;  ///< subtrees with more primitives stay inner nodes
    TriangleLayout triangle_layout = TriangleLayout::Edges;
};

template <int N, int M>
WideBvh<N, M> collapse_bvh(const Bvh2& bvh, const Scene& scene, const CollapseConfig& config);

/// SAH cost of a wide tree with the binary tree's convention (traversal_cost
/// per node visited, intersection_cost per primitive), relative to the root
/// box, so that BVH2, BVH4 and BVH8 compare directly.
template <int N, int M>
double sah_cost(const WideBvh<N, M>& bvh, float traversal_cost, float intersection_cost);

}  // namespace raypack
