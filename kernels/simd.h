#pragma once
// Lane types. Every kernel is a template over a lane type F: float or double
// (width 1, the scalar path) or xsimd::batch<float, Arch> (width 4, 8, 16).
// The same source then serves K rays against one primitive (ray fields are
// vectors, primitive fields broadcast) and one ray against M primitives
// (the other way round). Width 1 maps to plain float/bool, after Embree's
// common/simd/varying.h.
#include <xsimd/xsimd.hpp>

#include <cmath>
#include <cstdint>
#include <type_traits>

/// Kernels and lane operations are small and sit in hot loops; gcc declines
/// to inline them at width 16 on its own, which costs a call and a spill of
/// every packet (seen in the aabb/plain/16 assembly).
#define RAYPACK_INLINE inline __attribute__((always_inline))

namespace raypack {

template <int K>
struct SimdWidth;  // lane types for K lanes of float

template <>
struct SimdWidth<1> {
    using Float = float;
    using Mask = bool;
    using Int = std::int32_t;
};
#if defined(__SSE4_2__)
template <>
struct SimdWidth<4> {
    using Arch = xsimd::sse4_2;
    using Float = xsimd::batch<float, Arch>;
    using Mask = xsimd::batch_bool<float, Arch>;
    using Int = xsimd::batch<std::int32_t, Arch>;
};
#endif
#if defined(__AVX2__)
template <>
struct SimdWidth<8> {
    using Arch = xsimd::avx2;
    using Float = xsimd::batch<float, Arch>;
    using Mask = xsimd::batch_bool<float, Arch>;
    using Int = xsimd::batch<std::int32_t, Arch>;
};
#endif
#if defined(__AVX512BW__)
template <>
struct SimdWidth<16> {
    using Arch = xsimd::avx512bw;
    using Float = xsimd::batch<float, Arch>;
    using Mask = xsimd::batch_bool<float, Arch>;
    using Int = xsimd::batch<std::int32_t, Arch>;
};
#endif

/// True when this translation unit can use K lanes.
template <int K>
inline constexpr bool kWidthCompiled = requires { typename SimdWidth<K>::Float; };

template <int K> using vfloat = typename SimdWidth<K>::Float;
template <int K> using vmask = typename SimdWidth<K>::Mask;
template <int K> using vint = typename SimdWidth<K>::Int;

/// Lane type traits: the mask type and the lane count of F.
template <class F> struct LaneTraits {  // xsimd batches
    using Mask = typename F::batch_bool_type;
    static constexpr int width = int(F::size);
};
template <> struct LaneTraits<float> { using Mask = bool; static constexpr int width = 1; };
template <> struct LaneTraits<double> { using Mask = bool; static constexpr int width = 1; };
/// long double: scalar only, for high-precision references in tests.
template <> struct LaneTraits<long double> { using Mask = bool; static constexpr int width = 1; };
template <class F> using mask_of = typename LaneTraits<F>::Mask;
template <class F> inline constexpr int lanes_of = LaneTraits<F>::width;
/// True when F's masks live in AVX-512 mask registers (width 16). On Zen 4
/// every instruction that writes one (a compare) takes a cycle of the FMA
/// pipes, as a zmm multiply does (docs/kernels.md, "Speed-ups over width 1").
template <class F> inline constexpr bool kMaskRegisters = lanes_of<F> == 16;

// ---- Width-generic operations ---------------------------------------------
// Scalars get plain overloads; batches use xsimd's. Kernels call these
// unqualified, so the same source compiles for every lane type.

RAYPACK_INLINE bool any(bool m) { return m; }
RAYPACK_INLINE bool none(bool m) { return !m; }
RAYPACK_INLINE bool all(bool m) { return m; }
template <class A> RAYPACK_INLINE bool any(const xsimd::batch_bool<float, A>& m) { return xsimd::any(m); }
template <class A> RAYPACK_INLINE bool none(const xsimd::batch_bool<float, A>& m) { return xsimd::none(m); }
template <class A> RAYPACK_INLINE bool all(const xsimd::batch_bool<float, A>& m) { return xsimd::all(m); }

template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
RAYPACK_INLINE T select(bool m, T a, T b) { return m ? a : b; }
RAYPACK_INLINE bool select(bool m, bool a, bool b) { return m ? a : b; }
/// For 4 and 8 lanes on AVX-512VL machines one vpternlogd on the vector
/// mask: gcc otherwise turns xsimd's blendv into a compare into a mask
/// register plus a masked move, and that compare (like vblendvps) takes a
/// slot on the two multiply/FMA pipes the kernels saturate. Same bits.
template <class A>
RAYPACK_INLINE xsimd::batch<float, A> select(const xsimd::batch_bool<float, A>& m, const xsimd::batch<float, A>& a,
                                             const xsimd::batch<float, A>& b) {
#if defined(__AVX512VL__)
    if constexpr (sizeof(a) == 16)
        return _mm_castsi128_ps(
            _mm_ternarylogic_epi32(_mm_castps_si128(m), _mm_castps_si128(a), _mm_castps_si128(b), 0xCA));
    else if constexpr (sizeof(a) == 32)
        return _mm256_castsi256_ps(
            _mm256_ternarylogic_epi32(_mm256_castps_si256(m), _mm256_castps_si256(a), _mm256_castps_si256(b), 0xCA));
    else
#endif
        return xsimd::select(m, a, b);
}

// x86 minps/maxps return the second operand when the comparison is
// unordered, which is exactly a < b ? a : b; gcc emits minss/maxss for the
// scalar form. The batch forms call the intrinsics: xsimd 8.1's min/max for
// float batches on avx2 resolve to a generic compare-and-blend (two
// instructions instead of one).
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
RAYPACK_INLINE T vmin(T a, T b) { return a < b ? a : b; }
template <class T, std::enable_if_t<std::is_floating_point_v<T>, int> = 0>
RAYPACK_INLINE T vmax(T a, T b) { return a > b ? a : b; }
template <class A>
RAYPACK_INLINE xsimd::batch<float, A> vmin(const xsimd::batch<float, A>& a, const xsimd::batch<float, A>& b) {
    if constexpr (sizeof(a) == 16) return _mm_min_ps(a, b);
#if defined(__AVX__)
    else if constexpr (sizeof(a) == 32) return _mm256_min_ps(a, b);
#endif
#if defined(__AVX512F__)
    // Zero-masked with a full mask: the same vminps, without the undefined
    // pass-through operand that makes gcc 12 warn (-Wmaybe-uninitialized).
    else if constexpr (sizeof(a) == 64) return _mm512_maskz_min_ps(__mmask16(0xFFFF), a, b);
#endif
    else static_assert(sizeof(A) == 0, "vmin: unsupported width");
}
template <class A>
RAYPACK_INLINE xsimd::batch<float, A> vmax(const xsimd::batch<float, A>& a, const xsimd::batch<float, A>& b) {
    if constexpr (sizeof(a) == 16) return _mm_max_ps(a, b);
#if defined(__AVX__)
    else if constexpr (sizeof(a) == 32) return _mm256_max_ps(a, b);
#endif
#if defined(__AVX512F__)
    else if constexpr (sizeof(a) == 64) return _mm512_maskz_max_ps(__mmask16(0xFFFF), a, b);
#endif
    else static_assert(sizeof(A) == 0, "vmax: unsupported width");
}

/// Makes the compiler hold `v` in one register from here on. A three-operand
/// FMA overwrites one of its inputs, and gcc 12 then reloads an operand that
/// is used twice from memory instead of copying the register (a copy is free
/// at rename). At 512 bits those reloads, not the arithmetic, limited the
/// packet slab test on Zen 4 (aabb/plain/16: 3.8 -> 4.8 G tests/s).
template <class F>
RAYPACK_INLINE void keep_in_register(F& v) {
    if constexpr (std::is_floating_point_v<F>) {
        if constexpr (!std::is_same_v<F, long double>) asm("" : "+v"(v));
    } else {
        typename F::register_type r = v;
        asm("" : "+v"(r));
        v = F(r);
    }
}

/// Fused a * b + c with one rounding, at every width (std::fma compiles to
/// vfmadd under -march=native). Kernels call it only where they want the
/// fusion; the build forbids implicit contraction (see CMakeLists.txt).
RAYPACK_INLINE float vfmadd(float a, float b, float c) { return std::fma(a, b, c); }
RAYPACK_INLINE double vfmadd(double a, double b, double c) { return std::fma(a, b, c); }
RAYPACK_INLINE long double vfmadd(long double a, long double b, long double c) { return std::fma(a, b, c); }
#if defined(__FMA__)
template <class A>
RAYPACK_INLINE xsimd::batch<float, A> vfmadd(const xsimd::batch<float, A>& a, const xsimd::batch<float, A>& b,
                                             const xsimd::batch<float, A>& c) {
    if constexpr (sizeof(a) == 16) return _mm_fmadd_ps(a, b, c);
    else if constexpr (sizeof(a) == 32) return _mm256_fmadd_ps(a, b, c);
#if defined(__AVX512F__)
    else if constexpr (sizeof(a) == 64) return _mm512_fmadd_ps(a, b, c);
#endif
    else static_assert(sizeof(A) == 0, "vfmadd: unsupported width");
}
#endif

/// Fused a * b - c with one rounding (vfmsub; no negation of c).
RAYPACK_INLINE float vfmsub(float a, float b, float c) { return std::fma(a, b, -c); }
RAYPACK_INLINE double vfmsub(double a, double b, double c) { return std::fma(a, b, -c); }
RAYPACK_INLINE long double vfmsub(long double a, long double b, long double c) { return std::fma(a, b, -c); }
#if defined(__FMA__)
template <class A>
RAYPACK_INLINE xsimd::batch<float, A> vfmsub(const xsimd::batch<float, A>& a, const xsimd::batch<float, A>& b,
                                             const xsimd::batch<float, A>& c) {
    if constexpr (sizeof(a) == 16) return _mm_fmsub_ps(a, b, c);
    else if constexpr (sizeof(a) == 32) return _mm256_fmsub_ps(a, b, c);
#if defined(__AVX512F__)
    else if constexpr (sizeof(a) == 64) return _mm512_fmsub_ps(a, b, c);
#endif
    else static_assert(sizeof(A) == 0, "vfmsub: unsupported width");
}
#endif

/// Fused c - a * b with one rounding (vfnmadd; no negation of a).
RAYPACK_INLINE float vfnmadd(float a, float b, float c) { return std::fma(-a, b, c); }
RAYPACK_INLINE double vfnmadd(double a, double b, double c) { return std::fma(-a, b, c); }
RAYPACK_INLINE long double vfnmadd(long double a, long double b, long double c) { return std::fma(-a, b, c); }
#if defined(__FMA__)
template <class A>
RAYPACK_INLINE xsimd::batch<float, A> vfnmadd(const xsimd::batch<float, A>& a, const xsimd::batch<float, A>& b,
                                              const xsimd::batch<float, A>& c) {
    if constexpr (sizeof(a) == 16) return _mm_fnmadd_ps(a, b, c);
    else if constexpr (sizeof(a) == 32) return _mm256_fnmadd_ps(a, b, c);
#if defined(__AVX512F__)
    else if constexpr (sizeof(a) == 64) return _mm512_fnmadd_ps(a, b, c);
#endif
    else static_assert(sizeof(A) == 0, "vfnmadd: unsupported width");
}
#endif

RAYPACK_INLINE float vsqrt(float x) { return std::sqrt(x); }
RAYPACK_INLINE double vsqrt(double x) { return std::sqrt(x); }
RAYPACK_INLINE long double vsqrt(long double x) { return std::sqrt(x); }
template <class A>
RAYPACK_INLINE xsimd::batch<float, A> vsqrt(const xsimd::batch<float, A>& x) {
#if defined(__AVX512F__)
    // The all-lanes masked form is the same vsqrtps, without the undefined
    // pass-through operand gcc 12 warns about.
    if constexpr (sizeof(x) == 64) return _mm512_mask_sqrt_ps(x, __mmask16(0xFFFF), x);
    else
#endif
        return xsimd::sqrt(x);
}
RAYPACK_INLINE float vabs(float x) { return std::fabs(x); }
RAYPACK_INLINE double vabs(double x) { return std::fabs(x); }
RAYPACK_INLINE long double vabs(long double x) { return std::fabs(x); }
template <class A> RAYPACK_INLINE xsimd::batch<float, A> vabs(const xsimd::batch<float, A>& x) { return xsimd::abs(x); }

/// Copy the sign of `s` onto `x` (works for -0).
RAYPACK_INLINE float copysign_of(float x, float s) { return std::copysign(x, s); }
RAYPACK_INLINE double copysign_of(double x, double s) { return std::copysign(x, s); }
RAYPACK_INLINE long double copysign_of(long double x, long double s) { return std::copysign(x, s); }
template <class A>
RAYPACK_INLINE xsimd::batch<float, A> copysign_of(const xsimd::batch<float, A>& x, const xsimd::batch<float, A>& s) {
    return xsimd::copysign(x, s);
}

/// Rounding to the nearest integer (ties to even, the default mode) and
/// down, at every width: roundps in lanes, the same results as the scalars.
RAYPACK_INLINE float round_nearest(float x) { return std::nearbyint(x); }
RAYPACK_INLINE float round_down(float x) { return std::floor(x); }
template <class A>
RAYPACK_INLINE xsimd::batch<float, A> round_nearest(const xsimd::batch<float, A>& x) { return xsimd::nearbyint(x); }
template <class A>
RAYPACK_INLINE xsimd::batch<float, A> round_down(const xsimd::batch<float, A>& x) { return xsimd::floor(x); }

/// Mask lanes as bits, lane i in bit i.
RAYPACK_INLINE std::uint32_t mask_bits(bool m) { return m ? 1u : 0u; }
template <class A>
RAYPACK_INLINE std::uint32_t mask_bits(const xsimd::batch_bool<float, A>& m) {
    if constexpr (std::is_same_v<A, xsimd::sse4_2>) return std::uint32_t(_mm_movemask_ps(m));
#if defined(__AVX2__)
    else if constexpr (std::is_same_v<A, xsimd::avx2>) return std::uint32_t(_mm256_movemask_ps(m));
#endif
#if defined(__AVX512BW__)
    else if constexpr (std::is_same_v<A, xsimd::avx512bw>) return std::uint32_t(static_cast<__mmask16>(m));
#endif
    else static_assert(sizeof(A) == 0, "mask_bits: unsupported arch");
}

/// The lanes `bits` as a mask, lane i from bit i (mask_bits' inverse).
template <int K>
RAYPACK_INLINE vmask<K> mask_from_bits(std::uint32_t bits) {
#if defined(__AVX512F__)
    if constexpr (K == 16) return vmask<K>(__mmask16(bits));
#endif
#if defined(__AVX2__)
    if constexpr (K == 8) {
        const __m256i lane_bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
        const __m256i b = _mm256_and_si256(_mm256_set1_epi32(int(bits)), lane_bit);
        return vmask<K>(_mm256_castsi256_ps(_mm256_cmpeq_epi32(b, lane_bit)));
    }
#endif
    if constexpr (K == 4) {
        const __m128i lane_bit = _mm_setr_epi32(1, 2, 4, 8);
        const __m128i b = _mm_and_si128(_mm_set1_epi32(int(bits)), lane_bit);
        return vmask<K>(_mm_castsi128_ps(_mm_cmpeq_epi32(b, lane_bit)));
    }
}

/// Loads and stores of K consecutive floats.
template <class F>
RAYPACK_INLINE F load_lanes(const float* p) {
    if constexpr (std::is_floating_point_v<F>) return F(*p);
    else return F::load_unaligned(p);
}
template <class F>
RAYPACK_INLINE void store_lanes(float* p, const F& v) {
    if constexpr (std::is_floating_point_v<F>) *p = float(v);
    else v.store_unaligned(p);
}

/// Smallest and largest lane of x (a NaN lane may or may not be dropped).
RAYPACK_INLINE float lane_min4(__m128 a) {
    a = _mm_min_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(1, 0, 3, 2)));
    return _mm_cvtss_f32(_mm_min_ps(a, _mm_shuffle_ps(a, a, _MM_SHUFFLE(2, 3, 0, 1))));
}
template <int K>
RAYPACK_INLINE float lane_min(const vfloat<K>& x) {
    if constexpr (K == 16) {
#if defined(__AVX512F__)
        // Zero-masked extracts: gcc 12 warns on the undefined operand of
        // _mm512_reduce_min_ps and _mm512_castps512_ps256.
        const __m512d d = _mm512_castps_pd(x);
        const __m256 lo = _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(__mmask8(0xFF), d, 0));
        const __m256 hi = _mm256_castpd_ps(_mm512_maskz_extractf64x4_pd(__mmask8(0xFF), d, 1));
        return lane_min<8>(_mm256_min_ps(lo, hi));
#endif
    } else if constexpr (K == 8) {
        const __m256 v = x;
        return lane_min4(_mm_min_ps(_mm256_castps256_ps128(v), _mm256_extractf128_ps(v, 1)));
    } else {
        return lane_min4(x);
    }
}
template <int K>
RAYPACK_INLINE float lane_max(const vfloat<K>& x) {
    return -lane_min<K>(-x);  // negation is exact
}

/// Lane i of v, for tests and scalar fallbacks.
template <class F>
float lane(const F& v, int i) {
    if constexpr (std::is_floating_point_v<F>) {
        (void)i;
        return float(v);
    } else {
        alignas(64) float buf[F::size];
        v.store_aligned(buf);
        return buf[i];
    }
}
inline bool lane(bool m, int) { return m; }
template <class A>
bool lane(const xsimd::batch_bool<float, A>& m, int i) { return (mask_bits(m) >> i) & 1u; }

}  // namespace raypack
