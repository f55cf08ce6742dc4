// WideBvhAccel::count_traversal: the timed walk of trace_wide
// (wide_traversal.h) with CountTraversal as its counting policy: wide nodes
// and leaves entered, and the primitives in the leaf blocks tested (padding
// lanes excluded). The same code runs, so the answers and counts are those
// of the timed path.
#include "accel/bvh/wide_bvh_accel.h"

namespace raypack {

template <int N, int M, NodeTest Test>
bool WideBvhAccel<N, M, Test>::count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                                               TraversalCounts& counts) const {
    auto run = [&]<TriangleMethod TM, bool AnyHit>() {
        const PrimitiveIntersector<float> isect{scene_, kernels_};
        const CountTraversal count{counts};
        for (std::size_t i = 0; i < rays.size(); ++i) {
            Hitf hit;
            const bool found =
                kernels_.precision == Precision::Double
                    ? trace_wide<N, M, TM, Test, AnyHit, true>(bvh_, kernels_.sphere, rays[i], hit, kernels_.slabs,
                                                               kernels_.rcp, &isect, count)
                    : trace_wide<N, M, TM, Test, AnyHit, false>(bvh_, kernels_.sphere, rays[i], hit, kernels_.slabs,
                                                                kernels_.rcp, &isect, count);
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
