#pragma once
// Rays and hits between the exchange layout (one struct per ray) and lanes,
// eight at a time with AVX shuffles. A Rayf is eight floats and a Hitf four,
// so 8 rays are an 8 x 8 transpose and 8 hits a 4 x 8 one. Element by
// element through the stack, the wide loads that follow narrow stores miss
// store forwarding: on tetra's camera rays that copy was a fifth of a packet
// trace (perf).
#include <immintrin.h>

#include "kernels/ray.h"

namespace raypack {

#if defined(__AVX2__)
static_assert(sizeof(Rayf) == 32, "a Rayf must be eight floats for the transposed load");
static_assert(sizeof(Hitf) == 16, "a Hitf must be four 32-bit words for the transposed store");

/// An 8 x 8 transpose in registers: lane j of r[i] goes to lane i of r[j].
inline void transpose8x8(__m256 (&r)[8]) {
    const __m256 t0 = _mm256_unpacklo_ps(r[0], r[1]), t1 = _mm256_unpackhi_ps(r[0], r[1]);
    const __m256 t2 = _mm256_unpacklo_ps(r[2], r[3]), t3 = _mm256_unpackhi_ps(r[2], r[3]);
    const __m256 t4 = _mm256_unpacklo_ps(r[4], r[5]), t5 = _mm256_unpackhi_ps(r[4], r[5]);
    const __m256 t6 = _mm256_unpacklo_ps(r[6], r[7]), t7 = _mm256_unpackhi_ps(r[6], r[7]);
    const __m256 s0 = _mm256_shuffle_ps(t0, t2, 0x44), s1 = _mm256_shuffle_ps(t0, t2, 0xEE);
    const __m256 s2 = _mm256_shuffle_ps(t1, t3, 0x44), s3 = _mm256_shuffle_ps(t1, t3, 0xEE);
    const __m256 s4 = _mm256_shuffle_ps(t4, t6, 0x44), s5 = _mm256_shuffle_ps(t4, t6, 0xEE);
    const __m256 s6 = _mm256_shuffle_ps(t5, t7, 0x44), s7 = _mm256_shuffle_ps(t5, t7, 0xEE);
    r[0] = _mm256_permute2f128_ps(s0, s4, 0x20);
    r[1] = _mm256_permute2f128_ps(s1, s5, 0x20);
    r[2] = _mm256_permute2f128_ps(s2, s6, 0x20);
    r[3] = _mm256_permute2f128_ps(s3, s7, 0x20);
    r[4] = _mm256_permute2f128_ps(s0, s4, 0x31);
    r[5] = _mm256_permute2f128_ps(s1, s5, 0x31);
    r[6] = _mm256_permute2f128_ps(s2, s6, 0x31);
    r[7] = _mm256_permute2f128_ps(s3, s7, 0x31);
}

/// Rows of 8 rays (org.x, org.y, org.z, dir.x, dir.y, dir.z, tnear, tfar),
/// transposed: row[f] lane i is field f of ray i.
inline void transpose_rays8(const Rayf* rays, __m256 (&row)[8]) {
    for (int i = 0; i < 8; ++i) row[i] = _mm256_loadu_ps(reinterpret_cast<const float*>(rays + i));
    transpose8x8(row);
}

/// 8 consecutive hits as four rows of 8 lanes (t, prim's bits, u, v): the
/// inverse of store_hits8.
inline void load_hits8(const Hitf* hits, __m256 (&row)[4]) {
    const float* in = reinterpret_cast<const float*>(hits);
    // Hits 0-1 | 4-5 and 2-3 | 6-7 in the two 128-bit halves.
    const __m256 l0 = _mm256_loadu_ps(in), l1 = _mm256_loadu_ps(in + 8);
    const __m256 l2 = _mm256_loadu_ps(in + 16), l3 = _mm256_loadu_ps(in + 24);
    const __m256 e = _mm256_permute2f128_ps(l0, l2, 0x20), f = _mm256_permute2f128_ps(l0, l2, 0x31);
    const __m256 g = _mm256_permute2f128_ps(l1, l3, 0x20), k = _mm256_permute2f128_ps(l1, l3, 0x31);
    // Per 128-bit half h: e = hit h*4+0, f = +1, g = +2, k = +3 (t, p, u, v each).
    const __m256 a = _mm256_unpacklo_ps(e, f), b = _mm256_unpackhi_ps(e, f);  // t0 t1 p0 p1 | u0 u1 v0 v1
    const __m256 c = _mm256_unpacklo_ps(g, k), d = _mm256_unpackhi_ps(g, k);
    row[0] = _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(a), _mm256_castps_pd(c)));
    row[1] = _mm256_castpd_ps(_mm256_unpackhi_pd(_mm256_castps_pd(a), _mm256_castps_pd(c)));
    row[2] = _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(b), _mm256_castps_pd(d)));
    row[3] = _mm256_castpd_ps(_mm256_unpackhi_pd(_mm256_castps_pd(b), _mm256_castps_pd(d)));
}

/// The other way: rows of fields (transpose_rays8's) as 8 consecutive rays.
inline void store_rays8(__m256 (&row)[8], Rayf* rays) {
    transpose8x8(row);
    for (int i = 0; i < 8; ++i) _mm256_storeu_ps(reinterpret_cast<float*>(rays + i), row[i]);
}

/// Four rows of 8 lanes (t, prim's bits, u, v) as 8 consecutive hits.
inline void store_hits8(__m256 t, __m256 prim, __m256 u, __m256 v, Hitf* hits) {
    const __m256 a = _mm256_unpacklo_ps(t, prim), b = _mm256_unpackhi_ps(t, prim);
    const __m256 c = _mm256_unpacklo_ps(u, v), d = _mm256_unpackhi_ps(u, v);
    const __m256 e = _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(a), _mm256_castps_pd(c)));
    const __m256 f = _mm256_castpd_ps(_mm256_unpackhi_pd(_mm256_castps_pd(a), _mm256_castps_pd(c)));
    const __m256 g = _mm256_castpd_ps(_mm256_unpacklo_pd(_mm256_castps_pd(b), _mm256_castps_pd(d)));
    const __m256 k = _mm256_castpd_ps(_mm256_unpackhi_pd(_mm256_castps_pd(b), _mm256_castps_pd(d)));
    float* out = reinterpret_cast<float*>(hits);
    _mm256_storeu_ps(out, _mm256_permute2f128_ps(e, f, 0x20));
    _mm256_storeu_ps(out + 8, _mm256_permute2f128_ps(g, k, 0x20));
    _mm256_storeu_ps(out + 16, _mm256_permute2f128_ps(e, f, 0x31));
    _mm256_storeu_ps(out + 24, _mm256_permute2f128_ps(g, k, 0x31));
}
#endif

#if defined(__AVX512F__)
// gcc 12 reports the `_mm512_undefined_ps()` inside its own intrinsics as
// maybe uninitialised once they are inlined this deep.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
/// store_hits8 for 16 lanes: the same in-lane shuffles leave hit i + 4j in
/// 128-bit block j of register i; a 4 x 4 transpose of blocks orders them.
inline void store_hits16(__m512 t, __m512 prim, __m512 u, __m512 v, Hitf* hits) {
    const __m512 a = _mm512_unpacklo_ps(t, prim), b = _mm512_unpackhi_ps(t, prim);
    const __m512 c = _mm512_unpacklo_ps(u, v), d = _mm512_unpackhi_ps(u, v);
    const __m512 e = _mm512_castpd_ps(_mm512_unpacklo_pd(_mm512_castps_pd(a), _mm512_castps_pd(c)));
    const __m512 f = _mm512_castpd_ps(_mm512_unpackhi_pd(_mm512_castps_pd(a), _mm512_castps_pd(c)));
    const __m512 g = _mm512_castpd_ps(_mm512_unpacklo_pd(_mm512_castps_pd(b), _mm512_castps_pd(d)));
    const __m512 k = _mm512_castpd_ps(_mm512_unpackhi_pd(_mm512_castps_pd(b), _mm512_castps_pd(d)));
    const __m512 ef_lo = _mm512_shuffle_f32x4(e, f, 0x44), gk_lo = _mm512_shuffle_f32x4(g, k, 0x44);
    const __m512 ef_hi = _mm512_shuffle_f32x4(e, f, 0xEE), gk_hi = _mm512_shuffle_f32x4(g, k, 0xEE);
    float* out = reinterpret_cast<float*>(hits);
    _mm512_storeu_ps(out, _mm512_shuffle_f32x4(ef_lo, gk_lo, 0x88));
    _mm512_storeu_ps(out + 16, _mm512_shuffle_f32x4(ef_lo, gk_lo, 0xDD));
    _mm512_storeu_ps(out + 32, _mm512_shuffle_f32x4(ef_hi, gk_hi, 0x88));
    _mm512_storeu_ps(out + 48, _mm512_shuffle_f32x4(ef_hi, gk_hi, 0xDD));
}
#pragma GCC diagnostic pop
#endif

}  // namespace raypack
