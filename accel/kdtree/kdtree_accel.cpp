#include "accel/kdtree/kdtree_accel.h"

#include <tbb/parallel_for.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "accel/cell_kernel_variants.h"
#include "accel/cell_accel_impl.h"
#include "accel/kdtree/kdtree_build.h"
#include "accel/kdtree/kdtree_packet.h"
#include "accel/kdtree/kdtree_ray_interval.h"
#include "accel/kdtree/primitive_clipper.h"
#include "accel/outside_prims.h"

namespace raypack {

KdTreeAccel::KdTreeAccel(const Scene& scene, const AccelConfig& config, const KdTreeConfig& kd_config)
    : scene_(&scene), kernels_(config.kernels), packet_groups_(kd_config.packet_groups) {
    const std::size_t n = scene.primitive_count();
    std::vector<Box3f> boxes(n);
    tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) { boxes[i] = primitive_bounds(scene, std::uint32_t(i)); });
    const PrimitiveClipper clipper{&scene, kd_config.perfect_splits};
    const KdClipFn clip = [&](std::uint32_t prim, const Box3f& voxel, Box3f& out) {
        return clipper.clip(prim, voxel, out);
    };
    std::vector<std::uint32_t> outside = take_large_primitives(boxes);
    tree_ = build_kdtree(boxes, clip, kd_config);
    tree_.outside = std::move(outside);
    stats_.name = "kdtree";
    stats_.builder = "sah-nlogn";
    stats_.nodes = tree_.nodes.size();
    stats_.leaves = tree_.leaves;
    stats_.bytes = tree_.bytes();
    stats_.depth = tree_.depth;
    stats_.sah_cost = tree_.sah_cost;
    stats_.refs_per_prim = references_per_primitive();
    stats_.empty_leaves = tree_.empty_leaves;
}

double KdTreeAccel::references_per_primitive() const {
    const std::size_t n = scene_->primitive_count();
    return n ? double(tree_.references) / double(n) : 0.0;
}

namespace {

/// A closest-hit test under --precision double once the ray has a hit:
/// against tfar widened by kd_tie_tfar(), keeping the nearer hit and on equal
/// t the lower primitive. Out of line, off the default path.
[[gnu::noinline]] void test_after_hit_in_double(const PrimitiveIntersector<float>& isect, std::uint32_t prim,
                                                Rayf& ray, Hitf& hit) {
    const Hitf before = hit;
    Rayf probe = ray;
    probe.tfar = kd_tie_tfar(ray.tfar);
    if (!isect.intersect(prim, probe, hit)) return;
    if (hit.t > before.t || (hit.t == before.t && before.prim < prim)) hit = before;
    ray.tfar = hit.t;
}

/// The counting walk's visit of empty space: the empty leaf it stands for.
inline void count_empty_leaf(KdRayCounters* counters, bool visited) {
    counters->nodes_visited += visited;
    counters->leaves_visited += visited;
    counters->empty_leaves_visited += visited;
}

}  // namespace

// Front-to-back traversal with a stack of far children and their intervals
// (Havran's TA_B; pbrt's KdTreeAggregate::Intersect). Each split plane is
// widened by the tree's margin: the below child is visited where the ray is
// at most `margin` above the plane, the above child where it is at most
// `margin` below, so that neither rounding of the plane distance nor a hit
// the kernels report just across a plane is lost; a ray in a plane (its
// direction component +-0, reciprocal() clamps it) visits both children.
// Any hit the kernels report is genuine and shrinks tfar; a node is skipped
// once its interval starts past tfar.
// Slabs = Plain (`--slabs plain`): root box and split planes are all slab
// planes, so both take the plain form, p * rdir - org * rdir fused, without
// the margin: pbrt's traversal, whose misses near planes the robust form's
// margin exists to avoid.
template <bool AnyHit, bool Counting, SlabMethod Slabs>
bool KdTreeAccel::walk(Rayf& ray, Hitf& hit, KdRayCounters* counters) const {
    if constexpr (Counting) ++counters->rays;
    const PrimitiveIntersector<float> isect{scene_, kernels_};
    bool found = intersect_outside<AnyHit>(tree_.outside, isect, ray, hit, Counting ? &counters->prim_tests : nullptr);
    if (AnyHit && found) return true;
    if (tree_.empty()) return found;
    const Vec3f rdir = ray_reciprocal(ray.dir, kernels_.rcp);
    float tmin, tmax;
    if (!ray_box_interval<float, Slabs>(true, ray.org, rdir, ray.tnear, ray.tfar, tree_.bounds, tree_.margin, tmin,
                                       tmax))
        return found;
    constexpr bool plain = Slabs == SlabMethod::Plain;
    const Vec3f org_rdir{ray.org.x * rdir.x, ray.org.y * rdir.y, ray.org.z * rdir.z};
    const float margin = plain ? 0.0f : tree_.margin;
    const float slack[3] = {margin * std::fabs(rdir.x), margin * std::fabs(rdir.y), margin * std::fabs(rdir.z)};
    const bool double_ties = kernels_.precision == Precision::Double;
    const KdNode* nodes = tree_.nodes.data();
    struct PendingNode {
        std::uint32_t node;
        float tmin, tmax;
    };
    PendingNode stack[kKdMaxDepth + 1];
    int sp = 0;
    std::uint32_t current = 0;
    for (;;) {
        const KdNode node = nodes[current];
        if constexpr (Counting) ++counters->nodes_visited;
        if (!node.is_leaf()) {
            const int a = node.axis();
            const float t_split = plane_distance<Slabs>(node.split(), ray.org[a], rdir[a], org_rdir[a]);
            const float near_end = plain ? t_split : t_split + slack[a];
            const float far_start = plain ? t_split : t_split - slack[a];
            const bool below_first = rdir[a] >= 0.0f;
            const std::uint32_t below = node.below_child(current), above = node.above_child();
            const std::uint32_t near = below_first ? below : above;
            const std::uint32_t far = below_first ? above : below;
            // (A ray that misses the near side takes the far one even if a
            // NaN distance misses both.)
            const bool visit_near = near_end >= tmin, visit_far = far_start <= tmax || !visit_near;
            // Empty space (child 0) is not visited; the counting walk counts
            // it as the empty leaf it stands for (pushed, it counts when popped).
            if (visit_near && near) {
                if (visit_far && (far || Counting)) stack[sp++] = {far, std::max(tmin, far_start), tmax};
                current = near;
                tmax = std::min(tmax, near_end);
                continue;
            }
            if constexpr (Counting) count_empty_leaf(counters, visit_near);
            // Past empty space the far side is entered as if popped: only if
            // it starts before the closest hit so far.
            if (visit_far && far && (!visit_near || std::max(tmin, far_start) <= ray.tfar)) {
                current = far;
                tmin = std::max(tmin, far_start);
                continue;
            }
            if constexpr (Counting) count_empty_leaf(counters, visit_far && !visit_near);
        } else {
            const std::uint32_t count = node.prim_count();
            if constexpr (Counting) {
                ++counters->leaves_visited;
                counters->empty_leaves_visited += count == 0;
                counters->prim_tests += count;
            }
            const std::uint32_t* prims = tree_.leaf_prims(nodes[current]);
            for (std::uint32_t k = 0; k < count; ++k) {
                const Hitf before = hit;
                if constexpr (!AnyHit) {
                    if (double_ties && found) [[unlikely]] {
                        test_after_hit_in_double(isect, prims[k], ray, hit);
                        continue;
                    }
                }
                if (isect.intersect(prims[k], ray, hit)) {
                    found = true;
                    if constexpr (AnyHit) return true;
                    // The kernels accept t == tfar, so of several primitives at
                    // exactly the same t the last one tested would win: keep the
                    // lowest number instead, which makes the answer independent
                    // of the visiting order (packets order nodes by one lane).
                    if (hit.t == before.t && before.prim < prims[k]) hit = before;
                }
            }
        }
        // Pop the next node the ray reaches before its closest hit so far.
        for (;;) {
            if (sp == 0) return found;
            const PendingNode& t = stack[--sp];
            if (t.tmin <= ray.tfar) {
                if (Counting && t.node == 0) {
                    count_empty_leaf(counters, true);
                    continue;
                }
                current = t.node;
                tmin = t.tmin;
                tmax = t.tmax;
                break;
            }
        }
    }
}

template <bool AnyHit>
void KdTreeAccel::trace_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
    with_packet_width(width, "kdtree", [&]<int K>() {
        kdtree_trace_packets<K, AnyHit>(tree_, *scene_, kernels_, rays, hits, packet_groups_);
    });
}

template class CellAccel<KdTreeAccel, KdRayCounters>;

}  // namespace raypack
