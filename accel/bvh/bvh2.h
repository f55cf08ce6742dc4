#pragma once
// A binary BVH flattened depth first: the left child of an inner node
// directly follows it, the right child's index is stored.
#include <cstdint>
#include <vector>

#include "kernels/aabb.h"

namespace raypack {

struct Bvh2Node {
    Box3f box;             // 24 bytes
    std::uint32_t first;   // inner: right child index; leaf: first entry of prim_index
    std::uint32_t count;   // 0 for an inner node, else the number of primitives
    bool is_leaf() const { return count != 0; }
};  // total: 32 bytes
static_assert(sizeof(Bvh2Node) == 32);

struct Bvh2 {
    std::vector<Bvh2Node> nodes;
    std::vector<std::uint32_t> prim_index;  ///< leaf entries -> primitive numbers
    int depth = 0;
    std::size_t leaves = 0;
};

/// Maximum depth a builder may produce; traversal stacks are sized from it.
inline constexpr int kBvhMaxDepth = 64;

}  // namespace raypack
