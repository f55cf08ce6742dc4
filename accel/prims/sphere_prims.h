#pragma once
// Spheres as a leaf primitive kind: their block, and their test in every
// form a traversal calls (see accel/prims/prim_kinds.h). u = v = 0.
#include <cstdint>
#include <span>

#include "accel/kernel_choice.h"
#include "accel/prims/leaf_common.h"
#include "kernels/ray_packet.h"
#include "kernels/sphere.h"
#include "scene/scene.h"

namespace raypack {

template <int M>
struct SphereBlock {
    float center[3][M];
    float radius[M];
    std::uint32_t prim[M];
};  // total: 20 M bytes
static_assert(sizeof(SphereBlock<4>) == 80);

struct SpherePrims {
    static constexpr PrimKind kind = PrimKind::Sphere;
    template <int M>
    using Block = SphereBlock<M>;

    template <int M>
    static void pack(Block<M>& block, std::span<const std::uint32_t> prims, const Scene& scene, const BlockLayout&);

    template <TriangleMethod, class F, int M>
    static RAYPACK_INLINE mask_of<F> intersect_block(const Block<M>& b, SphereMethod method, const LeafRay<F>& r,
                                                     const F& tfar, F& t, F& u, F& v) {
        const QuadricRay<F> q{r.org, r.dir, r.tnear, tfar, r.dd, r.inv_dd};
        const Vec3<F> c = load_vec<F>(b.center);
        const F radius = F::load_unaligned(b.radius);
        return run<F>(method, mask_of<F>(true), q, c, radius, t, u, v);
    }

    template <TriangleMethod, class F, int M>
    static RAYPACK_INLINE mask_of<F> intersect_slot(const Block<M>& b, int j, SphereMethod method, const LeafRay<F>& r,
                                                    const mask_of<F>& active, const F& tfar, F& t, F& u, F& v) {
        const QuadricRay<F> q{r.org, r.dir, r.tnear, tfar, r.dd, r.inv_dd};
        Vec3<F> c = broadcast_row<F>(b.center, j);
        F radius(b.radius[j]);
        return run<F>(method, active, q, c, radius, t, u, v);
    }

    template <class T>
    static bool intersect(const Scene& scene, std::uint32_t index, const KernelChoice& k, const Ray<T>& ray, T& t,
                          T&, T&) {
        return intersect_sphere(k.sphere, ray, Vec3<T>(scene.spheres.center[index]), T(scene.spheres.radius[index]),
                                t);
    }

    template <class F>
    static RAYPACK_INLINE mask_of<F> intersect(const Scene& scene, std::uint32_t index, const KernelChoice& k,
                                               mask_of<F> valid, const RayLanes<F>& ray, F& t, F&, F&) {
        const Vec3<F> c = splat<F>(scene.spheres.center[index]);
        const F r(scene.spheres.radius[index]);
        switch (k.sphere) {
            case SphereMethod::Algebraic:
                return intersect_sphere_algebraic(valid, ray.org, ray.dir, ray.tnear, ray.tfar, c, r, t);
            case SphereMethod::Geometric:
                return intersect_sphere_geometric(valid, ray.org, ray.dir, ray.tnear, ray.tfar, c, r, t);
            default: break;
        }
        return intersect_sphere_precise(valid, ray.org, ray.dir, ray.tnear, ray.tfar, c, r, t);
    }

private:
    template <class F>
    static RAYPACK_INLINE mask_of<F> run(SphereMethod method, const mask_of<F>& valid, const QuadricRay<F>& q,
                                         const Vec3<F>& c, const F& radius, F& t, F& u, F& v) {
        u = v = F(0.0f);
        switch (method) {
            case SphereMethod::Algebraic: return intersect_sphere<SphereMethod::Algebraic, F>(valid, q, c, radius, t);
            case SphereMethod::Geometric: return intersect_sphere<SphereMethod::Geometric, F>(valid, q, c, radius, t);
            case SphereMethod::Precise: break;
        }
        return intersect_sphere<SphereMethod::Precise, F>(valid, q, c, radius, t);
    }
};

}  // namespace raypack
