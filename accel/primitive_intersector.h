#pragma once
// Intersects one scene primitive, whatever its kind, for the scalar path.
// Structures call it from their leaves; they never look at primitives
// themselves.
#include <cstdint>
#include <type_traits>

#include "accel/kernel_choice.h"
#include "accel/prims/prim_kinds.h"
#include "accel/prims/triangle_edges.h"
#include "scene/scene.h"

namespace raypack {

template <class T>
struct PrimitiveIntersector {
    const Scene* scene;
    KernelChoice kernels;
    /// Moeller's records of the scene's triangles (TriangleEdgeTable; float
    /// only), or null: triangles are then tested from their vertices.
    const TriangleEdgeRecord* triangle_edges = nullptr;

    /// If primitive `prim` is hit within [ray.tnear, ray.tfar], records it in
    /// `hit`, shrinks ray.tfar to the hit and returns true.
    bool intersect(std::uint32_t prim, Ray<T>& ray, Hit<T>& hit) const {
        if constexpr (std::is_same_v<T, float>)
            if (kernels.precision == Precision::Double) return intersect_in_double(prim, ray, hit);
        const PrimRef ref = scene->prims[prim];
        T t{}, u{}, v{};
        std::uint32_t id = prim;
        const bool found = PrimKinds::dispatch(ref.kind, [&]<class Kind>() RAYPACK_INLINE_LAMBDA {
            if constexpr (std::is_same_v<T, float> && std::is_same_v<Kind, TrianglePrims>)
                if (triangle_edges) {
                    T tt, uu, vv;
                    if (!intersect_triangle_record<T>(triangle_edges[ref.index], true, ray.org, ray.dir, ray.tnear,
                                                      ray.tfar, tt, uu, vv))
                        return false;
                    t = tt, u = uu, v = vv;
                    return true;
                }
            if constexpr (names_hits<Kind>) return Kind::intersect(*scene, ref.index, kernels, ray, t, u, v, id);
            else return Kind::intersect(*scene, ref.index, kernels, ray, t, u, v);
        });
        if (!found) return false;
        hit.t = t;
        hit.u = u;
        hit.v = v;
        hit.prim = id;
        ray.tfar = t;
        return true;
    }

private:
    /// --precision double: the same test on the ray converted to double
    /// (exactly); t rounds back to float, monotonically, so it stays within
    /// [tnear, tfar].
    bool intersect_in_double(std::uint32_t prim, Ray<T>& ray, Hit<T>& hit) const {
        Ray<double> r{Vec3<double>(ray.org), Vec3<double>(ray.dir), double(ray.tnear), double(ray.tfar)};
        Hit<double> h;
        if (!PrimitiveIntersector<double>{scene, kernels}.intersect(prim, r, h)) return false;
        hit.t = T(h.t);
        hit.u = T(h.u);
        hit.v = T(h.v);
        hit.prim = h.prim;
        ray.tfar = hit.t;
        return true;
    }
};

}  // namespace raypack
