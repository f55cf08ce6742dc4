#pragma once
// The SIMD width of the renderer's shading loops (point lights over a
// level's points, path vertices) and std::max / std::min in lanes: the
// loops compute the scalar code's bits lane by lane, so they need its
// operand order where a NaN or a signed zero can meet.
#include "kernels/simd.h"
#include "kernels/vec3.h"
#include "render/ray_offset.h"

namespace raypack {

/// The widest lanes this build has.
#if defined(__AVX512BW__)
inline constexpr int kShadeLanes = 16;
#elif defined(__AVX2__)
inline constexpr int kShadeLanes = 8;
#elif defined(__SSE4_2__)
inline constexpr int kShadeLanes = 4;
#else
inline constexpr int kShadeLanes = 1;
#endif

/// std::max(a, b) = a < b ? b : a, lane by lane (vmax(b, a)).
template <class F>
RAYPACK_INLINE F std_max(const F& a, const F& b) {
    return vmax(b, a);
}
/// std::min(a, b) = b < a ? b : a, lane by lane (vmin(b, a)).
template <class F>
RAYPACK_INLINE F std_min(const F& a, const F& b) {
    return vmin(b, a);
}
/// std::max({v.x, v.y, v.z}): the first largest.
template <class F>
RAYPACK_INLINE F max_component_lanes(const Vec3<F>& v) {
    return std_max(std_max(v.x, v.y), v.z);
}

/// The geometric normal g and shading normal sh of surfaces that rays of
/// unit direction `view` arrive at, turned toward the viewer (ng, ns; ns
/// falls back to ng where it is bent past the surface), as the scalar
/// shading turns them. Returns the lanes that met the outward side.
template <class F>
RAYPACK_INLINE auto face_viewer(const Vec3<F>& view, const Vec3<F>& g, const Vec3<F>& sh, Vec3<F>& ng, Vec3<F>& ns) {
    const auto front = dot(view, g) < F(0.0f);
    ng = {select(front, g.x, -g.x), select(front, g.y, -g.y), select(front, g.z, -g.z)};
    ns = {select(front, sh.x, -sh.x), select(front, sh.y, -sh.y), select(front, sh.z, -sh.z)};
    const auto bent = dot(ns, ng) < F(0.0f);
    ns = {select(bent, ng.x, ns.x), select(bent, ng.y, ns.y), select(bent, ng.z, ns.z)};
    return front;
}

/// OrthonormalBasis<float>(n).to_world({lx, ly, lz}) in lanes, bit for bit
/// (Duff et al. 2017, render/sampling.h).
template <class F>
RAYPACK_INLINE Vec3<F> to_world_lanes(const Vec3<F>& n, const F& lx, const F& ly, const F& lz) {
    const F sign = copysign_of(F(1.0f), n.z);
    const F a = F(-1.0f) / (sign + n.z), c = n.x * n.y * a;
    const Vec3<F> t{F(1.0f) + sign * n.x * n.x * a, sign * c, -sign * n.x};
    const Vec3<F> b{c, sign + n.y * n.y * a, -n.y};
    return t * lx + b * ly + n * lz;
}

/// RayOffset::offset in lanes, bit for bit, for the Epsilon and Scaled
/// policies (the robust one moves each coordinate by ULPs: callers keep it
/// scalar).
template <class F>
RAYPACK_INLINE Vec3<F> offset_lanes(const RayOffset& offset, const Vec3<F>& p, const Vec3<F>& n) {
    if (offset.policy() == OffsetPolicy::Epsilon) return p + n * F(1e-4f);
    const F size = max_component_lanes(Vec3<F>{vabs(p.x), vabs(p.y), vabs(p.z)});
    return p + n * (F(1e-4f) * std_max(size, F(1e-3f * offset.scene_extent())));
}

}  // namespace raypack
