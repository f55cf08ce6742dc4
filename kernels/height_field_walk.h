#pragma once
// Height fields traced directly (the ray-tracing notes' "height fields"):
// the ray is projected onto the base plane and walks the cells with a 2D DDA
// (Amanatides & Woo 1987); in each cell it meets the bilinear patch through
// the four corner samples where a quadratic in t vanishes. A pyramid of
// min/max heights over blocks of 2^l x 2^l cells (maximum mipmaps, Tevs, Ize
// & Seidel, "Maximum Mipmaps for Fast, Accurate, and Scalable Dynamic Height
// Field Rendering", I3D 2008; here with the minimum as well, so rays below
// the surface skip too) lets the walk step over whole blocks the ray passes
// above or below. Scalar, for T = float or double (the double reference
// converts the ray exactly; the samples are floats either way).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

#include "kernels/gather.h"
#include "kernels/height_field.h"
#include "kernels/ray.h"
#include "kernels/simd.h"

namespace raypack {

/// The bilinear patch of cell (i, j) against the ray: its first root in
/// [t_lo, t_hi] (the ray's span over the cell), and u, v the hit's position
/// over the whole field in [0, 1]. `dz` bounds the rounding of heights along
/// the ray: a root is taken up to dz / |slope| (at most the span's length)
/// outside the span, as a grazing ray's t moves far for a small height
/// error; never outside [tnear, tfar]. The root is a function of the ray's line and the cell alone (not
/// of tnear or the span), so that structures that clip rays to their cells
/// find the t the whole ray does.
template <class T>
bool intersect_height_cell(const HeightField& f, std::uint32_t i, std::uint32_t j, const Ray<T>& ray, T inv_dx,
                           T inv_dy, T t_lo, T t_hi, T dz, T& t, T& u, T& v) {
    const T sx = (T(f.hi.x) - T(f.lo.x)) / T(f.cells_x()), sy = (T(f.hi.y) - T(f.lo.y)) / T(f.cells_y());
    // Reciprocals, not divisions: the lockstep walk computes them once.
    const T inv_sx = T(1) / sx, inv_sy = T(1) / sy;
    const T inv_cx = T(1) / T(f.cells_x()), inv_cy = T(1) / T(f.cells_y());
    const T h00 = f.sample(i, j), h10 = f.sample(i + 1, j), h01 = f.sample(i, j + 1), h11 = f.sample(i + 1, j + 1);
    const T b = h10 - h00, c = h01 - h00, e = h00 - h10 - h01 + h11;
    // Local coordinates s, r in [0, 1] over the cell, from where the ray's
    // line enters the cell's column (ta): fewer large terms cancel than
    // from t = 0.
    const T x0 = T(f.lo.x) + T(i) * sx, y0 = T(f.lo.y) + T(j) * sy;
    const T tx = ray.dir.x > T(0) ? (x0 - ray.org.x) * inv_dx
                 : ray.dir.x < T(0) ? (x0 + sx - ray.org.x) * inv_dx
                                    : -std::numeric_limits<T>::infinity();
    const T ty = ray.dir.y > T(0) ? (y0 - ray.org.y) * inv_dy
                 : ray.dir.y < T(0) ? (y0 + sy - ray.org.y) * inv_dy
                                    : -std::numeric_limits<T>::infinity();
    T ta = std::max(tx, ty);
    if (!std::isfinite(ta)) ta = T(0);  // a vertical ray: from its origin
    const T s_a = (ray.org.x + ta * ray.dir.x - x0) * inv_sx;
    const T r_a = (ray.org.y + ta * ray.dir.y - y0) * inv_sy;
    const T ds = ray.dir.x * inv_sx, dr = ray.dir.y * inv_sy;
    const T z_a = ray.org.z + ta * ray.dir.z;
    // The ray's height minus the patch's, g(tau) = qa tau^2 + qb tau + qc.
    const T qa = -e * ds * dr;
    const T qb = ray.dir.z - (b * ds + c * dr + e * (s_a * dr + r_a * ds));
    const T qc = z_a - (h00 + b * s_a + c * r_a + e * s_a * r_a);
    T roots[2];
    int n = 0;
    if (qa == T(0)) {
        if (qb != T(0)) roots[n++] = -qc / qb;
    } else {
        // Stable form (Numerical Recipes 5.6): a small qa loses nothing.
        const T disc = qb * qb - T(4) * qa * qc;
        if (disc >= T(0)) {
            const T q = T(-0.5) * (qb + std::copysign(std::sqrt(disc), qb));
            roots[0] = q / qa;
            roots[1] = q != T(0) ? qc / q : roots[0];
            if (roots[0] > roots[1]) std::swap(roots[0], roots[1]);
            n = 2;
        }
    }
    for (int k = 0; k < n; ++k) {
        const T tau = roots[k], th = ta + tau;
        // At most the span's own length: far outside its cell, the patch is
        // not the surface.
        const T slack = std::min(dz / std::max(std::abs(T(2) * qa * tau + qb), std::numeric_limits<T>::min()),
                                 std::max(t_hi - t_lo, (std::abs(t_lo) + std::abs(t_hi)) * T(16) *
                                                           std::numeric_limits<T>::epsilon()));
        if (!(th >= t_lo - slack && th <= t_hi + slack && th >= ray.tnear && th <= ray.tfar)) continue;
        t = th;
        u = (T(i) + std::clamp(s_a + ds * tau, T(0), T(1))) * inv_cx;
        v = (T(j) + std::clamp(r_a + dr * tau, T(0), T(1))) * inv_cy;
        return true;
    }
    return false;
}

/// The first hit of the ray on the height field in [tnear, tfar]: t, and u,
/// v its position over the field in [0, 1]. Outputs change only on a hit.
template <class T>
bool intersect_height_field(const HeightField& f, const Ray<T>& ray, T& t_out, T& u_out, T& v_out) {
    constexpr T inf = std::numeric_limits<T>::infinity();
    const std::uint32_t cx = f.cells_x(), cy = f.cells_y();
    const T sx = (T(f.hi.x) - T(f.lo.x)) / T(cx), sy = (T(f.hi.y) - T(f.lo.y)) / T(cy);
    // The ray's span inside the field's box.
    T t0 = ray.tnear, t1 = ray.tfar;
    const T eps = std::numeric_limits<T>::epsilon();
    // The heights' box, deepened by the rounding of the ray's height, so
    // that a grazing ray's span covers where its computed height meets them.
    const T zpad = (std::abs(T(f.lo.z)) + std::abs(T(f.hi.z)) + std::abs(ray.org.z)) * eps * T(8);
    const T lo[3] = {T(f.lo.x), T(f.lo.y), T(f.lo.z) - zpad}, hi[3] = {T(f.hi.x), T(f.hi.y), T(f.hi.z) + zpad};
    for (int a = 0; a < 3; ++a) {
        const T o = ray.org[a], d = ray.dir[a];
        if (d == T(0)) {
            if (o < lo[a] || o > hi[a]) return false;
            continue;
        }
        T ta = (lo[a] - o) / d, tb = (hi[a] - o) / d;
        if (ta > tb) std::swap(ta, tb);
        t0 = std::max(t0, ta);
        t1 = std::min(t1, tb);
    }
    // A span that starts at infinity (tnear = -inf and no direction to clip
    // it) places the ray nowhere: no hit.
    if (!(t0 <= t1) || !(std::abs(t0) < inf)) return false;
    // Widen t1 a little so that a hit on the box's far face is not lost to
    // the rounding of the span.
    t1 = std::min(ray.tfar, t1 + (std::abs(t1) + std::abs(t0)) * eps * T(16));
    const T inv_sx = T(1) / sx, inv_sy = T(1) / sy;
    auto cell_of = [](T x, T origin, T inv_size, std::uint32_t n) {
        const T c = std::floor((x - origin) * inv_size);
        return std::uint32_t(std::clamp(c, T(0), T(n - 1)));
    };
    std::uint32_t ix = cell_of(ray.org.x + t0 * ray.dir.x, lo[0], inv_sx, cx);
    std::uint32_t iy = cell_of(ray.org.y + t0 * ray.dir.y, lo[1], inv_sy, cy);
    const int top = int(f.level_offset.size()) - 1;
    const T inv_dx = ray.dir.x != T(0) ? T(1) / ray.dir.x : inf, inv_dy = ray.dir.y != T(0) ? T(1) / ray.dir.y : inf;
    T t = t0;
    int level = top;
    for (;;) {
        // The coarsest block at (ix, iy), from `level` down, that the ray can
        // skip over its span; level 0 is one cell, tested against its patch.
        for (int l = level;; --l) {
            const std::uint32_t ax = ix >> l, ay = iy >> l;
            const std::uint32_t x_lo = ax << l, x_hi = std::min((ax + 1) << l, cx);
            const std::uint32_t y_lo = ay << l, y_hi = std::min((ay + 1) << l, cy);
            const T bx = ray.dir.x > T(0) ? T(x_hi) : T(x_lo), by = ray.dir.y > T(0) ? T(y_hi) : T(y_lo);
            const T tx = ray.dir.x != T(0) ? (lo[0] + bx * sx - ray.org.x) * inv_dx : inf;
            const T ty = ray.dir.y != T(0) ? (lo[1] + by * sy - ray.org.y) * inv_dy : inf;
            const T texit = std::min(std::min(tx, ty), t1);
            T zmin, zmax;
            if (l == 0) {
                const float h00 = f.sample(ix, iy), h10 = f.sample(ix + 1, iy), h01 = f.sample(ix, iy + 1),
                            h11 = f.sample(ix + 1, iy + 1);
                zmin = std::min(std::min(h00, h10), std::min(h01, h11));
                zmax = std::max(std::max(h00, h10), std::max(h01, h11));
            } else {
                const float* r = &f.range[f.level_offset[l] + (std::size_t(ay) * f.level_w[l] + ax) * 2];
                zmin = r[0];
                zmax = r[1];
            }
            const T za = ray.org.z + t * ray.dir.z, zb = ray.org.z + texit * ray.dir.z;
            const T margin = (std::abs(ray.org.z) + std::abs(t * ray.dir.z) + std::abs(texit * ray.dir.z) +
                              std::abs(zmin) + std::abs(zmax)) * eps * T(8);
            const bool skip = std::min(za, zb) - margin > zmax || std::max(za, zb) + margin < zmin;
            if (!skip && l > 0) continue;  // look closer
            if (!skip) {
                T th, u, v;
                if (intersect_height_cell(f, ix, iy, ray, inv_dx, inv_dy, t, texit, margin, th, u, v)) {
                    t_out = th;
                    u_out = u;
                    v_out = v;
                    return true;
                }
            }
            // Leave the block through its exit face.
            if (texit >= t1) return false;
            if (tx <= ty) {
                if (ray.dir.x > T(0) ? x_hi >= cx : x_lo == 0) return false;
                ix = ray.dir.x > T(0) ? x_hi : x_lo - 1;
                iy = std::clamp(cell_of(ray.org.y + texit * ray.dir.y, lo[1], inv_sy, cy), y_lo, y_hi - 1);
            } else {
                if (ray.dir.y > T(0) ? y_hi >= cy : y_lo == 0) return false;
                iy = ray.dir.y > T(0) ? y_hi : y_lo - 1;
                ix = std::clamp(cell_of(ray.org.x + texit * ray.dir.x, lo[0], inv_sx, cx), x_lo, x_hi - 1);
            }
            t = std::max(t, texit);
            level = std::min(l + 1, top);
            break;
        }
    }
}


// gcc 12 warns -Wmaybe-uninitialized for the pass-through operand inside
// AVX-512 rounding intrinsics (xsimd::floor) once inlined deep.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"

namespace height_field_detail {

/// std::min and std::max lane by lane, with their operand order (the
/// scalar walk's bits, signed zeros included).
template <class F>
RAYPACK_INLINE F vmin_like_std(const F& a, const F& b) {
    return select(b < a, b, a);
}
template <class F>
RAYPACK_INLINE F vmax_like_std(const F& a, const F& b) {
    return select(a < b, b, a);
}

/// intersect_height_cell lane by lane, each lane its own cell (ix, iy) with
/// its corner heights already read.
template <class F>
RAYPACK_INLINE mask_of<F> height_cell_lanes(const HeightField& f, const F& ix, const F& iy, const F& h00, const F& h10, const F& h01,
                             const F& h11, const Vec3<F>& org, const Vec3<F>& dir, const F& inv_dx, const F& inv_dy,
                             const F& tnear, const F& tfar, const F& t_lo, const F& t_hi, const F& dz, F& t, F& u,
                             F& v) {
    using M = mask_of<F>;
    const F zero(0.0f), one(1.0f), minus_inf(-std::numeric_limits<float>::infinity());
    const float sx = (f.hi.x - f.lo.x) / float(f.cells_x()), sy = (f.hi.y - f.lo.y) / float(f.cells_y());
    const float inv_sx = 1.0f / sx, inv_sy = 1.0f / sy;
    const float inv_cx = 1.0f / float(f.cells_x()), inv_cy = 1.0f / float(f.cells_y());
    const F b = h10 - h00, c = h01 - h00, e = h00 - h10 - h01 + h11;
    const F x0 = F(f.lo.x) + ix * F(sx), y0 = F(f.lo.y) + iy * F(sy);
    const F tx = select(dir.x > zero, (x0 - org.x) * inv_dx, select(dir.x < zero, (x0 + F(sx) - org.x) * inv_dx, minus_inf));
    const F ty = select(dir.y > zero, (y0 - org.y) * inv_dy, select(dir.y < zero, (y0 + F(sy) - org.y) * inv_dy, minus_inf));
    F ta = vmax_like_std(tx, ty);
    ta = select(vabs(ta) < F(std::numeric_limits<float>::infinity()), ta, zero);
    const F s_a = (org.x + ta * dir.x - x0) * F(inv_sx);
    const F r_a = (org.y + ta * dir.y - y0) * F(inv_sy);
    const F ds = dir.x * F(inv_sx), dr = dir.y * F(inv_sy);
    const F z_a = org.z + ta * dir.z;
    const F qa = -e * ds * dr;
    const F qb = dir.z - (b * ds + c * dr + e * (s_a * dr + r_a * ds));
    const F qc = z_a - (h00 + b * s_a + c * r_a + e * s_a * r_a);
    const M linear = qa == zero;
    const F disc = qb * qb - F(4.0f) * qa * qc;
    const F q = F(-0.5f) * (qb + copysign_of(vsqrt(disc), qb));
    F r0 = q / qa, r1 = select(q != zero, qc / q, r0);
    const M swap = r0 > r1;
    const F lo_root = select(swap, r1, r0), hi_root = select(swap, r0, r1);
    // Lanes with roots: linear with qb != 0 (one root), or disc >= 0 (two).
    const M quadratic = !linear, real = disc >= zero;
    const M has0 = (linear & (qb != zero)) | (quadratic & real);
    const M has1 = quadratic & real;
    const F root0 = select(linear, -qc / qb, lo_root), root1 = hi_root;
    const F span = vmax_like_std(t_hi - t_lo, (vabs(t_lo) + vabs(t_hi)) * F(16.0f) * F(std::numeric_limits<float>::epsilon()));
    auto accept = [&](const F& tau) {
        const F th = ta + tau;
        const F slack = vmin_like_std(dz / vmax_like_std(vabs(F(2.0f) * qa * tau + qb), F(std::numeric_limits<float>::min())), span);
        return (th >= t_lo - slack) & (th <= t_hi + slack) & (th >= tnear) & (th <= tfar);
    };
    const M take0 = has0 & accept(root0), not0 = !take0;
    const M take1 = not0 & has1 & accept(root1);
    const F tau = select(take0, root0, root1);
    t = ta + tau;
    auto clamp01 = [&](const F& x) { return select(x < zero, zero, select(one < x, one, x)); };
    u = (ix + clamp01(s_a + ds * tau)) * F(inv_cx);
    v = (iy + clamp01(r_a + dr * tau)) * F(inv_cy);
    return take0 | take1;
}

}  // namespace height_field_detail

/// intersect_height_field for K rays in lanes (F = vfloat<K>), each lane
/// walking on its own in lockstep: the same operations as the scalar walk,
/// lane for lane, so each lane's t, u, v are the scalar walk's bits.
/// Coherent rays (a camera packet) take about the same steps, so K lanes
/// cost little more than one ray. Returns the lanes of `active` that hit;
/// t, u, v change on those only.
template <class F>
mask_of<F> intersect_height_field_lanes(const HeightField& f, mask_of<F> active, const Vec3<F>& org,
                                        const Vec3<F>& dir, const F& tnear, const F& tfar, F& t_out, F& u_out,
                                        F& v_out) {
    using namespace height_field_detail;
    using M = mask_of<F>;
    using I = xsimd::batch<std::int32_t, typename F::arch_type>;
    const F inf(std::numeric_limits<float>::infinity()), zero(0.0f), one(1.0f);
    const float eps = std::numeric_limits<float>::epsilon();
    const std::uint32_t cx = f.cells_x(), cy = f.cells_y();
    const float sx = (f.hi.x - f.lo.x) / float(cx), sy = (f.hi.y - f.lo.y) / float(cy);
    const F fcx = F(float(cx)), fcy = F(float(cy));
    const F zpad = (F(std::abs(f.lo.z)) + F(std::abs(f.hi.z)) + vabs(org.z)) * F(eps) * F(8.0f);
    const F lo_x(f.lo.x), lo_y(f.lo.y), lo_z = F(f.lo.z) - zpad, hi_x(f.hi.x), hi_y(f.hi.y), hi_z = F(f.hi.z) + zpad;
    // The span inside the box, axis by axis as the scalar walk clips it.
    F t0 = tnear, t1 = tfar;
    auto clip = [&](const F& o, const F& d, const F& lo, const F& hi) {
        const M flat = d == zero;
        active = active & !(flat & ((o < lo) | (o > hi)));
        F ta = (lo - o) / d, tb = (hi - o) / d;
        const M swap = ta > tb;
        const F a = select(swap, tb, ta), b = select(swap, ta, tb);
        t0 = select(flat, t0, vmax_like_std(t0, a));
        t1 = select(flat, t1, vmin_like_std(t1, b));
    };
    clip(org.x, dir.x, lo_x, hi_x);
    clip(org.y, dir.y, lo_y, hi_y);
    clip(org.z, dir.z, lo_z, hi_z);
    active = active & (t0 <= t1) & (vabs(t0) < inf);
    if (none(active)) return active;
    t1 = vmin_like_std(tfar, t1 + (vabs(t1) + vabs(t0)) * F(eps) * F(16.0f));
    const float inv_sx = 1.0f / sx, inv_sy = 1.0f / sy;
    auto cell_of = [](const F& x, const F& origin, float inv_size, const F& n) {
        return vmin_like_std(vmax_like_std(xsimd::floor((x - origin) * F(inv_size)), F(0.0f)), n - F(1.0f));
    };
    // Lanes not walking keep cell 0: every lane's gathers stay in bounds.
    F ix = select(active, cell_of(org.x + t0 * dir.x, lo_x, inv_sx, fcx), zero);
    F iy = select(active, cell_of(org.y + t0 * dir.y, lo_y, inv_sy, fcy), zero);
    const int top = int(f.level_offset.size()) - 1;
    const M pos_x = dir.x > zero, pos_y = dir.y > zero, zero_x = dir.x == zero, zero_y = dir.y == zero;
    const M neg_x = !pos_x, neg_y = !pos_y;
    const F inv_dx = select(zero_x, inf, one / dir.x), inv_dy = select(zero_y, inf, one / dir.y);
    const I nx_i(std::int32_t(f.nx));
    const auto* samples = f.z.data();
    const auto* level_w = reinterpret_cast<const std::int32_t*>(f.level_w.data());
    const auto* level_offset = reinterpret_cast<const std::int32_t*>(f.level_offset.data());
    const F top_scale = F(float(1u << top));
    // The level tables in lanes (build_ranges keeps pyramids to 32
    // levels), looked up by a permute instead of two dependent gathers per
    // step.
    alignas(64) std::int32_t offset_table[32] = {}, width_table[32] = {};
    for (int k = 0; k <= top; ++k) {
        offset_table[k] = level_offset[k];
        width_table[k] = level_w[k];
    }
    const I offset_lo = I::load_aligned(offset_table), offset_hi = I::load_aligned(offset_table + 16);
    const I width_lo = I::load_aligned(width_table), width_hi = I::load_aligned(width_table + 16);
    // scale = 2^level and its reciprocal, kept exact by halving and doubling.
    F t = t0, level = F(float(top)), scale = top_scale, inv_scale = one / top_scale;
    M hit(false);
    while (any(active)) {
        // Each lane's block at its level: 2^l cells a side.
        const I l = xsimd::batch_cast<std::int32_t>(level);
        const F ax = xsimd::floor(ix * inv_scale), ay = xsimd::floor(iy * inv_scale);
        const F x_lo = ax * scale, x_hi = vmin_like_std((ax + one) * scale, fcx);
        const F y_lo = ay * scale, y_hi = vmin_like_std((ay + one) * scale, fcy);
        const F tx = select(zero_x, inf, (lo_x + select(pos_x, x_hi, x_lo) * F(sx) - org.x) * inv_dx);
        const F ty = select(zero_y, inf, (lo_y + select(pos_y, y_hi, y_lo) * F(sy) - org.y) * inv_dy);
        const F texit = vmin_like_std(vmin_like_std(tx, ty), t1);
        // The block's heights: its four samples at level 0, else the pyramid.
        const M at_cell = level == zero;
        // Gathered only when some walking lane needs them (coherent lanes
        // are mostly at one level), and only in those lanes: a gather costs
        // by the element, and a branch that skips it pays (not so a
        // branch-free walk with both gathers masked: 1.3x slower).
        F zmin(0.0f), zmax(0.0f), h00(0.0f), h10(0.0f), h01(0.0f), h11(0.0f);
        if (const M need = active & at_cell; any(need)) {
            const I s00 = xsimd::batch_cast<std::int32_t>(iy) * nx_i + xsimd::batch_cast<std::int32_t>(ix);
            h00 = gather_floats<F>(samples, s00, need);
            h10 = gather_floats<F>(samples, s00 + I(1), need);
            h01 = gather_floats<F>(samples, s00 + nx_i, need);
            h11 = gather_floats<F>(samples, s00 + nx_i + I(1), need);
            zmin = vmin_like_std(vmin_like_std(h00, h10), vmin_like_std(h01, h11));
            zmax = vmax_like_std(vmax_like_std(h00, h10), vmax_like_std(h01, h11));
        }
        if (const M need = active & !at_cell; top > 0 && any(need)) {
            // Level-0 lanes look up level 1 (any valid level) and read nothing.
            const I cell_bits = xsimd::bitwise_cast<I>(xsimd::bitwise_cast(at_cell));
            const I lc = l | (cell_bits & I(1));
            const I offset = lookup32(offset_table, offset_lo, offset_hi, lc);
            const I width = lookup32(width_table, width_lo, width_hi, lc);
            const I pidx = offset + (xsimd::batch_cast<std::int32_t>(ay) * width + xsimd::batch_cast<std::int32_t>(ax)) * I(2);
            zmin = select(at_cell, zmin, gather_floats<F>(f.range.data(), pidx, need));
            zmax = select(at_cell, zmax, gather_floats<F>(f.range.data(), pidx + I(1), need));
        }
        const F za = org.z + t * dir.z, zb = org.z + texit * dir.z;
        const F margin =
            (vabs(org.z) + vabs(t * dir.z) + vabs(texit * dir.z) + vabs(zmin) + vabs(zmax)) * F(eps) * F(8.0f);
        const M skip = (vmin_like_std(za, zb) - margin > zmax) | (vmax_like_std(za, zb) + margin < zmin);
        const M descend = active & !skip & !at_cell;
        const M test = active & !skip & at_cell;
        if (any(test)) {
            F th, u, v;
            const M found = test & height_cell_lanes(f, ix, iy, h00, h10, h01, h11, org, dir, inv_dx, inv_dy, tnear, tfar, t, texit,
                                                     margin, th, u, v);
            t_out = select(found, th, t_out);
            u_out = select(found, u, u_out);
            v_out = select(found, v, v_out);
            hit = hit | found;
            active = active & !found;
        }
        level = select(descend, level - one, level);
        scale = select(descend, scale * F(0.5f), scale);
        inv_scale = select(descend, inv_scale * F(2.0f), inv_scale);
        // The rest leave their block through its exit face.
        M leave = active & !descend;
        active = active & !(leave & (texit >= t1));
        leave = leave & active;
        const M via_x = tx <= ty, via_y = !via_x;
        const M off_x = via_x & ((pos_x & (x_hi >= fcx)) | (neg_x & (x_lo == zero)));
        const M off_y = via_y & ((pos_y & (y_hi >= fcy)) | (neg_y & (y_lo == zero)));
        active = active & !(leave & (off_x | off_y));
        leave = leave & active;
        const F new_ix_x = select(pos_x, x_hi, x_lo - one);
        const F new_iy_x = vmin_like_std(vmax_like_std(cell_of(org.y + texit * dir.y, lo_y, inv_sy, fcy), y_lo), y_hi - one);
        const F new_iy_y = select(pos_y, y_hi, y_lo - one);
        const F new_ix_y = vmin_like_std(vmax_like_std(cell_of(org.x + texit * dir.x, lo_x, inv_sx, fcx), x_lo), x_hi - one);
        ix = select(leave, select(via_x, new_ix_x, new_ix_y), ix);
        iy = select(leave, select(via_x, new_iy_x, new_iy_y), iy);
        t = select(leave, vmax_like_std(t, texit), t);
        const M up = leave & (level < F(float(top)));
        level = select(leave, vmin_like_std(level + one, F(float(top))), level);
        scale = select(up, scale * F(2.0f), scale);
        inv_scale = select(up, inv_scale * F(0.5f), inv_scale);
    }
    return hit;
}

#pragma GCC diagnostic pop

}  // namespace raypack
