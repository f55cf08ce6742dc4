#pragma once
// What the SIMD light loops share (render/point_light_shading.cpp,
// render/area_light_shading.cpp): a block of K shaded points' columns, and
// the Lambert plus Phong light they receive, bit for bit the scalar
// shading's (FMA contraction is off; phong_power in lanes as in scalars).
#include <bit>
#include <cmath>
#include <cstring>
#include <vector>

#include "kernels/ray_transpose.h"
#include "kernels/simd.h"
#include "render/phong_power.h"
#include "render/ray_offset.h"
#include "render/shade_lanes.h"
#include "render/shading_points.h"

namespace raypack {

struct LightLanes {
    using F = vfloat<kShadeLanes>;
    static constexpr int K = kShadeLanes;

    static Vec3<F> load3(const std::vector<float> (&a)[3], std::size_t j) {
        return {load_lanes<F>(&a[0][j]), load_lanes<F>(&a[1][j]), load_lanes<F>(&a[2][j])};
    }

    /// Shadow rays from the points j .. j + K of `pts` whose lanes are
    /// `lit`, toward `target` (per lane), in lane order into `run` (which
    /// holds popcount(lit) entries): spawn_ray_to's rays, their owners and
    /// the lanes' contributions. The lit lanes packed together, then written
    /// as rays eight at a time through a transpose (field by field from
    /// each lane before: the Cornell box's distribution render 5% slower).
    static void emit(const ShadingPoints& pts, std::size_t j, std::uint32_t lit, const Vec3<F>& above,
                     const Vec3<F>& target, const float (&contribution)[3][K], float tnear, ShadowQueue::Run run) {
        const int n = std::popcount(lit);
#if defined(__AVX512F__)
        if constexpr (K == 16) {
            const __mmask16 m = __mmask16(lit);
            auto pack = [&](const F& v) { return _mm512_maskz_compress_ps(m, __m512(v)); };
            const Vec3<F> dir = target - above;  // spawn_ray_to: target - origin
            const __m512 field[8] = {pack(above.x), pack(above.y), pack(above.z), pack(dir.x),
                                     pack(dir.y),   pack(dir.z),   _mm512_set1_ps(tnear), _mm512_set1_ps(kShadowRayEnd)};
            alignas(64) Rayf rays[K];
            for (int h = 0; h < 2 && 8 * h < n; ++h) {
                __m256 row[8];
                for (int f = 0; f < 8; ++f)
                    row[f] = h == 0 ? _mm512_castps512_ps256(field[f]) : _mm512_extractf32x8_ps(field[f], 1);
                store_rays8(row, rays + 8 * h);
            }
            std::memcpy(run.rays, rays, std::size_t(n) * sizeof(Rayf));
            alignas(64) std::int32_t owner[K];
            _mm512_store_si512(owner, _mm512_maskz_compress_epi32(m, _mm512_loadu_si512(&pts.ray_[j])));
            std::memcpy(run.owner, owner, std::size_t(n) * sizeof(std::int32_t));
            alignas(64) float c[3][K];
            for (int a = 0; a < 3; ++a) _mm512_store_ps(c[a], _mm512_maskz_compress_ps(m, _mm512_load_ps(contribution[a])));
            for (int k = 0; k < n; ++k) run.contribution[k] = {c[0][k], c[1][k], c[2][k]};
            return;
        }
#endif
        alignas(64) float to[3][K], from[3][K];
        for (int a = 0; a < 3; ++a) {
            store_lanes(to[a], target[a]);
            store_lanes(from[a], above[a]);
        }
        int k = 0;
        for (std::uint32_t bits = lit; bits != 0; bits &= bits - 1, ++k) {
            const int i = std::countr_zero(bits);
            Rayf& ray = run.rays[k];  // spawn_ray_to, component by component
            ray.org = {from[0][i], from[1][i], from[2][i]};
            ray.dir = {to[0][i] - ray.org.x, to[1][i] - ray.org.y, to[2][i] - ray.org.z};
            ray.tnear = tnear;
            ray.tfar = kShadowRayEnd;
            run.owner[k] = pts.ray_[j + std::size_t(i)];
            run.contribution[k] = {contribution[0][i], contribution[1][i], contribution[2][i]};
        }
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
