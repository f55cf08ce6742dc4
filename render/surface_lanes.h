#pragma once
// SurfaceTable::at for K hits at once, in SIMD lanes: the records, rays and
// hits gathered lane by lane, the same operations in the same order (FMA
// contraction is off), so every lane holds at()'s bits. Out of lanes: a
// scalar at() per hit and a copy of its Surface into lane arrays was most of
// the shading loop's time (store forwarding and dependent loads per hit).
#include <cstdint>

#include "kernels/ray_transpose.h"
#include "kernels/simd.h"
#include "render/gather_lanes.h"
#include "render/surface.h"

namespace raypack {

template <int K>
struct SurfaceLanes {
    using F = vfloat<K>;
    using I = vint<K>;
    Vec3<F> point, geometric_normal, shading_normal;
    Vec3<F> direction;  ///< the ray's
    I material;         ///< 0 in the lanes left out

    /// The surfaces of hits[index[l]] of rays[index[l]] for the lanes
    /// `lanes` (found hits; at the shutter's opening). Lanes outside `lanes`
    /// hold garbage, but their `index` must still be a valid ray.
    void gather(const SurfaceTable& table, const Rayf* rays, const Hitf* hits, const I& index, std::uint32_t lanes) {
        static_assert(sizeof(Hitf) == 16 && sizeof(Rayf) == 32);
        const auto* hit_words = reinterpret_cast<const float*>(hits);
        const auto* ray_words = reinterpret_cast<const float*>(rays);
        const I hit4 = shift_left<K>(index, 2), ray8 = shift_left<K>(index, 3);
        HitFields h;
        h.prim = gather_ints<K>(reinterpret_cast<const std::int32_t*>(hits), hit4 + I(1));
        h.t = gather_floats<K>(hit_words, hit4);
        h.org = {gather_floats<K>(ray_words, ray8), gather_floats<K>(ray_words, ray8 + I(1)),
                 gather_floats<K>(ray_words, ray8 + I(2))};
        h.dir = {gather_floats<K>(ray_words, ray8 + I(3)), gather_floats<K>(ray_words, ray8 + I(4)),
                 gather_floats<K>(ray_words, ray8 + I(5))};
        surfaces(table, rays, hits, index, lanes, h);
    }

    /// gather() for the K consecutive hits and rays first, first + 1 ...
    /// (index[l] = first + l): loaded whole and transposed in registers
    /// instead of eight gathers (a Cornell box's 4-sample render 3% faster,
    /// gears 1.5%).
    void load(const SurfaceTable& table, const Rayf* rays, const Hitf* hits, std::size_t first, const I& index,
              std::uint32_t lanes) {
#if defined(__AVX2__)
        if constexpr (K == 8 || K == 16) {
            __m256 ray_rows[2][8], hit_rows[2][4];
            for (int q = 0; q < K / 8; ++q) {
                transpose_rays8(rays + first + std::size_t(8 * q), ray_rows[q]);
                load_hits8(hits + first + std::size_t(8 * q), hit_rows[q]);
            }
            // Lanes 0-7 from the first eight, 8-15 from the second.
            auto field = [&](const __m256& lo, [[maybe_unused]] const __m256& hi) -> F {
                if constexpr (K == 8) return F(lo);
#if defined(__AVX512F__)
                else return F(_mm512_insertf32x8(_mm512_castps256_ps512(lo), hi, 1));
#endif
            };
            auto ray_field = [&](int f) { return field(ray_rows[0][f], ray_rows[1][f]); };
            auto hit_field = [&](int f) { return field(hit_rows[0][f], hit_rows[1][f]); };
            HitFields h;
            h.org = {ray_field(0), ray_field(1), ray_field(2)};
            h.dir = {ray_field(3), ray_field(4), ray_field(5)};
            h.t = hit_field(0);
            if constexpr (K == 8) h.prim = I(_mm256_castps_si256(hit_field(1)));
#if defined(__AVX512F__)
            else h.prim = I(_mm512_castps_si512(hit_field(1)));
#endif
            h.u = hit_field(2);
            h.v = hit_field(3);
            h.has_uv = true;
            surfaces(table, rays, hits, index, lanes, h);
            return;
        }
#endif
        gather(table, rays, hits, index, lanes);
    }

private:
    /// What gather() reads of each lane's hit and ray.
    struct HitFields {
        I prim;
        F t;
        Vec3<F> org, dir;
        bool has_uv = false;  ///< u, v read (else gathered where needed)
        F u, v;
    };

    /// The surfaces from the lanes' hits and rays.
    void surfaces(const SurfaceTable& table, const Rayf* rays, const Hitf* hits, const I& index, std::uint32_t lanes,
                  const HitFields& in) {
        static_assert(sizeof(SurfaceTable::Record) == 16);
        static_assert(sizeof(PrimRef) == 8 && sizeof(Vec3f) == 12);
        alignas(64) std::int32_t lane_bit[K];
        for (int l = 0; l < K; ++l) lane_bit[l] = std::int32_t(1u << l);
        const auto in_lanes = (I(std::int32_t(lanes)) & I::load_aligned(lane_bit)) != I(0);
        const auto* hit_words = reinterpret_cast<const float*>(hits);
        const I hit4 = shift_left<K>(index, 2);
        const I prim = in.prim;
        // Primitives inside instances have no record (prim >= records).
        const auto recorded = in_lanes & (prim >= I(0)) & (prim < I(std::int32_t(table.records_.size())));
        const std::uint32_t recorded_bits = int_mask_bits<K>(recorded);
        I material_kind = I(std::int32_t(SurfaceTable::kOther));
        Vec3<F> v{F(0.0f), F(0.0f), F(0.0f)};  // lanes without a record: unused
        if (recorded_bits != 0) {
            const std::int32_t first = first_lane<K>(prim, recorded_bits);
            if ((int_mask_bits<K>(prim == I(first)) & recorded_bits) == recorded_bits) {
                // One primitive in every lane (a large triangle, a near
                // sphere): its record once.
                const SurfaceTable::Record& r = table.records_[std::size_t(first)];
                material_kind = I(std::int32_t(r.material_kind));
                v = {F(r.v.x), F(r.v.y), F(r.v.z)};
            } else {
                const I record4 = shift_left<K>(xsimd::select(recorded, prim, I(first)), 2);
                const auto* record_words = reinterpret_cast<const float*>(table.records_.data());
                material_kind = gather_ints<K>(reinterpret_cast<const std::int32_t*>(record_words), record4 + I(3));
                v = {gather_floats<K>(record_words, record4), gather_floats<K>(record_words, record4 + I(1)),
                     gather_floats<K>(record_words, record4 + I(2))};
            }
        }
        material = xsimd::select(recorded, shift_right<K>(material_kind, int(SurfaceTable::kKindBits)), I(0));
        const I kind = material_kind & I(std::int32_t(SurfaceTable::kKindMask));
        direction = in.dir;
        point = in.org + in.dir * in.t;
        geometric_normal = v;  // flat and smooth triangles
        shading_normal = v;    // flat triangles
        const std::uint32_t sphere = lanes & int_mask_bits<K>(recorded & (kind == I(SurfaceTable::kSphere)));
        const auto smooth_lanes = recorded & (kind == I(SurfaceTable::kSmoothTriangle));
        const std::uint32_t smooth = lanes & int_mask_bits<K>(smooth_lanes);
        const auto cone_lanes = recorded & (kind == I(SurfaceTable::kCone));
        const std::uint32_t cone = lanes & int_mask_bits<K>(cone_lanes);
        const std::uint32_t other = lanes & ~int_mask_bits<K>(recorded & (kind != I(SurfaceTable::kOther)));
        if (sphere != 0) {
            const Vec3<F> d = point - v;
            const Vec3<F> n = d / vsqrt(dot(d, d));  // normalize
            const vmask<K> m = mask_from_bits<K>(sphere);
            for (int a = 0; a < 3; ++a) {
                geometric_normal[a] = select(m, n[a], geometric_normal[a]);
                shading_normal[a] = select(m, n[a], shading_normal[a]);
            }
        }
        if (smooth != 0) {
            // smooth_normal: the vertex normals at the barycentrics. Every
            // lane reads a smooth triangle's (another primitive's index
            // could lie past the triangle arrays).
            const TriangleSoA& tri = table.scene_.triangles;
            const I triangle = xsimd::select(smooth_lanes, prim, I(first_lane<K>(prim, smooth)));
            const I tri3 = gather_ints<K>(reinterpret_cast<const std::int32_t*>(table.scene_.prims.data()),
                                          shift_left<K>(triangle, 1) + I(1)) *
                           I(3);
            const F u = in.has_uv ? in.u : gather_floats<K>(hit_words, hit4 + I(2));
            const F w2 = in.has_uv ? in.v : gather_floats<K>(hit_words, hit4 + I(3));
            const F w = F(1.0f) - u - w2;
            const auto vertex_normal = [&](const std::vector<Vec3f>& n) {
                const auto* words = reinterpret_cast<const float*>(n.data());
                return Vec3<F>{gather_floats<K>(words, tri3), gather_floats<K>(words, tri3 + I(1)),
                               gather_floats<K>(words, tri3 + I(2))};
            };
            const Vec3<F> n = vertex_normal(tri.n0) * w + vertex_normal(tri.n1) * u + vertex_normal(tri.n2) * w2;
            const F len = vsqrt(dot(n, n));
            const vmask<K> m = mask_from_bits<K>(smooth) & (len > F(0.0f));
            const Vec3<F> unit = n / len;
            for (int a = 0; a < 3; ++a) shading_normal[a] = select(m, unit[a], shading_normal[a]);
        }
        if (cone != 0) {
            // cone_normal, normalised, operation for operation (the same
            // bits: contraction is off). Every lane reads a cone's ends.
            const ConeSoA& c = table.scene_.cones;
            const I any_cone = xsimd::select(cone_lanes, prim, I(first_lane<K>(prim, cone)));
            const I cone_index = gather_ints<K>(reinterpret_cast<const std::int32_t*>(table.scene_.prims.data()),
                                           shift_left<K>(any_cone, 1) + I(1));
            const I index3 = cone_index * I(3);
            const auto end = [&](const std::vector<Vec3f>& ends) {
                const auto* words = reinterpret_cast<const float*>(ends.data());
                return Vec3<F>{gather_floats<K>(words, index3), gather_floats<K>(words, index3 + I(1)),
                               gather_floats<K>(words, index3 + I(2))};
            };
            const Vec3<F> base = end(c.base), axis = end(c.apex) - base;
            const F rb = gather_floats<K>(c.base_radius.data(), cone_index),
                    ra = gather_floats<K>(c.apex_radius.data(), cone_index);
            const F h = vsqrt(dot(axis, axis));
            const Vec3<F> w = axis / h;
            const F k = (ra - rb) / h;
            const F s = dot(point - base, w);
            const Vec3<F> perp = (point - base) - w * s;
            const Vec3<F> n = perp - w * ((rb + k * s) * k);
            const Vec3<F> unit = n / vsqrt(dot(n, n));
            const vmask<K> m = mask_from_bits<K>(cone);
            for (int a = 0; a < 3; ++a) {
                geometric_normal[a] = select(m, unit[a], geometric_normal[a]);
                shading_normal[a] = select(m, unit[a], shading_normal[a]);
            }
        }
        if (other != 0) {
            // Height fields and instanced primitives: at(), lane by lane.
            alignas(64) float lane_arrays[9][K];
            alignas(64) std::int32_t lane_index[K], lane_material[K];
            for (int a = 0; a < 3; ++a) {
                point[a].store_aligned(lane_arrays[a]);
                geometric_normal[a].store_aligned(lane_arrays[3 + a]);
                shading_normal[a].store_aligned(lane_arrays[6 + a]);
            }
            index.store_aligned(lane_index);
            material.store_aligned(lane_material);
            for (std::uint32_t bits = other; bits != 0; bits &= bits - 1) {
                const int l = std::countr_zero(bits);
                const auto i = std::size_t(lane_index[l]);
                const Surface s = table.at(rays[i], hits[i]);
                for (int a = 0; a < 3; ++a) {
                    lane_arrays[a][l] = s.point[a];
                    lane_arrays[3 + a][l] = s.geometric_normal[a];
                    lane_arrays[6 + a][l] = s.shading_normal[a];
                }
                lane_material[l] = std::int32_t(s.material);
            }
            for (int a = 0; a < 3; ++a) {
                point[a] = F::load_aligned(lane_arrays[a]);
                geometric_normal[a] = F::load_aligned(lane_arrays[3 + a]);
                shading_normal[a] = F::load_aligned(lane_arrays[6 + a]);
            }
            material = I::load_aligned(lane_material);
        }
    }
};

}  // namespace raypack
