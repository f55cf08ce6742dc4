#pragma once
// Lanes read from scattered addresses and lanes packed together: the
// gathers and compressions of the shading loops that take hits in ray
// order (render/surface_lanes.h), with scalar loops where the build has no
// such instructions (SSE4.2 has neither; AVX2 has gathers only).
#include <bit>
#include <cstdint>

#include "kernels/simd.h"

namespace raypack {

/// v << n and v >> n (arithmetic) in lanes of 32-bit integers. The AVX-512
/// forms with a zeroed source: xsimd's start from an undefined register,
/// which gcc 12 warns about.
template <int K>
RAYPACK_INLINE vint<K> shift_left(const vint<K>& v, unsigned n) {
#if defined(__AVX512F__)
    if constexpr (K == 16) return vint<K>(_mm512_maskz_slli_epi32(__mmask16(0xFFFF), v, n));
#endif
    return v << int(n);
}
template <int K>
RAYPACK_INLINE vint<K> shift_right(const vint<K>& v, unsigned n) {
#if defined(__AVX512F__)
    if constexpr (K == 16) return vint<K>(_mm512_maskz_srai_epi32(__mmask16(0xFFFF), v, n));
#endif
    return v >> int(n);
}

/// base[index[l]] in lane l (indices in floats from base).
template <int K>
RAYPACK_INLINE vfloat<K> gather_floats(const float* base, const vint<K>& index) {
#if defined(__AVX512F__)
    // The masked forms: the plain ones start from an undefined register,
    // which gcc 12 warns about.
    if constexpr (K == 16)
        return vfloat<K>(_mm512_mask_i32gather_ps(_mm512_setzero_ps(), __mmask16(0xFFFF), static_cast<__m512i>(index), base, 4));
#endif
#if defined(__AVX2__)
    if constexpr (K == 8)
        return vfloat<K>(_mm256_mask_i32gather_ps(_mm256_setzero_ps(), base, static_cast<__m256i>(index),
                                                  _mm256_castsi256_ps(_mm256_set1_epi32(-1)), 4));
#endif
    alignas(64) std::int32_t i[K];
    alignas(64) float out[K];
    index.store_aligned(i);
    for (int l = 0; l < K; ++l) out[l] = base[i[l]];
    return vfloat<K>::load_aligned(out);
}

/// The 32-bit integers base[index[l]] in lane l.
template <int K>
RAYPACK_INLINE vint<K> gather_ints(const std::int32_t* base, const vint<K>& index) {
#if defined(__AVX512F__)
    if constexpr (K == 16)
        return vint<K>(_mm512_mask_i32gather_epi32(_mm512_setzero_si512(), __mmask16(0xFFFF), static_cast<__m512i>(index), base, 4));
#endif
#if defined(__AVX2__)
    if constexpr (K == 8)
        return vint<K>(_mm256_mask_i32gather_epi32(_mm256_setzero_si256(), base, static_cast<__m256i>(index),
                                                   _mm256_set1_epi32(-1), 4));
#endif
    alignas(64) std::int32_t i[K], out[K];
    index.store_aligned(i);
    for (int l = 0; l < K; ++l) out[l] = base[i[l]];
    return vint<K>::load_aligned(out);
}

/// The lanes `bits` of v moved to the first popcount(bits) lanes, in lane
/// order, and stored as K floats at out (the lanes after them are garbage:
/// out needs room for K).
template <int K>
RAYPACK_INLINE void store_packed(float* out, const vfloat<K>& v, std::uint32_t bits) {
#if defined(__AVX512F__)
    if constexpr (K == 16) {
        // Compressed in a register, then stored whole: a compressing store
        // to memory is microcoded and slow on AMD's cores.
        _mm512_storeu_ps(out, _mm512_maskz_compress_ps(__mmask16(bits), v));
        return;
    }
#endif
    alignas(64) float in[K];
    v.store_aligned(in);
    for (; bits != 0; bits &= bits - 1) *out++ = in[std::countr_zero(bits)];
}
template <int K>
RAYPACK_INLINE void store_packed(std::int32_t* out, const vint<K>& v, std::uint32_t bits) {
#if defined(__AVX512F__)
    if constexpr (K == 16) {
        _mm512_storeu_si512(out, _mm512_maskz_compress_epi32(__mmask16(bits), v));
        return;
    }
#endif
    alignas(64) std::int32_t in[K];
    v.store_aligned(in);
    for (; bits != 0; bits &= bits - 1) *out++ = in[std::countr_zero(bits)];
}

/// The first of the lanes `bits` (not 0) of v.
template <int K>
RAYPACK_INLINE std::int32_t first_lane(const vint<K>& v, std::uint32_t bits) {
#if defined(__AVX512F__)
    if constexpr (K == 16)
        // A zero-masked extract: gcc 12 warns on the cast's undefined operand.
        return _mm_cvtsi128_si32(
            _mm512_maskz_extracti32x4_epi32(__mmask8(0xF), _mm512_maskz_compress_epi32(__mmask16(bits & (0u - bits)), v), 0));
#endif
    alignas(64) std::int32_t lanes[K];
    v.store_aligned(lanes);
    return lanes[std::countr_zero(bits)];
}

/// Lanes of 32-bit integers as a float mask (lane l set where m's lane l is).
template <int K>
RAYPACK_INLINE std::uint32_t int_mask_bits(const xsimd::batch_bool<std::int32_t, typename SimdWidth<K>::Arch>& m) {
#if defined(__AVX512F__)
    if constexpr (K == 16) return std::uint32_t(static_cast<__mmask16>(m));
#endif
#if defined(__AVX2__)
    if constexpr (K == 8) return std::uint32_t(_mm256_movemask_ps(_mm256_castsi256_ps(m)));
#endif
    if constexpr (K == 4) return std::uint32_t(_mm_movemask_ps(_mm_castsi128_ps(m)));
}

}  // namespace raypack
