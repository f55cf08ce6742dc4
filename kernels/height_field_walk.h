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

#include "kernels/height_field.h"
#include "kernels/ray.h"

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
bool intersect_height_cell(const HeightField& f, std::uint32_t i, std::uint32_t j, const Ray<T>& ray, T t_lo,
                           T t_hi, T dz, T& t, T& u, T& v) {
    const T sx = (T(f.hi.x) - T(f.lo.x)) / T(f.cells_x()), sy = (T(f.hi.y) - T(f.lo.y)) / T(f.cells_y());
    const T h00 = f.sample(i, j), h10 = f.sample(i + 1, j), h01 = f.sample(i, j + 1), h11 = f.sample(i + 1, j + 1);
    const T b = h10 - h00, c = h01 - h00, e = h00 - h10 - h01 + h11;
    // Local coordinates s, r in [0, 1] over the cell, from where the ray's
    // line enters the cell's column (ta): fewer large terms cancel than
    // from t = 0.
    const T x0 = T(f.lo.x) + T(i) * sx, y0 = T(f.lo.y) + T(j) * sy;
    const T tx = ray.dir.x > T(0) ? (x0 - ray.org.x) / ray.dir.x
                 : ray.dir.x < T(0) ? (x0 + sx - ray.org.x) / ray.dir.x
                                    : -std::numeric_limits<T>::infinity();
    const T ty = ray.dir.y > T(0) ? (y0 - ray.org.y) / ray.dir.y
                 : ray.dir.y < T(0) ? (y0 + sy - ray.org.y) / ray.dir.y
                                    : -std::numeric_limits<T>::infinity();
    T ta = std::max(tx, ty);
    if (!std::isfinite(ta)) ta = T(0);  // a vertical ray: from its origin
    const T s_a = (ray.org.x + ta * ray.dir.x - x0) / sx;
    const T r_a = (ray.org.y + ta * ray.dir.y - y0) / sy;
    const T ds = ray.dir.x / sx, dr = ray.dir.y / sy;
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
        u = (T(i) + std::clamp(s_a + ds * tau, T(0), T(1))) / T(f.cells_x());
        v = (T(j) + std::clamp(r_a + dr * tau, T(0), T(1))) / T(f.cells_y());
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
    if (!(t0 <= t1)) return false;
    // Widen t1 a little so that a hit on the box's far face is not lost to
    // the rounding of the span.
    t1 = std::min(ray.tfar, t1 + (std::abs(t1) + std::abs(t0)) * eps * T(16));
    auto cell_of = [](T x, T origin, T size, std::uint32_t n) {
        const T c = std::floor((x - origin) / size);
        return std::uint32_t(std::clamp(c, T(0), T(n - 1)));
    };
    std::uint32_t ix = cell_of(ray.org.x + t0 * ray.dir.x, lo[0], sx, cx);
    std::uint32_t iy = cell_of(ray.org.y + t0 * ray.dir.y, lo[1], sy, cy);
    const int top = int(f.range.size()) - 1;
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
                const float* r = &f.range[l][(std::size_t(ay) * f.level_w[l] + ax) * 2];
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
                if (intersect_height_cell(f, ix, iy, ray, t, texit, margin, th, u, v)) {
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
                iy = std::clamp(cell_of(ray.org.y + texit * ray.dir.y, lo[1], sy, cy), y_lo, y_hi - 1);
            } else {
                if (ray.dir.y > T(0) ? y_hi >= cy : y_lo == 0) return false;
                iy = ray.dir.y > T(0) ? y_hi : y_lo - 1;
                ix = std::clamp(cell_of(ray.org.x + texit * ray.dir.x, lo[0], sx, cx), x_lo, x_hi - 1);
            }
            t = std::max(t, texit);
            level = std::min(l + 1, top);
            break;
        }
    }
}

}  // namespace raypack
