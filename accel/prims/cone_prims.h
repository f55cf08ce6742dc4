#pragma once
// Cones (truncated, open: NFF's `c`) as a leaf primitive kind: their block,
// and their test in every form a traversal calls (see
// accel/prims/prim_kinds.h). u is the kernel's axial parameter s, v = 0.
#include <cstdint>
#include <span>

#include "accel/kernel_choice.h"
#include "accel/prims/leaf_common.h"
#include "kernels/cone.h"
#include "kernels/ray_packet.h"
#include "scene/scene.h"

namespace raypack {

/// Cones as the kernel's ConeLanes, precomputed per cone (make_cone).
template <int M>
struct ConeBlock {
    float base[3][M], w[3][M], mid[3][M];
    float h[M], inv_h[M], k[M], rb[M];
    std::uint32_t prim[M];
};  // total: 56 M bytes
static_assert(sizeof(ConeBlock<4>) == 224);

struct ConePrims {
    static constexpr PrimKind kind = PrimKind::Cone;
    template <int M>
    using Block = ConeBlock<M>;

    template <int M>
    static void pack(Block<M>& block, std::span<const std::uint32_t> prims, const Scene& scene, const BlockLayout&);

    template <TriangleMethod, class F, int M>
    static RAYPACK_INLINE mask_of<F> intersect_block(const Block<M>& b, SphereMethod, const LeafRay<F>& r,
                                                     const F& tfar, F& t, F& u, F& v) {
        const QuadricRay<F> q{r.org, r.dir, r.tnear, tfar, r.dd, r.inv_dd};
        ConeLanes<F> c;
        c.base = load_vec<F>(b.base);
        c.w = load_vec<F>(b.w);
        c.mid = load_vec<F>(b.mid);
        c.h = F::load_unaligned(b.h);
        c.inv_h = F::load_unaligned(b.inv_h);
        c.k = F::load_unaligned(b.k);
        c.rb = F::load_unaligned(b.rb);
        v = F(0.0f);
        return intersect_cone<F>(mask_of<F>(true), q, c, t, u);
    }

    template <TriangleMethod, class F, int M>
    static RAYPACK_INLINE mask_of<F> intersect_slot(const Block<M>& b, int j, SphereMethod, const LeafRay<F>& r,
                                                    const mask_of<F>& active, const F& tfar, F& t, F& u, F& v) {
        const QuadricRay<F> q{r.org, r.dir, r.tnear, tfar, r.dd, r.inv_dd};
        ConeLanes<F> c;
        c.base = broadcast_row<F>(b.base, j);
        c.w = broadcast_row<F>(b.w, j);
        c.mid = broadcast_row<F>(b.mid, j);
        c.h = F(b.h[j]);
        c.inv_h = F(b.inv_h[j]);
        c.k = F(b.k[j]);
        c.rb = F(b.rb[j]);
        v = F(0.0f);
        return intersect_cone<F>(active, q, c, t, u);
    }

    template <class T>
    static bool intersect(const Scene& scene, std::uint32_t index, const KernelChoice&, const Ray<T>& ray, T& t, T& u,
                          T&) {
        const ConeSoA& c = scene.cones;
        return intersect_cone(ray, Vec3<T>(c.base[index]), T(c.base_radius[index]), Vec3<T>(c.apex[index]),
                              T(c.apex_radius[index]), t, u);
    }

    template <class F>
    static RAYPACK_INLINE mask_of<F> intersect(const Scene& scene, std::uint32_t index, const KernelChoice&,
                                               mask_of<F> valid, const RayLanes<F>& ray, F& t, F& u, F&) {
        const ConeSoA& c = scene.cones;
        return intersect_cone(valid, ray.org, ray.dir, ray.tnear, ray.tfar, splat<F>(c.base[index]),
                              F(c.base_radius[index]), splat<F>(c.apex[index]), F(c.apex_radius[index]), t, u);
    }
};

}  // namespace raypack
