#include "accel/octree/octree_accel.h"

#include <tbb/parallel_for.h>

#include <cmath>
#include <vector>

#include "accel/cell_kernel_variants.h"
#include "accel/cell_accel_impl.h"
#include "accel/octree/octree_build.h"
#include "accel/octree/octree_packet.h"
#include "accel/octree/revelles.h"
#include "accel/outside_prims.h"

namespace raypack {

OctreeAccel::OctreeAccel(const Scene& scene, const AccelConfig& config, const OctreeConfig& octree_config)
    : scene_(&scene), kernels_(config.kernels), packet_groups_(octree_config.packet_groups) {
    const std::size_t n = scene.primitive_count();
    std::vector<Box3f> boxes(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { boxes[i] = primitive_bounds(scene, std::uint32_t(i)); });
    std::vector<std::uint32_t> outside = take_large_primitives(boxes);
    const PrimitiveBoxOverlap exact{&scene};
    tree_ = build_octree(boxes, octree_config.exact_overlap ? &exact : nullptr, octree_config);
    tree_.outside = std::move(outside);
    std::size_t leaves = 0;
    for (const OctreeNode& node : tree_.nodes) {
        leaves += node.is_leaf();
        empty_leaves_ += node.is_leaf() && node.count == 0;
    }
    stats_.name = "octree";
    stats_.builder = "adaptive";
    stats_.nodes = tree_.nodes.size();
    stats_.leaves = leaves;
    make_triangle_edges(scene, kernels_);
    stats_.bytes = tree_.bytes() + triangle_edge_bytes();
    stats_.depth = tree_.depth;
    stats_.refs_per_prim = references_per_primitive();
    stats_.empty_leaves = empty_leaves_;
}

double OctreeAccel::references_per_primitive() const {
    const std::size_t n = scene_->primitive_count();
    return n ? double(tree_.refs.size()) / double(n) : 0.0;
}

namespace {

/// One inner node of the walk: its slab parameters and the next child to
/// visit (mirrored numbering; 8 = done). The explicit stack holds these for
/// the ancestors of the current node, in place of the paper's recursion.
struct Frame {
    float t0[3], tm[3], t1[3];
    std::uint32_t children;
    int child;
};

}  // namespace

// Closest hit or any hit. Nodes are visited front to back along the ray, so a
// hit at or before the current node's exit ends the walk: every later node
// starts at or after that exit. Hits the kernels report are genuine hits in
// [tnear, tfar] even when they lie beyond the current leaf, and shrink tfar.
// Slabs: the form of the root cube's plane distances, the only ones the walk
// computes from coordinates (every child's come from them as midpoints).
template <bool AnyHit, bool Counting, SlabMethod Slabs>
bool OctreeAccel::walk(Rayf& ray, Hitf& hit, OctreeRayCounters* counters) const {
    if constexpr (Counting) ++counters->rays;
    const PrimitiveIntersector<float> isect{scene_, kernels_, triangle_edges()};
    bool found = intersect_outside<AnyHit>(tree_.outside, isect, ray, hit, Counting ? &counters->prim_tests : nullptr);
    if (AnyHit && found) return true;
    if (tree_.empty()) return found;
    const Vec3f rdir = ray_reciprocal(ray.dir, kernels_.rcp);
    const Box3f& cube = tree_.cube;
    unsigned a = 0;
    Frame f;
    for (int k = 0; k < 3; ++k) {
        // Computed as the slab test of that form computes its distances.
        const float od = ray.org[k] * rdir[k];
        const float lo = plane_distance<Slabs>(cube.lo[k], ray.org[k], rdir[k], od),
                    hi = plane_distance<Slabs>(cube.hi[k], ray.org[k], rdir[k], od);
        const bool mirrored = std::signbit(ray.dir[k]);
        a |= mirrored ? 4u >> k : 0u;
        f.t0[k] = mirrored ? hi : lo;
        f.t1[k] = mirrored ? lo : hi;
        f.tm[k] = 0.5f * (f.t0[k] + f.t1[k]);
    }
    const float enter = std::max({f.t0[0], f.t0[1], f.t0[2]}), exit = std::min({f.t1[0], f.t1[1], f.t1[2]});
    if (!(std::max(enter, ray.tnear) <= std::min(exit, ray.tfar))) return found;

    const bool float_ties = kernels_.precision == Precision::Float;
    const OctreeNode* nodes = tree_.nodes.data();
    const std::uint32_t* refs = tree_.refs.data();
    // The primitives of a leaf; true if the walk may stop (any hit found).
    auto test_leaf = [&](const OctreeNode& leaf) {
        if constexpr (Counting) ++counters->leaves_visited;
        for (std::uint32_t k = leaf.first; k < leaf.first + leaf.count; ++k) {
            if constexpr (Counting) ++counters->prim_tests;
            const Hitf before = hit;
            if (isect.intersect(refs[k], ray, hit)) {
                found = true;
                if constexpr (AnyHit) return true;
                // Equal t: the lowest primitive number wins (accel/packet_ties.h),
                // so that groups of packets, which test more leaves than a
                // lane's own walk, keep the single ray's hit. (Double tests
                // go lane by lane in the packets' own order, and never in
                // groups: the last one tested wins, as in single rays.)
                if (float_ties && hit.t == before.t && before.prim < refs[k]) hit = before;
            }
        }
        return false;
    };
    if constexpr (Counting) ++counters->nodes_visited;
    if (nodes[0].is_leaf()) {
        test_leaf(nodes[0]);
        return found;
    }
    f.children = nodes[0].first;
    f.child = revelles::first_node(f.tm[0], f.tm[1], f.tm[2], std::max(enter, ray.tnear));
    Frame stack[kOctreeMaxDepth];
    int sp = 0;
    for (;;) {
        if (f.child >= 8) {
            if (sp == 0) break;
            f = stack[--sp];
            continue;
        }
        const int c = f.child;
        float c0[3], c1[3];
        for (int k = 0; k < 3; ++k) {
            const bool upper = c & (4 >> k);
            c0[k] = upper ? f.tm[k] : f.t0[k];
            c1[k] = upper ? f.t1[k] : f.tm[k];
        }
        f.child = revelles::new_node(c, c1[0], c1[1], c1[2]);
        const OctreeNode node = nodes[f.children + (unsigned(c) ^ a)];
        if constexpr (Counting) {
            ++counters->nodes_visited;
            counters->empty_leaves_visited += node.count == 0;
        }
        if (node.count == 0) continue;  // an empty leaf
        const float child_exit = std::min({c1[0], c1[1], c1[2]});
        if (child_exit < ray.tnear) continue;  // behind the ray's start (rounding only: first_node skips these)
        const float child_enter = std::max({c0[0], c0[1], c0[2]});
        if (child_enter > ray.tfar) break;  // front to back: every later node starts later
        if (node.is_leaf()) {
            if (test_leaf(node)) return true;
            if (found && ray.tfar <= child_exit) break;
            continue;
        }
        stack[sp++] = f;
        for (int k = 0; k < 3; ++k) {
            f.t0[k] = c0[k];
            f.t1[k] = c1[k];
            f.tm[k] = 0.5f * (c0[k] + c1[k]);
        }
        f.children = node.first;
        f.child = revelles::first_node(f.tm[0], f.tm[1], f.tm[2], std::max(child_enter, ray.tnear));
    }
    return found;
}

template <bool AnyHit>
void OctreeAccel::trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
    with_packet_width(width, "octree", [&]<int K>() {
        octree_trace_packets<K, AnyHit>(tree_, *scene_, kernels_, triangle_edges(), rays, hits, packet_groups_);
    });
}

template class CellAccel<OctreeAccel, OctreeRayCounters>;

}  // namespace raypack
