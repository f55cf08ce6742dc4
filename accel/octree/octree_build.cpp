#include "accel/octree/octree_build.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

namespace raypack {
namespace {

bool usable(const Box3f& b) { return all_finite(b.lo) && all_finite(b.hi) && !b.empty(); }

float max_abs_coord(const Box3f& b) {
    float m = 0;
    for (int a = 0; a < 3; ++a) m = std::max({m, std::fabs(b.lo[a]), std::fabs(b.hi[a])});
    return m;
}

/// Node during construction; flattened into OctreeNode order at the end.
struct BuildNode {
    std::vector<std::uint32_t> refs;
    std::unique_ptr<std::array<BuildNode, 8>> kids;
    /// An inner node that is a leaf to groups of packets: its references.
    std::vector<std::uint32_t> group_refs;
};

class Builder {
public:
    Builder(std::span<const Box3f> boxes, const PrimitiveBoxOverlap* exact, const OctreeConfig& config, double margin)
        : boxes_(boxes), exact_(exact), config_(config), margin_(margin) {}

    /// Splits `node` (box [lo, hi], at `depth`) recursively.
    void subdivide(BuildNode& node, const Vec3d& lo, const Vec3d& hi, int depth, bool in_group_leaf = false) const {
        const std::size_t n = node.refs.size();
        if (n <= std::size_t(std::max(config_.leaf_size, 0)) || depth >= std::min(config_.max_depth, kOctreeMaxDepth)) return;
        const Vec3d mid = (lo + hi) * 0.5;
        std::array<std::vector<std::uint32_t>, 8> child_refs;
        for (std::uint32_t p : node.refs) {
            const Box3f& b = boxes_[p];
            // Halves the box reaches along each axis (0 = lower, 1 = upper), widened by the margin.
            int from[3], to[3];
            for (int a = 0; a < 3; ++a) {
                from[a] = double(b.lo[a]) - margin_ <= mid[a] ? 0 : 1;
                to[a] = double(b.hi[a]) + margin_ >= mid[a] ? 1 : 0;
            }
            const bool one = from[0] == to[0] && from[1] == to[1] && from[2] == to[2];
            for (int x = from[0]; x <= to[0]; ++x) {
                for (int y = from[1]; y <= to[1]; ++y) {
                    for (int z = from[2]; z <= to[2]; ++z) {
                        const int c = x * 4 + y * 2 + z;
                        if (!one && exact_) {
                            Vec3d clo, chi;
                            child_box(c, lo, mid, hi, clo, chi);
                            const Vec3d m{margin_, margin_, margin_};
                            if (!exact_->overlaps(p, clo - m, chi + m)) continue;
                        }
                        child_refs[c].push_back(p);
                    }
                }
            }
        }
        // Two or more children holding every reference means the split only
        // duplicates: the references overlap throughout the node (a fan of
        // triangles meeting at the centre, layers of overlapping triangles in
        // a plane), and so they would in every deeper split. Stop here; a
        // single full child still cuts away empty space, so it continues.
        int full = 0;
        for (const auto& r : child_refs) full += r.size() == n;
        if (full >= std::max(1, config_.full_children_stop)) return;
        // The highest node of at most group_leaf_size references keeps them.
        const bool group_leaf = !in_group_leaf && n <= std::size_t(std::max(config_.group_leaf_size, 0));
        if (group_leaf) node.group_refs = node.refs;
        node.refs.clear();
        node.refs.shrink_to_fit();
        node.kids = std::make_unique<std::array<BuildNode, 8>>();
        auto build_child = [&](int c) {
            BuildNode& kid = (*node.kids)[c];
            kid.refs = std::move(child_refs[c]);
            Vec3d clo, chi;
            child_box(c, lo, mid, hi, clo, chi);
            subdivide(kid, clo, chi, depth + 1, in_group_leaf || group_leaf);
        };
        // Parallel near the root, where subtrees are large.
        if (n >= 4096) {
            tbb::parallel_for(0, 8, build_child);
        } else {
            for (int c = 0; c < 8; ++c) build_child(c);
        }
    }

    static void child_box(int c, const Vec3d& lo, const Vec3d& mid, const Vec3d& hi, Vec3d& clo, Vec3d& chi) {
        for (int a = 0; a < 3; ++a) {
            const bool upper = (c >> (2 - a)) & 1;
            clo[a] = upper ? mid[a] : lo[a];
            chi[a] = upper ? hi[a] : mid[a];
        }
    }

private:
    std::span<const Box3f> boxes_;
    const PrimitiveBoxOverlap* exact_;
    OctreeConfig config_;
    double margin_;
};

/// Depth-first layout: a node's eight children are consecutive.
void flatten(const BuildNode& b, std::uint32_t index, int depth, Octree& tree) {
    if (!b.kids) {
        tree.nodes[index] = {std::uint32_t(tree.refs.size()), std::uint32_t(b.refs.size())};
        tree.refs.insert(tree.refs.end(), b.refs.begin(), b.refs.end());
        tree.depth = std::max(tree.depth, depth);
        return;
    }
    const std::size_t base = tree.nodes.size();
    if (base + 8 >= std::numeric_limits<std::uint32_t>::max()) throw std::length_error("octree: too many nodes");
    tree.nodes.resize(base + 8);
    std::uint32_t occupied = 0;
    for (int c = 0; c < 8; ++c) {
        const BuildNode& kid = (*b.kids)[c];
        if (kid.kids || !kid.refs.empty()) occupied |= 1u << c;
    }
    const std::uint32_t group_leaf = b.group_refs.empty() ? 0u : OctreeNode::kGroupLeaf;
    tree.nodes[index] = {std::uint32_t(base), OctreeNode::kInner | group_leaf | occupied};
    tree.group_leaves.resize(tree.nodes.size(), OctreeNode{0, OctreeNode::kInner});
    if (group_leaf) {
        tree.group_leaves[index] = {std::uint32_t(tree.group_refs.size()), std::uint32_t(b.group_refs.size())};
        tree.group_refs.insert(tree.group_refs.end(), b.group_refs.begin(), b.group_refs.end());
    }
    for (int c = 0; c < 8; ++c) flatten((*b.kids)[c], std::uint32_t(base + c), depth + 1, tree);
}

}  // namespace

float octree_placement_margin(const Box3f& bounds) {
    const Vec3f e = bounds.extent();
    const float largest = std::max({e.x, e.y, e.z, 0.0f});
    // Twice the grid's: the traversal's plane distances carry one rounding
    // per level (about depth * 2^-24 relative to t), against the grid's one.
    return 2e-5f * largest + 8.0f * std::numeric_limits<float>::epsilon() * max_abs_coord(bounds);
}

Box3f octree_cube(const Box3f& bounds, float margin) {
    const Vec3f e = bounds.extent(), c = bounds.center();
    float half = 0.5f * std::max({e.x, e.y, e.z});
    if (!(half > 0)) half = 1e-3f * std::max(1.0f, max_abs_coord(bounds));  // a single point
    // Padded, so that no primitive touches the root's faces: rays grazing
    // the cube within rounding then have nothing to miss.
    half = half * (1.0f + 1e-3f) + 2.0f * margin;
    Box3f cube;
    for (int a = 0; a < 3; ++a) {
        cube.lo[a] = std::min(c[a] - half, bounds.lo[a] - 2.0f * margin);
        cube.hi[a] = std::max(c[a] + half, bounds.hi[a] + 2.0f * margin);
    }
    // Rounding of the centre can leave the sides a few ulps apart: equalise
    // them. lo + side itself rounds, and not every side is hi - lo for some
    // float hi, so raise the side an ulp at a time until it is for all three.
    const Vec3f top = cube.hi;
    float side = 0;
    for (int a = 0; a < 3; ++a) side = std::max(side, cube.hi[a] - cube.lo[a]);
    for (int round = 0; round < 64; ++round) {
        bool equal = true;
        for (int a = 0; a < 3; ++a) {
            cube.hi[a] = std::max(top[a], cube.lo[a] + side);
            equal = equal && cube.hi[a] - cube.lo[a] == side;
        }
        if (equal) break;
        side = std::nextafter(side, std::numeric_limits<float>::infinity());
    }
    return cube;
}

Octree build_octree(std::span<const Box3f> boxes, const PrimitiveBoxOverlap* exact, const OctreeConfig& config) {
    Octree tree;
    if (boxes.size() >= std::numeric_limits<std::uint32_t>::max()) throw std::length_error("octree: too many primitives");
    Box3f bounds;
    BuildNode root;
    for (std::uint32_t p = 0; p < boxes.size(); ++p) {
        if (!usable(boxes[p])) continue;
        bounds.extend(boxes[p]);
        root.refs.push_back(p);
    }
    if (root.refs.empty()) return tree;
    tree.margin = octree_placement_margin(bounds);
    tree.cube = octree_cube(bounds, tree.margin);
    const Builder builder(boxes, exact, config, tree.margin);
    builder.subdivide(root, Vec3d(tree.cube.lo), Vec3d(tree.cube.hi), 0);
    tree.nodes.resize(1);
    tree.group_leaves.resize(1, OctreeNode{0, OctreeNode::kInner});
    flatten(root, 0, 0, tree);
    tree.group_leaves.resize(tree.nodes.size(), OctreeNode{0, OctreeNode::kInner});
    if (tree.refs.size() >= std::numeric_limits<std::uint32_t>::max())
        throw std::length_error("octree: more references than 32-bit offsets can address");
    tree.ref_boxes.resize(tree.refs.size());
    for (std::size_t r = 0; r < tree.refs.size(); ++r) tree.ref_boxes[r] = boxes[tree.refs[r]];
    tree.group_ref_boxes.resize(tree.group_refs.size());
    for (std::size_t r = 0; r < tree.group_refs.size(); ++r) tree.group_ref_boxes[r] = boxes[tree.group_refs[r]];
    return tree;
}

}  // namespace raypack
