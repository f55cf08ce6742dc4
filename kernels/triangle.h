#pragma once
// Ray-triangle tests, two-sided, written once for every lane type (see
// kernels/simd.h): K rays against one triangle (ray fields in lanes, vertices
// broadcast) or one ray against M triangles stored as SoA (the other way
// round). (u, v) are the barycentric weights of vertices p1 and p2: the hit
// point is (1-u-v) p0 + u p1 + v p2.
//
// Every kernel takes the active lanes first and returns the lanes hit with
// tnear <= t <= tfar; t, u, v are defined on those lanes only. The mask
// narrows as the tests go and the kernel returns as soon as no lane is left,
// so width 1 keeps the early exits of the scalar code. Lane i computes exactly
// the operations width 1 computes (vfmadd is a fused multiply-add at every
// width), so packets and single rays agree bit for bit.
#include <bit>
#include <cstdint>
#include <limits>
#include <type_traits>

#include "kernels/ray.h"
#include "kernels/fused.h"
#include "kernels/simd.h"

namespace raypack {

enum class TriangleMethod { Moeller, Watertight, Plane };

namespace triangle_detail {

/// The sign bit of s alone (+0 or -0 per lane).
template <class F>
RAYPACK_INLINE F sign_bit(const F& s) {
    if constexpr (std::is_same_v<F, float>) {
        return std::bit_cast<float>(std::bit_cast<std::uint32_t>(s) & 0x80000000u);
    } else if constexpr (std::is_same_v<F, double>) {
        return std::bit_cast<double>(std::bit_cast<std::uint64_t>(s) & 0x8000000000000000u);
    } else {
        return s & F(-0.0f);
    }
}

/// x with its sign flipped where `sign` (from sign_bit) is -0: x * sign(s), exactly.
template <class F>
RAYPACK_INLINE F flip_sign(const F& x, const F& sign) {
    if constexpr (std::is_same_v<F, float>) {
        return std::bit_cast<float>(std::bit_cast<std::uint32_t>(x) ^ std::bit_cast<std::uint32_t>(sign));
    } else if constexpr (std::is_same_v<F, double>) {
        return std::bit_cast<double>(std::bit_cast<std::uint64_t>(x) ^ std::bit_cast<std::uint64_t>(sign));
    } else {
        return x ^ sign;
    }
}

/// The least |det| a kernel divides by: the smallest normal number, so that
/// 1/det is finite; a smaller determinant counts as zero.
template <class F>
inline constexpr auto kMinDet = std::numeric_limits<std::conditional_t<std::is_same_v<F, double>, double, float>>::min();

}  // namespace triangle_detail

/// A Moeller hit's u and v before their division by det. The test itself
/// needs only t, so the two products that make u and v are left to whoever
/// keeps the hit, to be done once for the hit that ends up closest (Embree's
/// MoellerTrumboreHitM::finalize defers them the same way); u() and v() are
/// the kernel's u and v bit for bit.
template <class F>
struct MoellerUV {
    F U, V, inv_det;
    RAYPACK_INLINE F u() const { return U * inv_det; }
    RAYPACK_INLINE F v() const { return V * inv_det; }
};

/// Moeller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection",
/// JGT 1997. With tvec = o - p0, pvec = d x e2 and qvec = tvec x e1, MT's
/// quantities are det = e1 . pvec, U = tvec . pvec, V = d . qvec,
/// T = e2 . qvec, and (t, u, v) = (T, U, V) / det. By the triple-product
/// identities they are, as Embree groups them (MoellerTrumboreIntersector),
///   det = d . ng,  U = e2 . s,  V = -e1 . s,  T = -tvec . ng,
/// with ng = e2 x e1 per triangle and s = d x (p0 - o) per ray: one cross
/// product per test instead of two. Two-sided: the edge tests compare the
/// undivided U, V (sign of det folded in) against |det|. A determinant below
/// the smallest normal float (ray parallel to the plane, degenerate
/// triangle) is a miss, and so is any lane where a quantity is NaN.
///
/// Up to width 8 the division comes last, for the lanes that passed the
/// edge tests, and the kernel returns early when none did. At width 16
/// (kMaskRegisters) a packet rarely fails as a whole while each compare
/// costs as much as a multiply, so the kernel runs straight through: the
/// division issues first, being the longest in latency, and three of the
/// edge conditions (U, V >= 0, |det| >= the least normal) fold into one
/// compare of their least margin. Every width computes the same values and
/// the same hits.
///
/// This is the per-ray part, with u, v deferred, for triangles stored with
/// their edges e1n = p0 - p1, e2 = p2 - p0 and ng = fused_cross(e1n, e2)
/// (fused_cross, so that the results are the same bit for bit; see
/// triangle_detail::moeller_edges). `uv` is defined wherever the result is.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_moeller_deferred(mask_of<F> valid, const Vec3<F>& org,
                                                              const Vec3<F>& dir, const F& tnear, const F& tfar,
                                                              const Vec3<F>& p0, const Vec3<F>& e1n,
                                                              const Vec3<F>& e2, const Vec3<F>& ng, F& t,
                                                              MoellerUV<F>& uv) {
    using namespace triangle_detail;
    const Vec3<F> w = p0 - org;  // -tvec
    const F det = fused_dot(dir, ng);
    if constexpr (kMaskRegisters<F>) {
        uv.inv_det = F(1) / det;
        t = fused_dot(w, ng) * uv.inv_det;
    }
    const Vec3<F> s = fused_cross(dir, w);  // tvec x d
    const F U = fused_dot(e2, s);
    const F V = fused_dot(e1n, s);
    const F sign = sign_bit(det), abs_det = vabs(det);
    const F Us = flip_sign(U, sign), Vs = flip_sign(V, sign);
    if constexpr (kMaskRegisters<F>) {
        uv.U = U;
        uv.V = V;
        // The margins' least is >= 0 exactly when each is (a difference of
        // floats has the sign of the exact one). vmin may drop a NaN of U or
        // V, but then Us + Vs is NaN and fails its own compare.
        const F margin = vmin(vmin(Us, Vs), abs_det - F(kMinDet<F>));
        return valid & (margin >= F(0)) & (Us + Vs <= abs_det) & (t >= tnear) & (t <= tfar);
    } else {
        valid = valid & (abs_det >= F(kMinDet<F>)) & (Us >= F(0)) & (Vs >= F(0)) & (Us + Vs <= abs_det);
        if (none(valid)) return valid;
        const F T = fused_dot(w, ng);
        uv = {U, V, F(1) / det};
        t = T * uv.inv_det;
        return valid & (t >= tnear) & (t <= tfar);
    }
}

/// intersect_triangle_moeller_deferred with u and v made at once (only when
/// some lane hit).
template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_moeller_edges(mask_of<F> valid, const Vec3<F>& org,
                                                           const Vec3<F>& dir, const F& tnear, const F& tfar,
                                                           const Vec3<F>& p0, const Vec3<F>& e1n,
                                                           const Vec3<F>& e2, const Vec3<F>& ng, F& t, F& u,
                                                           F& v) {
    MoellerUV<F> uv;
    valid = intersect_triangle_moeller_deferred<F>(valid, org, dir, tnear, tfar, p0, e1n, e2, ng, t, uv);
    if (none(valid)) return valid;
    u = uv.u();
    v = uv.v();
    return valid;
}

/// The whole test, per-triangle part included, with u, v deferred ...
/// The edges stay separate values here: as one aggregate (9 vectors, 576
/// bytes at width 16) gcc kept them in memory and stored them again on
/// every iteration of the callers' loops, which, depending on the build's
/// layout, made triangle/moeller/4 up to 5x slower.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_moeller(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                                     const F& tnear, const F& tfar, const Vec3<F>& p0,
                                                     const Vec3<F>& p1, const Vec3<F>& p2, F& t, MoellerUV<F>& uv) {
    const Vec3<F> e1n = p0 - p1, e2 = p2 - p0;  // triangle_detail::moeller_edges
    return intersect_triangle_moeller_deferred<F>(valid, org, dir, tnear, tfar, p0, e1n, e2, fused_cross(e1n, e2), t,
                                                  uv);
}

/// ... or with u, v made at once.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_moeller(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                                     const F& tnear, const F& tfar, const Vec3<F>& p0,
                                                     const Vec3<F>& p1, const Vec3<F>& p2, F& t, F& u, F& v) {
    const Vec3<F> e1n = p0 - p1, e2 = p2 - p0;
    return intersect_triangle_moeller_edges<F>(valid, org, dir, tnear, tfar, p0, e1n, e2, fused_cross(e1n, e2), t, u,
                                               v);
}

namespace triangle_detail {

/// Moeller's per-triangle part, for triangles stored with their edges: the
/// values intersect_triangle_moeller computes from the vertices.
template <class F>
struct MoellerEdges {
    Vec3<F> e1n, e2, ng;
};
template <class F>
MoellerEdges<F> moeller_edges(const Vec3<F>& p0, const Vec3<F>& p1, const Vec3<F>& p2) {
    const Vec3<F> e1n = p0 - p1;  // -e1
    const Vec3<F> e2 = p2 - p0;
    return {e1n, e2, fused_cross(e1n, e2)};  // ng = e2 x e1
}

}  // namespace triangle_detail

/// Per-ray part of the watertight test (Woop, Benthin & Wald, "Watertight
/// Ray/Triangle Intersection", JCGT 2(1) 2013): kz = argmax |d|, kx and ky
/// the next two axes, and the shear that maps d to (0, 0, 1) in that frame.
/// The axis is kept as masks, so that it may differ per lane, and as a number
/// when all lanes share it (always at width 1 and for a broadcast ray), which
/// lets the test read the components directly instead of selecting them.
/// The paper also swaps kx and ky when d[kz] < 0, to keep the winding for
/// backface culling; in a two-sided test the swap negates U, V, W, det and T
/// exactly and changes no result, so it is left out.
template <class F>
struct WatertightRay {
    Vec3<F> org;
    mask_of<F> kz_x, kz_y;  // kz is x, is y, else z
    int kz = -1;            // kz of every lane, or -1 if they differ
    F neg_sx, neg_sy, sz;   // -d[kx]/d[kz], -d[ky]/d[kz], 1/d[kz]
};

namespace triangle_detail {

/// p in the frame (kx, ky, kz), kz given per lane by the masks.
template <class F>
RAYPACK_INLINE Vec3<F> to_ray_axes(const mask_of<F>& kz_x, const mask_of<F>& kz_y, const Vec3<F>& p) {
    return {select(kz_x, p.y, select(kz_y, p.z, p.x)), select(kz_x, p.z, select(kz_y, p.x, p.y)),
            select(kz_x, p.x, select(kz_y, p.y, p.z))};
}

/// p in the frame (kx, ky, kz) for kz = Z in every lane.
template <int Z, class F>
RAYPACK_INLINE Vec3<F> to_ray_axes(const Vec3<F>& p) {
    return {p[(Z + 1) % 3], p[(Z + 2) % 3], p[Z]};
}

/// The watertight test once the vertices a, b, c are relative to the ray
/// origin and in the ray's axes: shear, 2D edge functions U, V, W (weights
/// of p0, p1, p2), the sign test, and t. The edge functions are plain
/// products and differences, with no fused operation, so an edge shared by
/// two triangles gets the same value up to sign in both and no ray slips
/// between them. Lanes where one is exactly zero recompute all three in
/// double, as the paper does (products of floats are exact in double); such
/// lanes are rare, so they are done one at a time.
template <class F>
RAYPACK_INLINE mask_of<F> watertight_in_ray_axes(mask_of<F> valid, const WatertightRay<F>& ray, const F& tnear,
                                                 const F& tfar, const Vec3<F>& a, const Vec3<F>& b,
                                                 const Vec3<F>& c, F& t, F& u, F& v) {
    const F ax = vfmadd(ray.neg_sx, a.z, a.x), ay = vfmadd(ray.neg_sy, a.z, a.y);
    const F bx = vfmadd(ray.neg_sx, b.z, b.x), by = vfmadd(ray.neg_sy, b.z, b.y);
    const F cx = vfmadd(ray.neg_sx, c.z, c.x), cy = vfmadd(ray.neg_sy, c.z, c.y);
    F U = cx * by - cy * bx;
    F V = ax * cy - ay * cx;
    F W = bx * ay - by * ax;
    const mask_of<F> zero = valid & ((U == F(0)) | (V == F(0)) | (W == F(0)));
    if (any(zero)) [[unlikely]] {
        using S = std::conditional_t<std::is_same_v<F, double>, long double, double>;
        auto edge = [](auto px, auto py, auto qx, auto qy) { return S(qx) * S(py) - S(qy) * S(px); };
        if constexpr (lanes_of<F> == 1) {
            U = F(edge(bx, by, cx, cy));
            V = F(edge(cx, cy, ax, ay));
            W = F(edge(ax, ay, bx, by));
        } else {
            alignas(64) float l[9][lanes_of<F>];
            const F* in[9] = {&ax, &ay, &bx, &by, &cx, &cy, &U, &V, &W};
            for (int k = 0; k < 9; ++k) in[k]->store_aligned(l[k]);
            for (std::uint32_t bits = mask_bits(zero); bits != 0; bits &= bits - 1) {
                const int i = std::countr_zero(bits);
                l[6][i] = float(edge(l[2][i], l[3][i], l[4][i], l[5][i]));
                l[7][i] = float(edge(l[4][i], l[5][i], l[0][i], l[1][i]));
                l[8][i] = float(edge(l[0][i], l[1][i], l[2][i], l[3][i]));
            }
            U = F::load_aligned(l[6]);
            V = F::load_aligned(l[7]);
            W = F::load_aligned(l[8]);
        }
    }
    // Two-sided: a hit when the edge functions do not have mixed signs.
    valid = valid & ((vmin(vmin(U, V), W) >= F(0)) | (vmax(vmax(U, V), W) <= F(0)));
    const F det = U + V + W;
    valid = valid & (vabs(det) >= F(kMinDet<F>));
    if (none(valid)) return valid;
    const F T = vfmadd(U, ray.sz * a.z, vfmadd(V, ray.sz * b.z, W * (ray.sz * c.z)));
    const F inv_det = F(1) / det;
    t = T * inv_det;
    valid = valid & (t >= tnear) & (t <= tfar);
    u = V * inv_det;
    v = W * inv_det;
    return valid;
}

}  // namespace triangle_detail

template <class F>
RAYPACK_INLINE WatertightRay<F> make_watertight_ray(const Vec3<F>& org, const Vec3<F>& dir) {
    const F ax = vabs(dir.x), ay = vabs(dir.y), az = vabs(dir.z);
    WatertightRay<F> r;
    r.org = org;
    // kz: the largest |d| component, the first one on ties.
    r.kz_x = (ax >= ay) & (ax >= az);
    r.kz_y = (ay > ax) & (ay >= az);
    const std::uint32_t all = (1u << lanes_of<F>) - 1u, bx = mask_bits(r.kz_x), by = mask_bits(r.kz_y);
    r.kz = bx == all ? 0 : by == all ? 1 : (bx | by) == 0 ? 2 : -1;
    const Vec3<F> d = triangle_detail::to_ray_axes(r.kz_x, r.kz_y, dir);
    r.sz = F(1) / d.z;
    r.neg_sx = -(d.x * r.sz);
    r.neg_sy = -(d.y * r.sz);
    return r;
}

/// The watertight test on a precomputed ray.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_watertight(mask_of<F> valid, const WatertightRay<F>& ray,
                                                        const F& tnear, const F& tfar, const Vec3<F>& p0,
                                                        const Vec3<F>& p1, const Vec3<F>& p2, F& t, F& u, F& v) {
    using namespace triangle_detail;
    const Vec3<F> a = p0 - ray.org, b = p1 - ray.org, c = p2 - ray.org;
    switch (ray.kz) {
        case 0: return watertight_in_ray_axes(valid, ray, tnear, tfar, to_ray_axes<0>(a), to_ray_axes<0>(b),
                                              to_ray_axes<0>(c), t, u, v);
        case 1: return watertight_in_ray_axes(valid, ray, tnear, tfar, to_ray_axes<1>(a), to_ray_axes<1>(b),
                                              to_ray_axes<1>(c), t, u, v);
        case 2: return watertight_in_ray_axes(valid, ray, tnear, tfar, to_ray_axes<2>(a), to_ray_axes<2>(b),
                                              to_ray_axes<2>(c), t, u, v);
        default:
            return watertight_in_ray_axes(valid, ray, tnear, tfar, to_ray_axes(ray.kz_x, ray.kz_y, a),
                                          to_ray_axes(ray.kz_x, ray.kz_y, b), to_ray_axes(ray.kz_x, ray.kz_y, c), t,
                                          u, v);
    }
}

template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_watertight(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                                        const F& tnear, const F& tfar, const Vec3<F>& p0,
                                                        const Vec3<F>& p1, const Vec3<F>& p2, F& t, F& u, F& v) {
    return intersect_triangle_watertight<F>(valid, make_watertight_ray(org, dir), tnear, tfar, p0, p1, p2, t, u, v);
}

/// Plane intersection followed by an inside test: t from the plane equation,
/// then the hit point's barycentrics against the edge planes e2 x n and
/// n x e1, which depend on the triangle alone (Havel & Herout, "Yet Faster
/// Ray-Triangle Intersection (Using SSE4)", IEEE TVCG 2010, who store them
/// divided by |n|^2; here the inside test compares the undivided values
/// with |n|^2, and u, v are divided once at the end). A ray parallel to the
/// plane, or a degenerate triangle, is a miss.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_plane(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                                   const F& tnear, const F& tfar, const Vec3<F>& p0,
                                                   const Vec3<F>& p1, const Vec3<F>& p2, F& t, F& u, F& v) {
    using namespace triangle_detail;
    const Vec3<F> e1 = p1 - p0;
    const Vec3<F> e2 = p2 - p0;
    const Vec3<F> n = fused_cross(e1, e2);
    const F nn = fused_dot(n, n);
    const Vec3<F> n1 = fused_cross(e2, n), n2 = fused_cross(n, e1);
    const F denom = fused_dot(n, dir);
    const Vec3<F> w = p0 - org;
    t = fused_dot(n, w) / denom;
    valid = valid & (vabs(denom) >= F(kMinDet<F>)) & (t >= tnear) & (t <= tfar);
    if (none(valid)) return valid;
    // q = o + t d - p0, the hit point relative to p0; q = U e1 + V e2 with
    // U = q . n1 / |n|^2, V = q . n2 / |n|^2.
    const Vec3<F> q{vfmsub(dir.x, t, w.x), vfmsub(dir.y, t, w.y), vfmsub(dir.z, t, w.z)};
    const F U = fused_dot(q, n1), V = fused_dot(q, n2);
    valid = valid & (U >= F(0)) & (V >= F(0)) & (U + V <= nn);
    const F inv_nn = F(1) / nn;
    u = U * inv_nn;
    v = V * inv_nn;
    return valid;
}

// ---- Scalar entry points (one ray, one triangle; T = float or double) -------
// Outputs change only on a hit.

template <class T>
bool intersect_triangle_moeller(const Ray<T>& ray, const Vec3<T>& p0, const Vec3<T>& p1, const Vec3<T>& p2,
                                T& t, T& u, T& v) {
    T tt, uu, vv;
    if (!intersect_triangle_moeller<T>(true, ray.org, ray.dir, ray.tnear, ray.tfar, p0, p1, p2, tt, uu, vv))
        return false;
    t = tt, u = uu, v = vv;
    return true;
}

template <class T>
bool intersect_triangle_watertight(const Ray<T>& ray, const Vec3<T>& p0, const Vec3<T>& p1, const Vec3<T>& p2,
                                   T& t, T& u, T& v) {
    T tt, uu, vv;
    if (!intersect_triangle_watertight<T>(true, ray.org, ray.dir, ray.tnear, ray.tfar, p0, p1, p2, tt, uu, vv))
        return false;
    t = tt, u = uu, v = vv;
    return true;
}

template <class T>
bool intersect_triangle_plane(const Ray<T>& ray, const Vec3<T>& p0, const Vec3<T>& p1, const Vec3<T>& p2,
                              T& t, T& u, T& v) {
    T tt, uu, vv;
    if (!intersect_triangle_plane<T>(true, ray.org, ray.dir, ray.tnear, ray.tfar, p0, p1, p2, tt, uu, vv))
        return false;
    t = tt, u = uu, v = vv;
    return true;
}

template <class T>
bool intersect_triangle(TriangleMethod method, const Ray<T>& ray, const Vec3<T>& p0, const Vec3<T>& p1,
                        const Vec3<T>& p2, T& t, T& u, T& v) {
    switch (method) {
        case TriangleMethod::Moeller: return intersect_triangle_moeller(ray, p0, p1, p2, t, u, v);
        case TriangleMethod::Watertight: return intersect_triangle_watertight(ray, p0, p1, p2, t, u, v);
        case TriangleMethod::Plane: return intersect_triangle_plane(ray, p0, p1, p2, t, u, v);
    }
    return false;
}

}  // namespace raypack
