// WideBvhAccel::count_traversal: trace_wide (wide_traversal.h) step for step,
// counting the wide nodes and leaves it enters and the primitives in the leaf
// blocks it tests (padding lanes excluded). Blocks are tested one call each
// through the same intersect_run the timed path uses, so the answers agree.
#include <algorithm>

#include "accel/bvh/wide_bvh_accel.h"

namespace raypack {
namespace {

template <int M, class Block>
std::uint32_t valid_lanes(const Block& b) {
    return std::uint32_t(std::count_if(b.prim, b.prim + M, [](std::uint32_t p) { return p != kNoPrim; }));
}

template <int N, int M, TriangleMethod TM, NodeTest Test, bool AnyHit>
struct WideCountingWalk {
    const WideBvh<N, M>& bvh;
    KernelChoice kernels;
    const PrimitiveIntersector<float>* by_prim;  ///< --precision double: leaves test primitives by id
    TraversalCounts& counts;

    /// One run of blocks, a kernel call per block; true if something was hit.
    template <class Block>
    bool run(const Block* blocks, std::uint32_t count, const LeafRay<vfloat<M>>& r, const Rayf& ray, float& tfar,
             Hitf& hit) const {
        bool found = false;
        for (std::uint32_t k = 0; k < count; ++k) {
            counts.prims += valid_lanes<M>(blocks[k]);
            if (by_prim) found |= intersect_run_by_prim<AnyHit>(blocks + k, 1, PrimLeafRay{by_prim, ray}, tfar, hit);
            else found |= intersect_run<TM, AnyHit>(blocks + k, 1, kernels.sphere, r, tfar, hit);
            if (AnyHit && found) return true;
        }
        return found;
    }

    bool leaf(std::uint32_t code, const LeafRay<vfloat<M>>& r, const Rayf& ray, float& tfar, Hitf& hit) const {
        ++counts.nodes;
        const std::uint32_t first = wide_child::first(code), count = wide_child::blocks(code);
        switch (wide_child::kind(code)) {
            case LeafKind::Triangle: return run(bvh.triangles.data() + first, count, r, ray, tfar, hit);
            case LeafKind::Sphere: return run(bvh.spheres.data() + first, count, r, ray, tfar, hit);
            case LeafKind::Cone: return run(bvh.cones.data() + first, count, r, ray, tfar, hit);
            case LeafKind::Mixed: break;
        }
        const MixedLeaf& m = bvh.mixed[first];
        constexpr int tri = int(LeafKind::Triangle), sph = int(LeafKind::Sphere), cone = int(LeafKind::Cone);
        bool found = run(bvh.triangles.data() + m.first[tri], m.count[tri], r, ray, tfar, hit);
        if (AnyHit && found) return true;
        found |= run(bvh.spheres.data() + m.first[sph], m.count[sph], r, ray, tfar, hit);
        if (AnyHit && found) return true;
        return run(bvh.cones.data() + m.first[cone], m.count[cone], r, ray, tfar, hit) || found;
    }

    /// trace_wide with counters: the same pushes, order and pops.
    bool trace(const Rayf& ray, Hitf& hit) const {
        using F = vfloat<N>;
        if (bvh.nodes.empty()) return false;
        const NodeRay<N> nr = make_node_ray<Test, N>(ray, kernels.slabs, kernels.rcp);
        const LeafRay<vfloat<M>> lr = make_leaf_ray<vfloat<M>>(ray, TM);
        float tfar = ray.tfar;
        WideStackEntry stack[(N - 1) * kBvhMaxDepth + 1];
        WideStackEntry* sp = stack;
        std::uint32_t cur = 0;
        bool found = false;
        for (;;) {
            bool descend = true;
            while (descend && !wide_child::is_leaf(cur)) {
                ++counts.nodes;
                const WideNode<N>& node = bvh.nodes[cur];
                F entry;
                std::uint32_t bits = node_hits<Test>(node, nr, F(node_tfar(tfar)), entry);
                alignas(64) float dist[N];
                entry.store_aligned(dist);
                WideStackEntry* base = sp;
                for (; bits != 0; bits &= bits - 1) {
                    const int i = std::countr_zero(bits);
                    *sp++ = {node.child[i], AnyHit ? 0.0f : dist[i]};
                }
                const std::ptrdiff_t hit_count = sp - base;
                if (hit_count == 0) {
                    descend = false;
                } else if (AnyHit || hit_count == 1) {
                    cur = base->node;  // the first child hit; the rest stay pushed as they came
                    std::copy(base + 1, sp, base);
                    --sp;
                } else if (hit_count == 2) {
                    const bool first_near = base[0].dist <= base[1].dist;
                    cur = base[first_near ? 0 : 1].node;
                    base[0] = base[first_near ? 1 : 0];
                    --sp;
                } else {
                    // Stable sort, decreasing distance towards the top, as trace_wide's insertion sort.
                    std::stable_sort(base, sp, [](const WideStackEntry& a, const WideStackEntry& b) {
                        return a.dist > b.dist;
                    });
                    cur = (--sp)->node;
                }
            }
            if (descend && leaf(cur, lr, ray, tfar, hit)) {
                found = true;
                if constexpr (AnyHit) return true;
            }
            for (;;) {
                if (sp == stack) return found;
                --sp;
                if (AnyHit || sp->dist <= node_tfar(tfar)) break;
            }
            cur = sp->node;
        }
    }
};

}  // namespace

template <int N, int M, NodeTest Test>
bool WideBvhAccel<N, M, Test>::count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                                               TraversalCounts& counts) const {
    auto run = [&]<TriangleMethod TM, bool AnyHit>() {
        const PrimitiveIntersector<float> isect{scene_, kernels_};
        const bool by_prim = kernels_.precision == Precision::Double;
        const WideCountingWalk<N, M, TM, Test, AnyHit> walk{bvh_, kernels_, by_prim ? &isect : nullptr, counts};
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Hitf hit;
            const bool found = walk.trace(rays[i], hit);
            if (AnyHit && found) hit.prim = 0;  // any-hit leaf tests stop before recording the hit
            hits[i] = found ? hit : Hitf{};
        }
    };
    auto with_method = [&]<bool AnyHit>() {
        switch (kernels_.triangle) {
            case TriangleMethod::Moeller: return run.template operator()<TriangleMethod::Moeller, AnyHit>();
            case TriangleMethod::Watertight: return run.template operator()<TriangleMethod::Watertight, AnyHit>();
            case TriangleMethod::Plane: return run.template operator()<TriangleMethod::Plane, AnyHit>();
        }
    };
    if (any_hit) with_method.template operator()<true>();
    else with_method.template operator()<false>();
    return true;
}

#if defined(__SSE4_2__)
template bool WideBvhAccel<4, 4>::count_traversal(std::span<const Rayf>, bool, std::span<Hitf>, TraversalCounts&) const;
#endif
#if defined(__AVX2__)
template bool WideBvhAccel<8, 4>::count_traversal(std::span<const Rayf>, bool, std::span<Hitf>, TraversalCounts&) const;
template bool WideBvhAccel<8, 8>::count_traversal(std::span<const Rayf>, bool, std::span<Hitf>, TraversalCounts&) const;
template bool WideBvhAccel<4, 8>::count_traversal(std::span<const Rayf>, bool, std::span<Hitf>, TraversalCounts&) const;
template bool WideBvhAccel<8, 8, NodeTest::Plain>::count_traversal(std::span<const Rayf>, bool, std::span<Hitf>, TraversalCounts&) const;
template bool WideBvhAccel<8, 8, NodeTest::Robust>::count_traversal(std::span<const Rayf>, bool, std::span<Hitf>, TraversalCounts&) const;
template bool WideBvhAccel<4, 8, NodeTest::Plain>::count_traversal(std::span<const Rayf>, bool, std::span<Hitf>, TraversalCounts&) const;
template bool WideBvhAccel<4, 8, NodeTest::Robust>::count_traversal(std::span<const Rayf>, bool, std::span<Hitf>, TraversalCounts&) const;
#endif

}  // namespace raypack
