#pragma once
// Intersects one scene primitive with the lanes of a ray packet: the leaf
// step of every packet traversal. Structures never look at primitive kinds.
#include <bit>
#include <cstdint>

#include "accel/primitive_intersector.h"
#include "kernels/cone.h"
#include "kernels/ray_packet.h"
#include "kernels/sphere.h"
#include "kernels/triangle.h"
#include "scene/scene.h"

namespace raypack {

template <class F>
RAYPACK_INLINE Vec3<F> splat(const Vec3f& p) {
    return {F(p.x), F(p.y), F(p.z)};
}

template <class F>
struct PacketPrimitiveIntersector {
    const Scene* scene;
    KernelChoice kernels;

    /// Lanes of `valid` that hit primitive `prim` within [tnear, tfar]:
    /// records the hit in those lanes of `hit` and shrinks their tfar.
    RAYPACK_INLINE mask_of<F> intersect(mask_of<F> valid, RayLanes<F>& ray, HitLanes<F>& hit,
                                        std::uint32_t prim) const {
        const PrimRef ref = scene->prims[prim];
        const std::uint32_t i = ref.index;
        F t, u(0.0f), v(0.0f);
        mask_of<F> m;
        switch (ref.kind) {
            case PrimKind::Sphere: {
                const Vec3<F> c = splat<F>(scene->spheres.center[i]);
                const F r(scene->spheres.radius[i]);
                switch (kernels.sphere) {
                    case SphereMethod::Algebraic:
                        m = intersect_sphere_algebraic(valid, ray.org, ray.dir, ray.tnear, ray.tfar, c, r, t);
                        break;
                    case SphereMethod::Geometric:
                        m = intersect_sphere_geometric(valid, ray.org, ray.dir, ray.tnear, ray.tfar, c, r, t);
                        break;
                    default:
                        m = intersect_sphere_precise(valid, ray.org, ray.dir, ray.tnear, ray.tfar, c, r, t);
                        break;
                }
                break;
            }
            case PrimKind::Triangle: {
                const TriangleSoA& tr = scene->triangles;
                const Vec3<F> p0 = splat<F>(tr.p0[i]), p1 = splat<F>(tr.p1[i]), p2 = splat<F>(tr.p2[i]);
                switch (kernels.triangle) {
                    case TriangleMethod::Moeller:
                        m = intersect_triangle_moeller(valid, ray.org, ray.dir, ray.tnear, ray.tfar, p0, p1, p2, t, u, v);
                        break;
                    case TriangleMethod::Plane:
                        m = intersect_triangle_plane(valid, ray.org, ray.dir, ray.tnear, ray.tfar, p0, p1, p2, t, u, v);
                        break;
                    default:
                        m = intersect_triangle_watertight(valid, ray.org, ray.dir, ray.tnear, ray.tfar, p0, p1, p2, t, u,
                                                          v);
                        break;
                }
                break;
            }
            case PrimKind::Cone: {
                const ConeSoA& c = scene->cones;
                m = intersect_cone(valid, ray.org, ray.dir, ray.tnear, ray.tfar, splat<F>(c.base[i]),
                                   F(c.base_radius[i]), splat<F>(c.apex[i]), F(c.apex_radius[i]), t, u);
                break;
            }
        }
        if (none(m)) return m;
        hit.t = select(m, t, hit.t);
        hit.u = select(m, u, hit.u);
        hit.v = select(m, v, hit.v);
        ray.tfar = select(m, t, ray.tfar);
        for (std::uint32_t bits = mask_bits(m); bits; bits &= bits - 1) hit.prim[std::countr_zero(bits)] = prim;
        return m;
    }
};

}  // namespace raypack
