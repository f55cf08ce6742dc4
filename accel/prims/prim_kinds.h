#pragma once
// The registration of primitive kinds: every traversal reaches primitives
// only through this list and the kind's own file (accel/prims/*_prims.h),
// as Embree's PrimitiveIntersectorK and bvh v2's leaf_fn do. A kind
// provides
//   kind                         its PrimKind
//   Block<M>                     M primitives as SoA, with `prim[M]`
//   pack(block, prims, scene, layout)
//   intersect_block<TM>(block, sphere, leaf_ray, tfar, t, u, v)        1 x M
//   intersect_slot<TM>(block, j, sphere, leaf_ray, active, tfar, t, u, v)  K x 1
//   intersect(scene, index, kernels, ray, t, u, v)         by id, one ray
//   intersect(scene, index, kernels, valid, lanes, t, u, v)  by id, lanes
// and a kind whose hits are named inside it (instances: kNamesHits) takes
// one more argument to each test, the ids of its hits.
// Adding a kind: its file, a PrimKind value, and one entry below.
#include <cstdint>
#include <tuple>
#include <type_traits>

#include "accel/kernel_choice.h"
#include "accel/prims/cone_prims.h"
#include "accel/prims/height_field_prims.h"
#include "accel/prims/instance_prims.h"
#include "accel/prims/sphere_prims.h"
#include "accel/prims/triangle_prims.h"

/// For the lambdas handed to dispatch / for_each_run in hot loops: gcc
/// does not inline a lambda's call operator into an always_inline caller by
/// itself (an outlined leaf lambda cost 10% of a packet trace).
#define RAYPACK_INLINE_LAMBDA __attribute__((always_inline))

namespace raypack {

template <class... Kinds>
struct KindList {
    static constexpr int size = sizeof...(Kinds);
    using Tuple = std::tuple<Kinds...>;

    /// fn.template operator()<Kind>() for the kind whose PrimKind is k.
    template <class Fn>
    static RAYPACK_INLINE decltype(auto) dispatch(PrimKind k, Fn&& fn) {
        using First = std::tuple_element_t<0, std::tuple<Kinds...>>;
        using R = decltype(fn.template operator()<First>());
        if constexpr (std::is_void_v<R>) {
            (void)((k == Kinds::kind ? (fn.template operator()<Kinds>(), true) : false) || ...);
        } else {
            R r{};
            (void)((k == Kinds::kind ? (r = fn.template operator()<Kinds>(), true) : false) || ...);
            return r;
        }
    }

    /// fn.template operator()<Kind>() for each kind in list order, stopping
    /// at the first that returns true; whether one did.
    template <class Fn>
    static RAYPACK_INLINE bool until(Fn&& fn) {
        return (fn.template operator()<Kinds>() || ...);
    }

    /// One vector of blocks per kind.
    template <template <class> class Vector, int M>
    using BlockStore = std::tuple<Vector<typename Kinds::template Block<M>>...>;
};

/// The kinds in the order a mixed leaf tests its runs.
using PrimKinds = KindList<TrianglePrims, SpherePrims, ConePrims, HeightFieldPrims, InstancePrims>;
inline constexpr int kPrimKinds = PrimKinds::size;

/// Which kinds a structure's hot loops are compiled for, chosen once per
/// build from what the scene holds ("model only what the scene requires"):
/// a scene of triangles alone runs loops with no sphere, cone, height-field
/// or instance code in them; any other scene the general loops.
enum class KindSpecialisation : std::uint8_t { General, Triangles };
using TriangleKinds = KindList<TrianglePrims>;

/// Triangles when the scene holds triangles and nothing else, for the
/// default kernels (Moeller-Trumbore, float: the loops compiled twice) and
/// unless `--specialise off`.
inline KindSpecialisation specialisation_for(const Scene& scene, const KernelChoice& k) {
    const bool triangles_only = scene.triangles.size() > 0 && scene.spheres.size() == 0 && scene.cones.size() == 0 &&
                                scene.height_fields.empty() && !scene.placements();
    const bool default_kernels = k.triangle == TriangleMethod::Moeller && k.precision == Precision::Float;
    return k.specialise && triangles_only && default_kernels ? KindSpecialisation::Triangles
                                                             : KindSpecialisation::General;
}
inline const char* specialisation_name(KindSpecialisation k) {
    return k == KindSpecialisation::Triangles ? "triangles" : "general";
}

/// fn.template operator()<Kinds>() with the KindList of `k`.
template <class Fn>
RAYPACK_INLINE decltype(auto) with_kinds(KindSpecialisation k, Fn&& fn) {
    if (k == KindSpecialisation::Triangles) return fn.template operator()<TriangleKinds>();
    return fn.template operator()<PrimKinds>();
}

}  // namespace raypack
