#pragma once
// Leaf blocks: M primitives of one kind stored as SoA, tested against one
// broadcast ray at once (the 1xM shape of the kernels). Each block keeps the
// scene-global numbers of its primitives. Lanes past the primitive count hold
// NaN, which every kernel reports as a miss, so no lane mask is stored.
#include <cstdint>
#include <span>

#include "accel/primitive_intersector.h"
#include "kernels/cone.h"
#include "kernels/quadratic.h"
#include "kernels/sphere.h"
#include "kernels/triangle.h"
#include "scene/scene.h"

namespace raypack {

/// The kinds of a leaf's blocks; the first three have PrimKind's values.
enum class LeafKind : std::uint8_t { Sphere = 0, Triangle = 1, Cone = 2, Mixed = 3 };
static_assert(int(LeafKind::Sphere) == int(PrimKind::Sphere) && int(LeafKind::Triangle) == int(PrimKind::Triangle) &&
              int(LeafKind::Cone) == int(PrimKind::Cone));

/// What a triangle block stores, fixed at build time by the triangle kernel:
/// Edges for Moeller-Trumbore (p0, p0 - p1, p2 - p0 and their cross product,
/// precomputed exactly as the kernel computes them), Vertices for the others.
enum class TriangleLayout : std::uint8_t { Edges, Vertices };

template <int M>
struct TriangleBlock {
    float p0[3][M];
    float a[3][M];   ///< Edges: p0 - p1; Vertices: p1
    float b[3][M];   ///< Edges: p2 - p0; Vertices: p2
    float ng[3][M];  ///< Edges: (p0 - p1) x (p2 - p0); Vertices: unused
    std::uint32_t prim[M];
};  // total: 52 M bytes (208 for M = 4, 416 for M = 8)
static_assert(sizeof(TriangleBlock<4>) == 208 && sizeof(TriangleBlock<8>) == 416);

template <int M>
struct SphereBlock {
    float center[3][M];
    float radius[M];
    std::uint32_t prim[M];
};  // total: 20 M bytes
static_assert(sizeof(SphereBlock<4>) == 80);

/// Cones as the kernel's ConeLanes, precomputed per cone (make_cone).
template <int M>
struct ConeBlock {
    float base[3][M], w[3][M], mid[3][M];
    float h[M], inv_h[M], k[M], rb[M];
    std::uint32_t prim[M];
};  // total: 56 M bytes
static_assert(sizeof(ConeBlock<4>) == 224);

/// Fill one block from up to M primitives of the block's kind.
template <int M>
void pack_triangles(TriangleBlock<M>& block, std::span<const std::uint32_t> prims, const Scene& scene,
                    TriangleLayout layout);
template <int M>
void pack_spheres(SphereBlock<M>& block, std::span<const std::uint32_t> prims, const Scene& scene);
template <int M>
void pack_cones(ConeBlock<M>& block, std::span<const std::uint32_t> prims, const Scene& scene);

// ---- One broadcast ray against a block -------------------------------------------

/// The ray as the leaf kernels see it, broadcast to M lanes once per ray.
template <class F>
struct LeafRay {
    Vec3<F> org, dir;
    F tnear;
    F dd, inv_dd;  ///< |dir|^2 and its reciprocal, as make_quadric_ray computes them
    WatertightRay<F> watertight;
};

template <class F>
RAYPACK_INLINE LeafRay<F> make_leaf_ray(const Rayf& r, TriangleMethod method) {
    LeafRay<F> l;
    l.org = {F(r.org.x), F(r.org.y), F(r.org.z)};
    l.dir = {F(r.dir.x), F(r.dir.y), F(r.dir.z)};
    l.tnear = F(r.tnear);
    const float dd = fused_dot(r.dir, r.dir);
    l.dd = F(dd);
    l.inv_dd = F(1.0f / dd);
    if (method == TriangleMethod::Watertight) l.watertight = make_watertight_ray<F>(l.org, l.dir);
    return l;
}

template <class F>
RAYPACK_INLINE Vec3<F> load_vec(const float (&p)[3][lanes_of<F>]) {
    return {F::load_unaligned(p[0]), F::load_unaligned(p[1]), F::load_unaligned(p[2])};
}

template <TriangleMethod Method, class F, int M>
RAYPACK_INLINE mask_of<F> intersect_block(const TriangleBlock<M>& b, const LeafRay<F>& r, const F& tfar, F& t, F& u,
                                          F& v) {
    static_assert(lanes_of<F> == M);
    const mask_of<F> all(true);
    const Vec3<F> p0 = load_vec<F>(b.p0), a = load_vec<F>(b.a), c = load_vec<F>(b.b);
    if constexpr (Method == TriangleMethod::Moeller) {
        return intersect_triangle_moeller_edges<F>(all, r.org, r.dir, r.tnear, tfar, p0, a, c, load_vec<F>(b.ng), t, u,
                                                   v);
    } else if constexpr (Method == TriangleMethod::Watertight) {
        return intersect_triangle_watertight<F>(all, r.watertight, r.tnear, tfar, p0, a, c, t, u, v);
    } else {
        return intersect_triangle_plane<F>(all, r.org, r.dir, r.tnear, tfar, p0, a, c, t, u, v);
    }
}

template <class F, int M>
RAYPACK_INLINE mask_of<F> intersect_block(const SphereBlock<M>& b, SphereMethod method, const LeafRay<F>& r,
                                          const F& tfar, F& t) {
    const QuadricRay<F> q{r.org, r.dir, r.tnear, tfar, r.dd, r.inv_dd};
    const Vec3<F> c = load_vec<F>(b.center);
    const F radius = F::load_unaligned(b.radius);
    const mask_of<F> all(true);
    switch (method) {
        case SphereMethod::Algebraic: return intersect_sphere<SphereMethod::Algebraic, F>(all, q, c, radius, t);
        case SphereMethod::Geometric: return intersect_sphere<SphereMethod::Geometric, F>(all, q, c, radius, t);
        case SphereMethod::Precise: break;
    }
    return intersect_sphere<SphereMethod::Precise, F>(all, q, c, radius, t);
}

template <class F, int M>
RAYPACK_INLINE mask_of<F> intersect_block(const ConeBlock<M>& b, const LeafRay<F>& r, const F& tfar, F& t, F& s) {
    const QuadricRay<F> q{r.org, r.dir, r.tnear, tfar, r.dd, r.inv_dd};
    ConeLanes<F> c;
    c.base = load_vec<F>(b.base);
    c.w = load_vec<F>(b.w);
    c.mid = load_vec<F>(b.mid);
    c.h = F::load_unaligned(b.h);
    c.inv_h = F::load_unaligned(b.inv_h);
    c.k = F::load_unaligned(b.k);
    c.rb = F::load_unaligned(b.rb);
    return intersect_cone<F>(mask_of<F>(true), q, c, t, s);
}

}  // namespace raypack
