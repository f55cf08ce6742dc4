#pragma once
// A height field: samples over a rectangle, each cell the bilinear patch
// through its corners, and the min/max pyramid its walk skips blocks by
// (the walk: kernels/height_field_walk.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <vector>

#include "kernels/ray.h"
#include "kernels/vec3.h"

namespace raypack {

/// nx x ny height samples over the rectangle [lo.x, hi.x] x [lo.y, hi.y]
/// (z up): sample (i, j) at x = lo.x + i (hi.x - lo.x) / (nx - 1), and so on,
/// z[j nx + i] its height. (nx - 1) x (ny - 1) cells, each the bilinear patch
/// through its corners. lo.z and hi.z are the lowest and highest sample.
struct HeightField {
    Vec3f lo, hi;
    std::uint32_t nx = 0, ny = 0;
    std::vector<float> z;
    /// Level l = 1, 2, ... of the min/max pyramid: cell (a, b) covers level-0
    /// cells [a 2^l, (a + 1) 2^l) x [b 2^l, (b + 1) 2^l); stored as (min,
    /// max) pairs, row-major, level_w[l] x level_h[l] cells from
    /// range[level_offset[l]] on (one array, so that lanes gather from it).
    /// Level 0 (one cell) is read from the samples. The last level has one
    /// cell.
    std::vector<float> range;
    std::vector<std::uint32_t> level_w, level_h, level_offset;

    std::uint32_t cells_x() const { return nx - 1; }
    /// The highest sample as a point: it lies on the field's bounding box.
    Vec3f peak() const {
        const std::size_t k = std::size_t(std::max_element(z.begin(), z.end()) - z.begin());
        const std::uint32_t i = std::uint32_t(k % nx), j = std::uint32_t(k / nx);
        return {lo.x + (hi.x - lo.x) * float(i) / float(nx - 1), lo.y + (hi.y - lo.y) * float(j) / float(ny - 1), z[k]};
    }
    std::uint32_t cells_y() const { return ny - 1; }
    float sample(std::uint32_t i, std::uint32_t j) const { return z[std::size_t(j) * nx + i]; }
    std::size_t bytes() const {
        return (z.size() + range.size()) * sizeof(float) +
               (level_w.size() + level_h.size() + level_offset.size()) * sizeof(std::uint32_t);
    }
    /// Fills `range`, level_w, level_h, lo.z and hi.z from the samples.
    void build_ranges();
};

inline void HeightField::build_ranges() {
    const std::uint32_t cx = cells_x(), cy = cells_y();
    range.clear();  // level 0 is read from the samples
    level_w.assign(1, cx);
    level_h.assign(1, cy);
    level_offset.assign(1, 0);
    auto [zmin, zmax] = std::minmax_element(z.begin(), z.end());
    lo.z = *zmin;
    hi.z = *zmax;
    std::uint32_t w = cx, h = cy;
    for (int l = 1; w > 1 || h > 1; ++l) {
        const std::uint32_t pw = w, ph = h, previous = level_offset.back();
        w = (w + 1) / 2;
        h = (h + 1) / 2;
        const std::size_t base = range.size();
        if (base + std::size_t(w) * h * 2 > 0xFFFFFFFFu) throw std::length_error("height field pyramid too large");
        range.resize(base + std::size_t(w) * h * 2);
        for (std::uint32_t b = 0; b < h; ++b)
            for (std::uint32_t a = 0; a < w; ++a) {
                float mn = std::numeric_limits<float>::infinity(), mx = -mn;
                for (std::uint32_t j = 2 * b; j < std::min(2 * b + 2, ph); ++j)
                    for (std::uint32_t i = 2 * a; i < std::min(2 * a + 2, pw); ++i) {
                        float cmn, cmx;
                        if (l == 1) {
                            const float h00 = sample(i, j), h10 = sample(i + 1, j), h01 = sample(i, j + 1),
                                        h11 = sample(i + 1, j + 1);
                            cmn = std::min(std::min(h00, h10), std::min(h01, h11));
                            cmx = std::max(std::max(h00, h10), std::max(h01, h11));
                        } else {
                            const float* p = &range[previous + (std::size_t(j) * pw + i) * 2];
                            cmn = p[0];
                            cmx = p[1];
                        }
                        mn = std::min(mn, cmn);
                        mx = std::max(mx, cmx);
                    }
                range[base + (std::size_t(b) * w + a) * 2] = mn;
                range[base + (std::size_t(b) * w + a) * 2 + 1] = mx;
            }
        level_w.push_back(w);
        level_h.push_back(h);
        level_offset.push_back(std::uint32_t(base));
    }
    // The lane walk holds the level tables in 32 lanes (height_field_walk.h):
    // fields up to 2^31 cells a side.
    if (level_offset.size() > 32) throw std::length_error("height field pyramid deeper than 32 levels");
}

/// Where field position (u, v) in [0, 1]^2 lies: cell (i, j), at (s, r) in
/// [0, 1]^2 within it.
struct HeightFieldSpot {
    std::uint32_t i, j;
    float s, r;
};

inline HeightFieldSpot height_field_spot(const HeightField& f, float u, float v) {
    const std::uint32_t cx = f.cells_x(), cy = f.cells_y();
    const float gx = std::clamp(u, 0.0f, 1.0f) * float(cx), gy = std::clamp(v, 0.0f, 1.0f) * float(cy);
    const std::uint32_t i = std::min(std::uint32_t(gx), cx - 1), j = std::min(std::uint32_t(gy), cy - 1);
    return {i, j, gx - float(i), gy - float(j)};
}

/// The upward normal of the patch at field position (u, v) (not
/// normalised): (-dz/dx, -dz/dy, 1).
inline Vec3f height_field_normal(const HeightField& f, float u, float v) {
    const auto [i, j, s, r] = height_field_spot(f, u, v);
    const float h00 = f.sample(i, j), h10 = f.sample(i + 1, j), h01 = f.sample(i, j + 1), h11 = f.sample(i + 1, j + 1);
    const float e = h00 - h10 - h01 + h11;
    const float dhds = (h10 - h00) + e * r, dhdr = (h01 - h00) + e * s;
    const float sx = (f.hi.x - f.lo.x) / float(f.cells_x()), sy = (f.hi.y - f.lo.y) / float(f.cells_y());
    return {-dhds / sx, -dhdr / sy, 1.0f};
}

/// The point of the field at (u, v).
inline Vec3f height_field_point(const HeightField& f, float u, float v) {
    const auto [i, j, s, r] = height_field_spot(f, u, v);
    const float h00 = f.sample(i, j), h10 = f.sample(i + 1, j), h01 = f.sample(i, j + 1), h11 = f.sample(i + 1, j + 1);
    const float h = h00 + (h10 - h00) * s + (h01 - h00) * r + (h00 - h10 - h01 + h11) * s * r;
    return {f.lo.x + u * (f.hi.x - f.lo.x), f.lo.y + v * (f.hi.y - f.lo.y), h};
}

}  // namespace raypack
