#pragma once
// Collapse a binary BVH into an N-wide one, then pack its leaves into SoA
// blocks of M primitives. Two ways to choose each wide node's children: open
// the child with the largest surface area until there are N (Wald, Benthin,
// Boulos 2008; Embree's BVHN builders; tinybvh's BVH8_CPU::ConvertFrom), or
// a dynamic program over the binary tree that minimises the wide tree's SAH
// cost (Ylitie, Karras, Laine 2017).
#include "accel/bvh/bvh2.h"
#include "accel/bvh/wide_bvh.h"
#include "scene/scene.h"

namespace raypack {

enum class CollapseMethod {
    /// Open the child with the largest area until N (Wald et al. 2008,
    /// Embree, tinybvh); leaves chosen beforehand by a binary SAH pass.
    Greedy,
    /// Leaves and slots chosen together to minimise the wide tree's SAH cost
    /// (Ylitie, Karras, Laine, HPG 2017).
    Optimal,
};

struct CollapseConfig {
    CollapseMethod method = CollapseMethod::Optimal;
    /// SAH costs of the wide tree: one N-wide node test and one M-wide block
    /// test, each times the surface area of the box that leads to it.
    float node_cost = 1.0f;
    float block_cost = 1.0f;
    int max_leaf_prims = 8;  ///< subtrees with more primitives stay inner nodes
    TriangleLayout triangle_layout = TriangleLayout::Edges;
    const ObjectAccels* objects = nullptr;  ///< what instance blocks point to
};

template <int N, int M>
WideBvh<N, M> collapse_bvh(const Bvh2& bvh, const Scene& scene, const CollapseConfig& config);

/// SAH cost of a wide tree with the binary tree's convention (traversal_cost
/// per node visited, intersection_cost per primitive), relative to the root
/// box, so that BVH2, BVH4 and BVH8 compare directly.
template <int N, int M>
double sah_cost(const WideBvh<N, M>& bvh, float traversal_cost, float intersection_cost);

}  // namespace raypack
