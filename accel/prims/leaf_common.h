#pragma once
// What every primitive kind's leaf intersector (accel/prims/*_prims.h)
// shares: the ray as leaves see it, one ray broadcast to the M lanes of a
// block (1 x M) or K rays in lanes against one primitive of a block (K x 1),
// computed once per ray or packet; the block layout a build chooses; lane
// helpers. Blocks are SoA; lanes past the primitive count hold NaN, which
// every kernel reports as a miss, and prim = kNoPrim.
#include <cstdint>
#include <limits>

#include "kernels/simd.h"
#include "kernels/triangle.h"
#include "kernels/vec3.h"

namespace raypack {

/// What a triangle block stores, fixed at build time by the triangle kernel:
/// Edges for Moeller-Trumbore (p0, p0 - p1, p2 - p0 and their cross product,
/// precomputed exactly as the kernel computes them), Vertices for the others.
enum class TriangleLayout : std::uint8_t { Edges, Vertices };

struct ObjectAccels;

/// Build-time choices of the block layouts, and the structures instance
/// blocks point to.
struct BlockLayout {
    TriangleLayout triangles = TriangleLayout::Edges;
    const ObjectAccels* objects = nullptr;
};

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

/// Row j of an SoA block field, broadcast to every lane (the K x 1 form).
template <class F, int M>
RAYPACK_INLINE Vec3<F> broadcast_row(const float (&p)[3][M], int j) {
    return {F(p[0][j]), F(p[1][j]), F(p[2][j])};
}

/// An SoA block field as lanes (the 1 x M form).
template <class F>
RAYPACK_INLINE Vec3<F> load_vec(const float (&p)[3][lanes_of<F>]) {
    return {F::load_unaligned(p[0]), F::load_unaligned(p[1]), F::load_unaligned(p[2])};
}

/// A 3-vector broadcast to every lane.
template <class F>
RAYPACK_INLINE Vec3<F> splat(const Vec3f& p) {
    return {F(p.x), F(p.y), F(p.z)};
}

// ---- Filling blocks (cold: the build) ----------------------------------------

inline constexpr float kBlockPadding = std::numeric_limits<float>::quiet_NaN();

template <int M>
void set_row(float (&a)[3][M], int lane, const Vec3f& p) {
    a[0][lane] = p.x;
    a[1][lane] = p.y;
    a[2][lane] = p.z;
}

template <int M>
void fill_rows(float (&a)[3][M], float value) {
    for (auto& row : a)
        for (float& x : row) x = value;
}

}  // namespace raypack
