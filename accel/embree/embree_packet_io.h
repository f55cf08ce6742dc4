#pragma once
// raypack's rays into Embree's packets and Embree's answers back, for the
// Embree backend alone. At Embree's speed on coherent rays (~10 ns a ray)
// a lane-by-lane copy costs a third of the trace (perf on tetra's camera
// rays), so whole packets are moved with 8 x 8 transposes: a Rayf is eight
// floats (org, dir, tnear, tfar), one AVX register.
#include <immintrin.h>

#include <cstdint>
#include <cstring>
#include <limits>

#include <embree3/rtcore.h>

#include "kernels/ray.h"
#include "kernels/ray_transpose.h"

namespace raypack::embree_io {

/// Fields Embree reads but never writes (time, mask, id, flags): set once
/// per packet object, not per trace.
template <int K, class RayK>
void set_constant_fields(RayK& ray) {
    for (int i = 0; i < K; ++i) {
        ray.time[i] = 0.0f;
        ray.mask[i] = 0xFFFFFFFFu;
        ray.id[i] = unsigned(i);
        ray.flags[i] = 0;
    }
}

/// Lane i of `ray` from `r`: org, dir, tnear, tfar.
template <class RayK>
void set_lane(RayK& ray, int i, const Rayf& r) {
    ray.org_x[i] = r.org.x;
    ray.org_y[i] = r.org.y;
    ray.org_z[i] = r.org.z;
    ray.dir_x[i] = r.dir.x;
    ray.dir_y[i] = r.dir.y;
    ray.dir_z[i] = r.dir.z;
    ray.tnear[i] = r.tnear;
    ray.tfar[i] = r.tfar;
}

#if defined(__AVX2__)
/// Whether all 8 rays of `row` start at `origin` (lane 0 of the packet).
inline bool same_origin8(const __m256 (&row)[8], const Rayf& first) {
    const int eq = _mm256_movemask_ps(_mm256_cmp_ps(row[0], _mm256_set1_ps(first.org.x), _CMP_EQ_OQ)) &
                   _mm256_movemask_ps(_mm256_cmp_ps(row[1], _mm256_set1_ps(first.org.y), _CMP_EQ_OQ)) &
                   _mm256_movemask_ps(_mm256_cmp_ps(row[2], _mm256_set1_ps(first.org.z), _CMP_EQ_OQ));
    return eq == 0xFF;
}

/// Rays [0, 8) into lanes [offset, offset + 8) of `ray`.
template <class RayK>
bool load8(const Rayf* rays, RayK& ray, int offset) {
    __m256 row[8];
    transpose_rays8(rays, row);
    _mm256_storeu_ps(ray.org_x + offset, row[0]);
    _mm256_storeu_ps(ray.org_y + offset, row[1]);
    _mm256_storeu_ps(ray.org_z + offset, row[2]);
    _mm256_storeu_ps(ray.dir_x + offset, row[3]);
    _mm256_storeu_ps(ray.dir_y + offset, row[4]);
    _mm256_storeu_ps(ray.dir_z + offset, row[5]);
    _mm256_storeu_ps(ray.tnear + offset, row[6]);
    _mm256_storeu_ps(ray.tfar + offset, row[7]);
    return same_origin8(row, rays[0]);
}
#endif

/// No hit yet in any lane (geomID, primID and instID invalid).
template <int K, class HitK>
void clear_hits(HitK& hit) {
#if defined(__AVX2__)
    if constexpr (K % 8 == 0) {
        const __m256i invalid = _mm256_set1_epi32(int(RTC_INVALID_GEOMETRY_ID));
        for (int h = 0; h < K; h += 8) {
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(hit.geomID + h), invalid);
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(hit.primID + h), invalid);
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(hit.instID[0] + h), invalid);
        }
        return;
    }
#endif
    for (int i = 0; i < K; ++i) hit.geomID[i] = hit.primID[i] = hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
}

/// A full packet of K rays into `ray`; returns whether they share one origin
/// (Embree's coherent context then applies).
template <int K, class RayK>
bool load_full(const Rayf* rays, RayK& ray) {
#if defined(__AVX2__)
    if constexpr (K >= 8) {
        bool coherent = true;
        for (int h = 0; h < K; h += 8) coherent &= load8(rays + h, ray, h) && rays[h].org == rays[0].org;
        return coherent;
    }
#endif
    bool coherent = true;
    for (int i = 0; i < K; ++i) {
        set_lane(ray, i, rays[i]);
        coherent &= rays[i].org == rays[0].org;
    }
    return coherent;
}

/// Embree's answer for lanes [0, n) as raypack hits. `base[g]` is the
/// global number of geometry g's primitive 0 when its primitives are
/// numbered consecutively (else `table` maps geometry, primID -> global).
template <int K, class RayHitK, class Table>
void store_hits(const RayHitK& rh, int n, const std::uint32_t* base, bool consecutive, const Table& table,
                Hitf* hits) {
#if defined(__AVX2__)
    if (consecutive && n == K && K >= 8) {
        const __m256i invalid = _mm256_set1_epi32(int(RTC_INVALID_GEOMETRY_ID));
        const __m256i bases = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(base));  // 8 geometries at most
        for (int h = 0; h < K; h += 8) {
            const __m256i geom = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rh.hit.geomID + h));
            const __m256 miss = _mm256_castsi256_ps(_mm256_cmpeq_epi32(geom, invalid));
            const __m256i prim = _mm256_add_epi32(
                _mm256_permutevar8x32_epi32(bases, geom),
                _mm256_loadu_si256(reinterpret_cast<const __m256i*>(rh.hit.primID + h)));
            const __m256 t = _mm256_blendv_ps(_mm256_loadu_ps(rh.ray.tfar + h),
                                              _mm256_set1_ps(std::numeric_limits<float>::infinity()), miss);
            const __m256 p = _mm256_blendv_ps(_mm256_castsi256_ps(prim), _mm256_castsi256_ps(invalid), miss);
            const __m256 u = _mm256_andnot_ps(miss, _mm256_loadu_ps(rh.hit.u + h));
            const __m256 v = _mm256_andnot_ps(miss, _mm256_loadu_ps(rh.hit.v + h));
            store_hits8(t, p, u, v, hits + h);
        }
        return;
    }
#endif
    for (int i = 0; i < n; ++i) {
        Hitf hit;
        if (rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID) {
            hit.t = rh.ray.tfar[i];
            hit.prim = table[rh.hit.geomID[i]][rh.hit.primID[i]];
            hit.u = rh.hit.u[i];
            hit.v = rh.hit.v[i];
        }
        hits[i] = hit;
    }
}

/// Lanes [0, n) occluded (Embree sets tfar to -inf) as 0/1 bytes.
template <int K, class RayK>
void store_occluded(const RayK& ray, int n, std::uint8_t* occluded) {
#if defined(__AVX2__) && defined(__BMI2__)
    if (n == K && K >= 8) {
        const __m256 minus_inf = _mm256_set1_ps(-std::numeric_limits<float>::infinity());
        for (int h = 0; h < K; h += 8) {
            const unsigned bits =
                unsigned(_mm256_movemask_ps(_mm256_cmp_ps(_mm256_loadu_ps(ray.tfar + h), minus_inf, _CMP_EQ_OQ)));
            const std::uint64_t bytes = _pdep_u64(bits, 0x0101010101010101ull);
            std::memcpy(occluded + h, &bytes, 8);
        }
        return;
    }
#endif
    for (int i = 0; i < n; ++i) occluded[i] = ray.tfar[i] == -std::numeric_limits<float>::infinity() ? 1 : 0;
}

}  // namespace raypack::embree_io
