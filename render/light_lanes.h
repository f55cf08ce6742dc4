#pragma once
// What the SIMD light loops share (render/point_light_shading.cpp,
// render/area_light_shading.cpp): a block of K shaded points' columns, and
// the Lambert plus Phong light they receive, bit for bit the scalar
// shading's (FMA contraction is off; phong_power in lanes as in scalars).
#include <bit>
#include <cmath>
#include <vector>

#include "kernels/simd.h"
#include "render/phong_power.h"
#include "render/shade_lanes.h"
#include "render/shading_points.h"

namespace raypack {

struct LightLanes {
    using F = vfloat<kShadeLanes>;
    static constexpr int K = kShadeLanes;

    static Vec3<F> load3(const std::vector<float> (&a)[3], std::size_t j) {
        return {load_lanes<F>(&a[0][j]), load_lanes<F>(&a[1][j]), load_lanes<F>(&a[2][j])};
    }

    /// The light of colour `light_color` (per lane) arriving along unit `l`
    /// at the points j .. j + K of `pts` whose lanes are `lit`, with
    /// ns_l = dot(ns, l): Lambert plus the Phong highlight, where it is not
    /// +0 anyway (the specular cut-off). Written to out[channel][lane].
    static void direct(const ShadingPoints& pts, std::size_t j, std::uint32_t lit, const Vec3<F>& ns,
                       const Vec3<F>& l, const F& ns_l, const Vec3<F>& view, const Vec3<F>& light_color,
                       float (&out)[3][K]) {
        const F diffuse = load_lanes<F>(&pts.kd_[j]) * ns_l;
        const Vec3<F> r = ns * (F(2.0f) * ns_l) - l;  // mirror of l about the normal
        const F rv = std_max(F(0.0f), -dot(r, view));
        const F ks = load_lanes<F>(&pts.ks_[j]);
        const auto highlight = (ks > F(0.0f)) && (rv > load_lanes<F>(&pts.cutoff_[j]));
        const std::uint32_t shiny = lit & mask_bits(highlight);
        F spec(0.0f);
        if (shiny != 0) {
            // Lanes without a highlight take the power of 1, unused (lanes
            // that are not lit are not read).
            const F power = phong_power(select(highlight, rv, F(1.0f)), load_lanes<F>(&pts.shine_[j]));
            spec = select(highlight, ks * power, F(0.0f));
        }
        const Vec3<F> color = load3(pts.color_, j);
        store_lanes(out[0], light_color.x * color.x * diffuse + light_color.x * spec);
        store_lanes(out[1], light_color.y * color.y * diffuse + light_color.y * spec);
        store_lanes(out[2], light_color.z * color.z * diffuse + light_color.z * spec);
    }
};

}  // namespace raypack
