#include "render/sampler.h"

#include <bit>
#include <cmath>
#include <stdexcept>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

namespace raypack {
namespace {

/// A 64-bit finaliser (SplitMix64's, Steele, Lea, Flood 2014) over a few
/// keys: the seed of one (pixel, dimension, purpose).
std::uint64_t mix(std::uint64_t h) {
    h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
    h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
    return h ^ (h >> 31);
}

/// The seed of one (pixel, dimension, purpose), from the pixel's hash
/// (Sampler::pixel: the seed's hash mixed with the pixel number).
std::uint64_t hash_keys(std::uint64_t pixel_hash, std::uint64_t dimension, std::uint64_t purpose) {
    return mix(pixel_hash ^ (dimension * 0x100000001B3ull + purpose + 1));
}

/// [0, 1) from the top 24 bits, so that the float never rounds up to 1.
float unit_float(std::uint32_t bits) { return float(bits >> 8) * 0x1.0p-24f; }

/// A point of stratum c of n along one axis, from 32 random bits: in double,
/// then moved to the float nearest it inside [c / n, (c + 1) / n) (a float
/// sum c + jitter would round up into the next stratum).
float in_stratum(std::uint32_t c, std::uint32_t n, double inv_n, std::uint32_t bits) {
    float f = float((double(c) + double(bits) * 0x1.0p-32) * inv_n);
    // The product f n is exact in double (24 + 32 bits): compare strata exactly.
    while (double(f) * double(n) >= double(c + 1)) f = std::nextafter(f, 0.0f);
    while (double(f) * double(n) < double(c)) f = std::nextafter(f, 1.0f);
    return f;
}

/// A pseudo-random permutation of [0, n) (Kensler, "Correlated
/// Multi-Jittered Sampling", Pixar Technical Memo 13-01, 2013): an
/// invertible hash on the smallest power-of-two range that holds n, walked
/// until it lands below n (cycle walking).
std::uint32_t permute(std::uint32_t i, std::uint32_t n, std::uint32_t key) {
    std::uint32_t w = n - 1;
    w |= w >> 1;
    w |= w >> 2;
    w |= w >> 4;
    w |= w >> 8;
    w |= w >> 16;
    do {
        i ^= key;
        i *= 0xe170893du;
        i ^= key >> 16;
        i ^= (i & w) >> 4;
        i ^= key >> 8;
        i *= 0x0929eb3fu;
        i ^= key >> 23;
        i ^= (i & w) >> 1;
        i *= 1u | key >> 27;
        i *= 0x6935fa69u;
        i ^= (i & w) >> 11;
        i *= 0x74dcb303u;
        i ^= (i & w) >> 2;
        i *= 0x9e501cc3u;
        i ^= (i & w) >> 2;
        i *= 0xc860a3dfu;
        i &= w;
        i ^= i >> 5;
    } while (i >= n);
    return (n & (n - 1)) == 0 ? (i + key) & (n - 1) : (i + key) % n;  // no division for powers of two
}

std::uint32_t reverse_bits(std::uint32_t x) {
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0F0F0F0Fu) | ((x & 0x0F0F0F0Fu) << 4);
    x = ((x >> 8) & 0x00FF00FFu) | ((x & 0x00FF00FFu) << 8);
    return (x >> 16) | (x << 16);
}

/// Owen scrambling of a 32-bit fraction in one hash (Burley, "Practical
/// Hash-based Owen Scrambling", JCGT 2020, after Laine and Karras 2011): in
/// bit-reversed order, each bit is flipped by a function of the bits above
/// it in the fraction, which is what a nested uniform scramble does.
std::uint32_t owen_scramble(std::uint32_t x, std::uint32_t seed) {
    x = reverse_bits(x);
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return reverse_bits(x);
}

/// The first two dimensions of Sobol's sequence as 32-bit fractions: the
/// van der Corput sequence, and the dimension of primitive polynomial x + 1
/// (direction numbers v_k = v_(k-1) ^ (v_(k-1) >> 1)). Any 2^m consecutive
/// aligned points form a (0, m, 2)-net in base 2.
std::uint32_t sobol0(std::uint32_t i) { return reverse_bits(i); }

/// Its direction numbers are Pascal's triangle mod 2: v_k has bit 31 - j
/// set iff the bits of j are a subset of those of k (Lucas), so bit 31 - j
/// of the point is the parity of the set bits k of i with j a subset of k,
/// a superset sum over GF(2) that five shift-xor steps compute (in place of
/// a loop over the bits of i). Bit reversed: bit j of the result.
std::uint32_t sobol1_reversed(std::uint32_t i) {
    i ^= (i >> 1) & 0x55555555u;
    i ^= (i >> 2) & 0x33333333u;
    i ^= (i >> 4) & 0x0F0F0F0Fu;
    i ^= (i >> 8) & 0x00FF00FFu;
    return i ^ ((i >> 16) & 0x0000FFFFu);
}

std::uint32_t sobol1(std::uint32_t i) { return reverse_bits(sobol1_reversed(i)); }

#if defined(__AVX2__)
// Eight draws in SIMD lanes: their 64-bit hashes in one AVX-512 register,
// or in two AVX2 registers of four (AVX2 has no 64-bit multiply: it is
// built from three 32 x 32 -> 64 products). Every function below computes
// its scalar namesake's bits lane by lane.
#if defined(__AVX512F__) && defined(__AVX512DQ__) && defined(__AVX512VL__)
// 64-bit lane operations in their zero-masked forms with a full mask: the
// same instructions, without the undefined pass-through operand that makes
// gcc 12 warn (-Wmaybe-uninitialized).
constexpr __mmask8 kAll8 = 0xFF;
struct U64x8 {
    __m512i v;
    [[gnu::always_inline]] static U64x8 splat(std::uint64_t x) { return {_mm512_set1_epi64(std::int64_t(x))}; }
    [[gnu::always_inline]] static U64x8 of(const std::uint64_t (&x)[8]) {
        return {_mm512_setr_epi64(std::int64_t(x[0]), std::int64_t(x[1]), std::int64_t(x[2]), std::int64_t(x[3]),
                                  std::int64_t(x[4]), std::int64_t(x[5]), std::int64_t(x[6]), std::int64_t(x[7]))};
    }
    /// Eight 32-bit lanes zero-extended.
    [[gnu::always_inline]] static U64x8 widen(__m256i x) { return {_mm512_maskz_cvtepu32_epi64(kAll8, x)}; }
    [[gnu::always_inline]] friend U64x8 operator^(U64x8 a, U64x8 b) { return {_mm512_xor_si512(a.v, b.v)}; }
    [[gnu::always_inline]] friend U64x8 operator+(U64x8 a, U64x8 b) { return {_mm512_add_epi64(a.v, b.v)}; }
    [[gnu::always_inline]] friend U64x8 operator*(U64x8 a, U64x8 b) { return {_mm512_maskz_mullo_epi64(kAll8, a.v, b.v)}; }
    [[gnu::always_inline]] U64x8 operator>>(unsigned s) const { return {_mm512_maskz_srli_epi64(kAll8, v, s)}; }
    [[gnu::always_inline]] U64x8 operator<<(unsigned s) const { return {_mm512_maskz_slli_epi64(kAll8, v, s)}; }
    /// The low 32 bits of each lane.
    [[gnu::always_inline]] __m256i low32() const { return _mm512_maskz_cvtepi64_epi32(kAll8, v); }
};
#else
struct U64x8 {
    __m256i lo, hi;  ///< lanes 0-3, 4-7
    [[gnu::always_inline]] static U64x8 splat(std::uint64_t x) {
        const __m256i v = _mm256_set1_epi64x(std::int64_t(x));
        return {v, v};
    }
    [[gnu::always_inline]] static U64x8 of(const std::uint64_t (&x)[8]) {
        return {_mm256_setr_epi64x(std::int64_t(x[0]), std::int64_t(x[1]), std::int64_t(x[2]), std::int64_t(x[3])),
                _mm256_setr_epi64x(std::int64_t(x[4]), std::int64_t(x[5]), std::int64_t(x[6]), std::int64_t(x[7]))};
    }
    [[gnu::always_inline]] static U64x8 widen(__m256i x) {
        return {_mm256_cvtepu32_epi64(_mm256_castsi256_si128(x)), _mm256_cvtepu32_epi64(_mm256_extracti128_si256(x, 1))};
    }
    [[gnu::always_inline]] friend U64x8 operator^(U64x8 a, U64x8 b) { return {_mm256_xor_si256(a.lo, b.lo), _mm256_xor_si256(a.hi, b.hi)}; }
    [[gnu::always_inline]] friend U64x8 operator+(U64x8 a, U64x8 b) { return {_mm256_add_epi64(a.lo, b.lo), _mm256_add_epi64(a.hi, b.hi)}; }
    [[gnu::always_inline]] friend U64x8 operator*(U64x8 a, U64x8 b) { return {mul(a.lo, b.lo), mul(a.hi, b.hi)}; }
    [[gnu::always_inline]] U64x8 operator>>(unsigned s) const {
        return {_mm256_srli_epi64(lo, int(s)), _mm256_srli_epi64(hi, int(s))};
    }
    [[gnu::always_inline]] U64x8 operator<<(unsigned s) const {
        return {_mm256_slli_epi64(lo, int(s)), _mm256_slli_epi64(hi, int(s))};
    }
    [[gnu::always_inline]] __m256i low32() const {
        // The even 32-bit elements of both halves, in lane order.
        const __m256 even = _mm256_shuffle_ps(_mm256_castsi256_ps(lo), _mm256_castsi256_ps(hi), _MM_SHUFFLE(2, 0, 2, 0));
        return _mm256_permute4x64_epi64(_mm256_castps_si256(even), _MM_SHUFFLE(3, 1, 2, 0));
    }

private:
    /// The low 64 bits of a b: lo lo + (hi lo + lo hi) 2^32.
    [[gnu::always_inline]] static __m256i mul(__m256i a, __m256i b) {
        const __m256i cross = _mm256_add_epi64(_mm256_mul_epu32(_mm256_srli_epi64(a, 32), b),
                                               _mm256_mul_epu32(a, _mm256_srli_epi64(b, 32)));
        return _mm256_add_epi64(_mm256_mul_epu32(a, b), _mm256_slli_epi64(cross, 32));
    }
};
#endif

/// The high 32 bits of each 64-bit lane.
[[gnu::always_inline]] inline __m256i high32(const U64x8& v) { return (v >> 32).low32(); }

/// mix() in eight lanes.
[[gnu::always_inline]] inline U64x8 mix8(U64x8 h) {
    h = (h ^ (h >> 30)) * U64x8::splat(0xBF58476D1CE4E5B9ull);
    h = (h ^ (h >> 27)) * U64x8::splat(0x94D049BB133111EBull);
    return h ^ (h >> 31);
}

/// permute() in eight 32-bit lanes for a power-of-two n (no cycle walking:
/// the masked value is already below n).
[[gnu::always_inline]] inline __m256i permute8_pow2(__m256i i, std::uint32_t n, __m256i key) {
    const __m256i w = _mm256_set1_epi32(int(n - 1));
    auto mul = [](__m256i a, std::uint32_t c) { return _mm256_mullo_epi32(a, _mm256_set1_epi32(int(c))); };
    auto fold = [&](__m256i a, int s) { return _mm256_xor_si256(a, _mm256_srli_epi32(_mm256_and_si256(a, w), s)); };
    i = _mm256_xor_si256(i, key);
    i = mul(i, 0xe170893du);
    i = _mm256_xor_si256(i, _mm256_srli_epi32(key, 16));
    i = fold(i, 4);
    i = _mm256_xor_si256(i, _mm256_srli_epi32(key, 8));
    i = mul(i, 0x0929eb3fu);
    i = _mm256_xor_si256(i, _mm256_srli_epi32(key, 23));
    i = fold(i, 1);
    i = _mm256_mullo_epi32(i, _mm256_or_si256(_mm256_set1_epi32(1), _mm256_srli_epi32(key, 27)));
    i = mul(i, 0x6935fa69u);
    i = fold(i, 11);
    i = mul(i, 0x74dcb303u);
    i = fold(i, 2);
    i = mul(i, 0x9e501cc3u);
    i = fold(i, 2);
    i = mul(i, 0xc860a3dfu);
    i = _mm256_and_si256(i, w);
    i = _mm256_xor_si256(i, _mm256_srli_epi32(i, 5));
    return _mm256_and_si256(_mm256_add_epi32(i, key), w);
}

/// reverse_bits() in eight lanes: bytes swapped, then each byte's bits
/// reversed by two nibble lookups.
[[gnu::always_inline]] inline __m256i reverse_bits8(__m256i x) {
    const __m256i bswap = _mm256_setr_epi8(3, 2, 1, 0, 7, 6, 5, 4, 11, 10, 9, 8, 15, 14, 13, 12, 3, 2, 1, 0, 7, 6, 5, 4,
                                           11, 10, 9, 8, 15, 14, 13, 12);
    // The nibbles 0-15 bit reversed, in the low nibble and in the high one.
    const __m256i rev_lo = _mm256_setr_epi8(0x0, 0x8, 0x4, 0xC, 0x2, 0xA, 0x6, 0xE, 0x1, 0x9, 0x5, 0xD, 0x3, 0xB, 0x7,
                                            0xF, 0x0, 0x8, 0x4, 0xC, 0x2, 0xA, 0x6, 0xE, 0x1, 0x9, 0x5, 0xD, 0x3, 0xB,
                                            0x7, 0xF);
    const __m256i rev_hi = _mm256_slli_epi16(rev_lo, 4);
    const __m256i nibble = _mm256_set1_epi8(0x0F);
    x = _mm256_shuffle_epi8(x, bswap);
    const __m256i low = _mm256_and_si256(x, nibble), high = _mm256_and_si256(_mm256_srli_epi16(x, 4), nibble);
    return _mm256_or_si256(_mm256_shuffle_epi8(rev_hi, low), _mm256_shuffle_epi8(rev_lo, high));
}

/// owen_scramble() in eight lanes, without its two bit reversals: the
/// scramble of x is reverse_bits8(owen_core8(reverse_bits8(x), seed)).
[[gnu::always_inline]] inline __m256i owen_core8(__m256i x, __m256i seed) {
    auto xor_mul = [](__m256i a, std::uint32_t c) {
        return _mm256_xor_si256(a, _mm256_mullo_epi32(a, _mm256_set1_epi32(int(c))));
    };
    x = _mm256_add_epi32(x, seed);
    x = xor_mul(x, 0x6c50b47cu);
    x = xor_mul(x, 0xb82f1e52u);
    x = xor_mul(x, 0xc7afe638u);
    return xor_mul(x, 0x8d22f6e6u);
}

/// sobol1() in eight lanes, bit reversed (see sobol1_reversed).
[[gnu::always_inline]] inline __m256i sobol1_reversed8(__m256i i) {
    auto step = [](__m256i a, int s, std::uint32_t m) {
        return _mm256_xor_si256(a, _mm256_and_si256(_mm256_srli_epi32(a, s), _mm256_set1_epi32(int(m))));
    };
    i = step(i, 1, 0x55555555u);
    i = step(i, 2, 0x33333333u);
    i = step(i, 4, 0x0F0F0F0Fu);
    i = step(i, 8, 0x00FF00FFu);
    return step(i, 16, 0x0000FFFFu);
}

/// unit_float() in eight lanes.
[[gnu::always_inline]] inline __m256 unit_float8(__m256i bits) {
    return _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srli_epi32(bits, 8)), _mm256_set1_ps(0x1.0p-24f));
}
#define RAYPACK_SAMPLER_LANES 1
#endif

}  // namespace

std::optional<SamplerKind> sampler_from_name(std::string_view name) {
    if (name == "regular") return SamplerKind::Regular;
    if (name == "random") return SamplerKind::Random;
    if (name == "stratified") return SamplerKind::Stratified;
    if (name == "sobol") return SamplerKind::Sobol;
    return std::nullopt;
}

const char* sampler_name(SamplerKind kind) {
    switch (kind) {
        case SamplerKind::Regular: return "regular";
        case SamplerKind::Random: return "random";
        case SamplerKind::Stratified: return "stratified";
        case SamplerKind::Sobol: return "sobol";
    }
    return "?";
}

StrataGrid strata_grid(int spp) {
    if (spp < 1) throw std::invalid_argument("strata_grid: spp must be at least 1");
    int nx = int(std::sqrt(double(spp)));
    while (spp % nx != 0) --nx;
    return {nx, spp / nx};
}

Sampler::Sampler(SamplerKind kind, int spp, std::uint64_t seed)
    : kind_(kind), spp_(spp), seed_(seed), seed_hash_(mix(seed + 0x9E3779B97F4A7C15ull)),
      grid_(strata_grid(spp)),
      inv_nx_(1.0 / grid_.nx),
      inv_ny_(1.0 / grid_.ny),
      log2_nx_(std::has_single_bit(unsigned(grid_.nx)) ? std::countr_zero(unsigned(grid_.nx)) : -1),
      log2_ny_(std::has_single_bit(unsigned(grid_.ny)) ? std::countr_zero(unsigned(grid_.ny)) : -1),
      // Computed once: ldexp per sample was 5% of a path-traced bunny.
      jitter_unit_x_(std::ldexp(1.0f, log2_nx_ - 24)),
      jitter_unit_y_(std::ldexp(1.0f, log2_ny_ - 24)) {}

Sampler::Pixel Sampler::pixel(std::uint64_t number) const {
    return {number, mix(seed_hash_ ^ (number + 0x9E3779B97F4A7C15ull * 2))};
}

void Sampler::get_many(std::span<const Draw> draws, int dimension, Sample2* out) const {
    std::size_t j = 0;
#if defined(RAYPACK_SAMPLER_LANES)
    const bool pow2_strata = kind_ == SamplerKind::Stratified && log2_nx_ >= 0 && log2_ny_ >= 0;
    if (pow2_strata || kind_ == SamplerKind::Random || kind_ == SamplerKind::Sobol) {
        const auto dim = std::uint64_t(dimension);
        for (; j + 8 <= draws.size(); j += 8) {
            // Built from the elements, not loaded from a stack copy: eight
            // stores then one wide load stall on store forwarding (a sixth
            // of this function's time).
            const Draw* d = &draws[j];
            const U64x8 h = U64x8::of({d[0].pixel.hash, d[1].pixel.hash, d[2].pixel.hash, d[3].pixel.hash,
                                       d[4].pixel.hash, d[5].pixel.hash, d[6].pixel.hash, d[7].pixel.hash});
            const __m256i i = _mm256_setr_epi32(d[0].index, d[1].index, d[2].index, d[3].index, d[4].index,
                                                d[5].index, d[6].index, d[7].index);
            __m256 fx, fy;
            if (kind_ == SamplerKind::Random) {
                // hash_keys(pixel hash, dimension, 1 + 4 i)
                const U64x8 r = mix8(h ^ ((U64x8::widen(i) << 2) + U64x8::splat(dim * 0x100000001B3ull + 2)));
                fx = unit_float8(r.low32());
                fy = unit_float8(high32(r));
            } else if (kind_ == SamplerKind::Sobol) {
                const U64x8 k1 = mix8(h ^ U64x8::splat(dim * 0x100000001B3ull + 1));
                const U64x8 k2 = mix8(k1 + U64x8::splat(0x9E3779B97F4A7C15ull));
                // shuffled = owen_scramble(i, k1); x = owen_scramble(sobol0(shuffled), k1 >> 32)
                // with sobol0 = reverse_bits, y = owen_scramble(sobol1(shuffled), k2): the
                // reversals that cancel are left out.
                const __m256i core = owen_core8(reverse_bits8(i), k1.low32());
                const __m256i shuffled = reverse_bits8(core);
                fx = unit_float8(reverse_bits8(owen_core8(shuffled, high32(k1))));
                fy = unit_float8(reverse_bits8(owen_core8(sobol1_reversed8(shuffled), k2.low32())));
            } else {
                const U64x8 key = mix8(h ^ U64x8::splat(dim * 0x100000001B3ull + 1));
                const __m256i cell = permute8_pow2(i, std::uint32_t(spp_), key.low32());
                const U64x8 jitter =
                    mix8(key + U64x8::splat(0x9E3779B97F4A7C15ull) * (U64x8::widen(i) + U64x8::splat(1)));
                const __m256i cx = _mm256_and_si256(cell, _mm256_set1_epi32(grid_.nx - 1));
                const __m256i cy = _mm256_srlv_epi32(cell, _mm256_set1_epi32(log2_nx_));
                const __m256 jx = _mm256_mul_ps(
                    _mm256_cvtepi32_ps(_mm256_srlv_epi32(jitter.low32(), _mm256_set1_epi32(8 + log2_nx_))),
                    _mm256_set1_ps(jitter_unit_x_));
                const __m256 jy = _mm256_mul_ps(
                    _mm256_cvtepi32_ps(_mm256_srlv_epi32(high32(jitter), _mm256_set1_epi32(8 + log2_ny_))),
                    _mm256_set1_ps(jitter_unit_y_));
                fx = _mm256_mul_ps(_mm256_add_ps(_mm256_cvtepi32_ps(cx), jx), _mm256_set1_ps(float(inv_nx_)));
                fy = _mm256_mul_ps(_mm256_add_ps(_mm256_cvtepi32_ps(cy), jy), _mm256_set1_ps(float(inv_ny_)));
            }
            // (x, y) pairs in lane order: two stores, not sixteen.
            static_assert(sizeof(Sample2) == 2 * sizeof(float));
            const __m256 lo = _mm256_unpacklo_ps(fx, fy), hi = _mm256_unpackhi_ps(fx, fy);
            _mm256_storeu_ps(&out[j].x, _mm256_permute2f128_ps(lo, hi, 0x20));
            _mm256_storeu_ps(&out[j + 4].x, _mm256_permute2f128_ps(lo, hi, 0x31));
        }
    }
#endif
    for (; j < draws.size(); ++j) out[j] = get(draws[j].pixel, draws[j].index, dimension);
}

Sample2 Sampler::get(const Pixel& pixel, int index, int dimension) const {
    const auto n = std::uint32_t(spp_), i = std::uint32_t(index);
    switch (kind_) {
        case SamplerKind::Regular: {
            // Dimension 0 walks the grid in order; the others in one fixed
            // order per dimension (the same for every pixel), so that the lens
            // sample is not a function of the position in the pixel.
            const std::uint32_t cell = dimension == 0 ? i : permute(i, n, std::uint32_t(mix(seed_ + dimension)));
            return {(float(cell % std::uint32_t(grid_.nx)) + 0.5f) / float(grid_.nx),
                    (float(cell / std::uint32_t(grid_.nx)) + 0.5f) / float(grid_.ny)};
        }
        case SamplerKind::Random: {
            const std::uint64_t h = hash_keys(pixel.hash, std::uint64_t(dimension), 1 + std::uint64_t(i) * 4);
            return {unit_float(std::uint32_t(h)), unit_float(std::uint32_t(h >> 32))};
        }
        case SamplerKind::Stratified: {
            // Cells shuffled per pixel and dimension (pbrt's stratified
            // sampler shuffles too), so that dimensions are not correlated.
            const std::uint64_t key = hash_keys(pixel.hash, std::uint64_t(dimension), 0);
            const std::uint32_t cell = permute(i, n, std::uint32_t(key));
            // The jitter of sample i: one more mix of the (pixel, dimension) key.
            const std::uint64_t jitter = mix(key + 0x9E3779B97F4A7C15ull * (std::uint64_t(i) + 1));
            const auto nx = std::uint32_t(grid_.nx), ny = std::uint32_t(grid_.ny);
            if (log2_nx_ >= 0 && log2_ny_ >= 0) {
                // Power-of-two strata: c + jitter with 24 - log2(n) bits of
                // jitter is exact in float and so is the scaling by 1 / n, so the
                // point stays in its stratum with no check (the common spp 1,
                // 4, 16, 64, 256 ...).
                const std::uint32_t cx = cell & (nx - 1), cy = cell >> log2_nx_;
                const float jx = float(std::uint32_t(jitter) >> (8 + log2_nx_)) * jitter_unit_x_;
                const float jy = float(std::uint32_t(jitter >> 32) >> (8 + log2_ny_)) * jitter_unit_y_;
                return {(float(cx) + jx) * float(inv_nx_), (float(cy) + jy) * float(inv_ny_)};
            }
            const std::uint32_t cy = cell / nx, cx = cell - cy * nx;
            return {in_stratum(cx, nx, inv_nx_, std::uint32_t(jitter)), in_stratum(cy, ny, inv_ny_, std::uint32_t(jitter >> 32))};
        }
        case SamplerKind::Sobol: {
            // Burley (2020): shuffle the index by an Owen scramble (which keeps
            // it inside one aligned block of 2^m points, a (0, m, 2)-net), then
            // Owen-scramble each coordinate; seeds per pixel and dimension.
            const std::uint64_t k1 = hash_keys(pixel.hash, std::uint64_t(dimension), 0);
            const std::uint64_t k2 = mix(k1 + 0x9E3779B97F4A7C15ull);
            const std::uint32_t shuffled = owen_scramble(i, std::uint32_t(k1));
            return {unit_float(owen_scramble(sobol0(shuffled), std::uint32_t(k1 >> 32))),
                    unit_float(owen_scramble(sobol1(shuffled), std::uint32_t(k2)))};
        }
    }
    return {};
}

}  // namespace raypack
