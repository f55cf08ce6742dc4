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
#include <type_traits>

#include "kernels/ray.h"
#include "kernels/simd.h"

namespace raypack {

enum class TriangleMethod { Moeller, Watertight, Plane };

namespace triangle_detail {

/// a x b, each component one product and one fused multiply-subtract.
template <class F>
RAYPACK_INLINE Vec3<F> fcross(const Vec3<F>& a, const Vec3<F>& b) {
    return {vfmsub(a.y, b.z, a.z * b.y), vfmsub(a.z, b.x, a.x * b.z), vfmsub(a.x, b.y, a.y * b.x)};
}

/// a . b as one product and two fused multiply-adds.
template <class F>
RAYPACK_INLINE F fdot(const Vec3<F>& a, const Vec3<F>& b) {
    return vfmadd(a.x, b.x, vfmadd(a.y, b.y, a.z * b.z));
}

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

}  // namespace triangle_detail

/// Moeller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection",
/// JGT 1997. With tvec = o - p0, pvec = d x e2 and qvec = tvec x e1, MT's
/// quantities are det = e1 . pvec, U = tvec . pvec, V = d . qvec,
/// T = e2 . qvec, and (t, u, v) = (T, U, V) / det. By the triple-product
/// identities they are, as Embree groups them (MoellerTrumboreIntersector),
///   det = d . ng,  U = e2 . s,  V = -e1 . s,  T = -tvec . ng,
/// with ng = e2 x e1 per triangle and s = d x (p0 - o) per ray: one cross
/// product per test instead of two. Two-sided: the edge tests compare the
/// undivided U, V (sign of det folded in) against |det|, and the one
/// division comes last, for the lanes that passed them. A zero determinant
/// (ray parallel to the plane, degenerate triangle) is a miss.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_moeller(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                                     const F& tnear, const F& tfar, const Vec3<F>& p0,
                                                     const Vec3<F>& p1, const Vec3<F>& p2, F& t, F& u, F& v) {
    using namespace triangle_detail;
    const Vec3<F> e1n = p0 - p1;  // -e1
    const Vec3<F> e2 = p2 - p0;
    const Vec3<F> ng = fcross(e1n, e2);  // e2 x e1
    const Vec3<F> w = p0 - org;          // -tvec
    const Vec3<F> s = fcross(dir, w);    // tvec x d
    const F det = fdot(dir, ng);
    const F U = fdot(e2, s);
    const F V = fdot(e1n, s);
    const F sign = sign_bit(det), abs_det = vabs(det);
    const F Us = flip_sign(U, sign), Vs = flip_sign(V, sign);
    valid = valid & (abs_det > F(0)) & (Us >= F(0)) & (Vs >= F(0)) & (Us + Vs <= abs_det);
    if (none(valid)) return valid;
    const F T = fdot(w, ng);
    const F inv_det = F(1) / det;
    t = T * inv_det;
    valid = valid & (t >= tnear) & (t <= tfar);
    u = U * inv_det;
    v = V * inv_det;
    return valid;
}

/// Per-ray part of the watertight test (Woop, Benthin & Wald, "Watertight
/// Ray/Triangle Intersection", JCGT 2(1) 2013): kz = argmax |d|, kx and ky the
/// next axes (swapped when d[kz] < 0, to keep the winding), and the shear
/// that maps d to (0, 0, 1) in the permuted frame. The permutation is kept as
/// masks, so it may differ per lane.
template <class F>
struct WatertightRay {
    Vec3<F> org;
    mask_of<F> kx_x, kx_y, ky_x, ky_y, kz_x, kz_y;  // axis k is x, is y, else z
    F neg_sx, neg_sy, sz;                            // -d[kx]/d[kz], -d[ky]/d[kz], 1/d[kz]
};

template <class F>
RAYPACK_INLINE WatertightRay<F> make_watertight_ray(const Vec3<F>& org, const Vec3<F>& dir) {
    const F ax = vabs(dir.x), ay = vabs(dir.y), az = vabs(dir.z);
    const mask_of<F> zx = (ax >= ay) & (ax >= az);
    const mask_of<F> not_zx = !zx;
    const mask_of<F> zy = not_zx & (ay >= az);
    const mask_of<F> not_zy = !zy;
    const mask_of<F> zz = not_zx & not_zy;
    const F dkz = select(zx, dir.x, select(zy, dir.y, dir.z));
    const mask_of<F> neg = dkz < F(0), pos = !neg;
    WatertightRay<F> r;
    r.org = org;
    r.kz_x = zx;
    r.kz_y = zy;
    // kz = x: (kx, ky) = (y, z), swapped (z, y); kz = y: (z, x) / (x, z); kz = z: (x, y) / (y, x).
    r.kx_x = (zz & pos) | (zy & neg);
    r.kx_y = (zx & pos) | (zz & neg);
    r.ky_x = (zy & pos) | (zz & neg);
    r.ky_y = (zz & pos) | (zx & neg);
    const F dkx = select(r.kx_x, dir.x, select(r.kx_y, dir.y, dir.z));
    const F dky = select(r.ky_x, dir.x, select(r.ky_y, dir.y, dir.z));
    r.sz = F(1) / dkz;
    r.neg_sx = -(dkx * r.sz);
    r.neg_sy = -(dky * r.sz);
    return r;
}

/// The watertight test on a precomputed ray. Vertices are translated to the
/// ray origin, permuted and sheared; the 2D edge functions U, V, W (weights
/// of p0, p1, p2) are plain products and differences, with no fused
/// operation, so an edge shared by two triangles gets the same value up to
/// sign in both and no ray slips between them. Lanes where an edge function
/// is exactly zero recompute all three in double, as the paper does
/// (products of floats are exact in double); the lanes that need it are rare,
/// so they are done one at a time.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_watertight(mask_of<F> valid, const WatertightRay<F>& ray,
                                                        const F& tnear, const F& tfar, const Vec3<F>& p0,
                                                        const Vec3<F>& p1, const Vec3<F>& p2, F& t, F& u, F& v) {
    const Vec3<F> a = p0 - ray.org, b = p1 - ray.org, c = p2 - ray.org;
    auto pick = [](const Vec3<F>& p, const mask_of<F>& is_x, const mask_of<F>& is_y) {
        return select(is_x, p.x, select(is_y, p.y, p.z));
    };
    const F akz = pick(a, ray.kz_x, ray.kz_y), bkz = pick(b, ray.kz_x, ray.kz_y), ckz = pick(c, ray.kz_x, ray.kz_y);
    const F ax = vfmadd(ray.neg_sx, akz, pick(a, ray.kx_x, ray.kx_y));
    const F ay = vfmadd(ray.neg_sy, akz, pick(a, ray.ky_x, ray.ky_y));
    const F bx = vfmadd(ray.neg_sx, bkz, pick(b, ray.kx_x, ray.kx_y));
    const F by = vfmadd(ray.neg_sy, bkz, pick(b, ray.ky_x, ray.ky_y));
    const F cx = vfmadd(ray.neg_sx, ckz, pick(c, ray.kx_x, ray.kx_y));
    const F cy = vfmadd(ray.neg_sy, ckz, pick(c, ray.ky_x, ray.ky_y));
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
    // Two-sided: a miss when the edge functions have mixed signs.
    valid = valid & !((vmin(vmin(U, V), W) < F(0)) & (vmax(vmax(U, V), W) > F(0)));
    const F det = U + V + W;
    valid = valid & (vabs(det) > F(0));
    if (none(valid)) return valid;
    const F T = vfmadd(U, ray.sz * akz, vfmadd(V, ray.sz * bkz, W * (ray.sz * ckz)));
    const F inv_det = F(1) / det;
    t = T * inv_det;
    valid = valid & (t >= tnear) & (t <= tfar);
    u = V * inv_det;
    v = W * inv_det;
    return valid;
}

template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_watertight(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                                        const F& tnear, const F& tfar, const Vec3<F>& p0,
                                                        const Vec3<F>& p1, const Vec3<F>& p2, F& t, F& u, F& v) {
    return intersect_triangle_watertight<F>(valid, make_watertight_ray(org, dir), tnear, tfar, p0, p1, p2, t, u, v);
}

/// Plane intersection followed by an inside test: t from the plane equation,
/// then the hit point's barycentrics against the edge planes n1 = e2 x n / |n|^2
/// and n2 = n x e1 / |n|^2, which depend on the triangle alone (Havel & Herout,
/// "Yet Faster Ray-Triangle Intersection (Using SSE4)", IEEE TVCG 2010).
/// A ray parallel to the plane, or a degenerate triangle, is a miss.
template <class F>
RAYPACK_INLINE mask_of<F> intersect_triangle_plane(mask_of<F> valid, const Vec3<F>& org, const Vec3<F>& dir,
                                                   const F& tnear, const F& tfar, const Vec3<F>& p0,
                                                   const Vec3<F>& p1, const Vec3<F>& p2, F& t, F& u, F& v) {
    using namespace triangle_detail;
    const Vec3<F> e1 = p1 - p0;
    const Vec3<F> e2 = p2 - p0;
    const Vec3<F> n = fcross(e1, e2);
    const F inv_nn = F(1) / fdot(n, n);
    const Vec3<F> n1 = fcross(e2, n) * inv_nn;
    const Vec3<F> n2 = fcross(n, e1) * inv_nn;
    const F denom = fdot(n, dir);
    const Vec3<F> w = p0 - org;
    t = fdot(n, w) / denom;
    valid = valid & (vabs(denom) > F(0)) & (t >= tnear) & (t <= tfar);
    if (none(valid)) return valid;
    // q = o + t d - p0, the hit point relative to p0.
    const Vec3<F> q{vfmsub(dir.x, t, w.x), vfmsub(dir.y, t, w.y), vfmsub(dir.z, t, w.z)};
    u = fdot(q, n1);
    v = fdot(q, n2);
    valid = valid & (u >= F(0)) & (v >= F(0)) & (u + v <= F(1));
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
