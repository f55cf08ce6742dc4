#pragma once
// Intersects one scene primitive, whatever its kind, for the scalar path.
// Structures call it from their leaves; they never look at primitives
// themselves.
#include <cstdint>
#include <type_traits>

#include "kernels/aabb.h"
#include "kernels/cone.h"
#include "kernels/sphere.h"
#include "kernels/triangle.h"
#include "scene/scene.h"

namespace raypack {

/// Arithmetic of the primitive tests (`--precision`): float, or double on
/// the float ray and scene converted exactly (the closest hit is still kept
/// as a float t). Traversal stays float; with robust slabs it never culls a
/// box the exact ray meets, so double tests lose no hit to it.
enum class Precision { Float, Double };

/// Which variant of each test to run: primitive tests, slab tests of the
/// traversal (`--slabs`), reciprocal directions (`--rcp`) and precision.
struct KernelChoice {
    SphereMethod sphere = SphereMethod::Geometric;
    TriangleMethod triangle = TriangleMethod::Moeller;
    SlabMethod slabs = SlabMethod::Robust;
    RcpMethod rcp = RcpMethod::Exact;
    Precision precision = Precision::Float;
};

template <class T>
struct PrimitiveIntersector {
    const Scene* scene;
    KernelChoice kernels;

    /// If primitive `prim` is hit within [ray.tnear, ray.tfar], records it in
    /// `hit`, shrinks ray.tfar to the hit and returns true.
    bool intersect(std::uint32_t prim, Ray<T>& ray, Hit<T>& hit) const {
        if constexpr (std::is_same_v<T, float>)
            if (kernels.precision == Precision::Double) return intersect_in_double(prim, ray, hit);
        const PrimRef ref = scene->prims[prim];
        const std::uint32_t i = ref.index;
        T t{}, u{}, v{};
        bool found = false;
        switch (ref.kind) {
            case PrimKind::Sphere:
                found = intersect_sphere(kernels.sphere, ray, Vec3<T>(scene->spheres.center[i]),
                                         T(scene->spheres.radius[i]), t);
                break;
            case PrimKind::Triangle:
                found = intersect_triangle(kernels.triangle, ray, Vec3<T>(scene->triangles.p0[i]),
                                           Vec3<T>(scene->triangles.p1[i]), Vec3<T>(scene->triangles.p2[i]), t, u,
                                           v);
                break;
            case PrimKind::Cone:
                found = intersect_cone(ray, Vec3<T>(scene->cones.base[i]), T(scene->cones.base_radius[i]),
                                       Vec3<T>(scene->cones.apex[i]), T(scene->cones.apex_radius[i]), t, u);
                break;
        }
        if (!found) return false;
        hit.t = t;
        hit.u = u;
        hit.v = v;
        hit.prim = prim;
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
        hit.prim = prim;
        ray.tfar = hit.t;
        return true;
    }
};

}  // namespace raypack
