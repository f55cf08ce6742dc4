#pragma once
// Gathers of 32-bit values by 32-bit lane indices, as hardware gathers, and
// lookups in a table of at most 32 entries as one permute.
// xsimd 8.1's batch::gather names its kernel with explicit template
// arguments that the AVX2 / AVX-512 float overloads do not take, so it falls
// back to a generic loop through an out-of-line call: 27% of a height-field
// camera trace (perf) before this header.
#include <cstdint>

#include "kernels/simd.h"

namespace raypack {

namespace gather_detail {
/// The portable form, lane by lane through memory; lanes outside `bits`
/// read nothing and are 0.
template <class V, class T, class I>
RAYPACK_INLINE V by_lanes(const T* base, const I& index, std::uint32_t bits = ~0u) {
    constexpr int width = int(I::size);
    alignas(64) std::int32_t at[width];
    alignas(64) T out[width];
    index.store_aligned(at);
    for (int k = 0; k < width; ++k) out[k] = (bits >> k) & 1u ? base[at[k]] : T(0);
    return V::load_aligned(out);
}
}  // namespace gather_detail

/// Lane k of the result is base[index[k]] in the lanes of `m`, 0 in the
/// others, which read nothing (fewer loads: Zen 4 pays for a gather element
/// by element). F = float or a float batch, I the matching int32 lanes.
template <class F, class I>
RAYPACK_INLINE F gather_floats(const float* base, const I& index, const mask_of<F>& m) {
    if constexpr (std::is_same_v<F, float>) {
        return m ? base[index] : 0.0f;
    } else {
        constexpr int width = lanes_of<F>;
#if defined(__AVX512F__)
        if constexpr (width == 16)
            return F(_mm512_mask_i32gather_ps(_mm512_setzero_ps(), __mmask16(mask_bits(m)), __m512i(index), base, 4));
#endif
#if defined(__AVX2__)
        if constexpr (width == 8)
            return F(_mm256_mask_i32gather_ps(_mm256_setzero_ps(), base, __m256i(index), __m256(m), 4));
        if constexpr (width == 4) return F(_mm_mask_i32gather_ps(_mm_setzero_ps(), base, __m128i(index), __m128(m), 4));
#endif
        return gather_detail::by_lanes<F>(base, index, mask_bits(m));
    }
}

/// base[index[k]] in every lane, for 32-bit integers.
template <class I>
RAYPACK_INLINE I gather_ints(const std::int32_t* base, const I& index) {
    if constexpr (std::is_same_v<I, std::int32_t>) {
        return base[index];
    } else {
        constexpr int width = int(I::size);
#if defined(__AVX512F__)
        if constexpr (width == 16) return I(_mm512_i32gather_epi32(__m512i(index), base, 4));
#endif
#if defined(__AVX2__)
        if constexpr (width == 8) return I(_mm256_i32gather_epi32(base, __m256i(index), 4));
        if constexpr (width == 4) return I(_mm_i32gather_epi32(base, __m128i(index), 4));
#endif
        return gather_detail::by_lanes<I>(base, index);
    }
}

/// table[index[k]] for a table of 32 entries (index < 32), held at 16 lanes
/// in two vectors (lo = entries 0-15, hi = 16-31): one vpermi2d, 3 cycles
/// instead of a gather's 30 or so. Other widths gather from the table.
template <class I>
RAYPACK_INLINE I lookup32(const std::int32_t (&table)[32], const I& lo, const I& hi, const I& index) {
#if defined(__AVX512F__)
    if constexpr (int(I::size) == 16) return I(_mm512_permutex2var_epi32(__m512i(lo), __m512i(index), __m512i(hi)));
#endif
    return gather_ints(table, index);
}

}  // namespace raypack
