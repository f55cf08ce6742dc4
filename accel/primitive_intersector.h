#pragma once
// Intersects one scene primitive, whatever its kind, for the scalar path.
// Structures call it from their leaves; they never look at primitives
// themselves.
#include <cstdint>

#include "kernels/cone.h"
#include "kernels/sphere.h"
#include "kernels/triangle.h"
#include "scene/scene.h"

namespace raypack {

/// Which variant of each primitive test to run.
struct KernelChoice {
    SphereMethod sphere = SphereMethod::Geometric;
    TriangleMethod triangle = TriangleMethod::Moeller;
};

template <class T>
struct PrimitiveIntersector {
    const Scene* scene;
    KernelChoice kernels;

    /// If primitive `prim` is hit within [ray.tnear, ray.tfar], records it in
    /// `hit`, shrinks ray.tfar to the hit and returns true.
    bool intersect(std::uint32_t prim, Ray<T>& ray, Hit<T>& hit) const {
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
};

}  // namespace raypack
