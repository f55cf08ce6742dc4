#pragma once
// Sample points of the unit square for pixel samples (image position, lens,
// light, lobe, time): each is a pure function of (seed, pixel, sample index,
// dimension), so an image does not depend on thread count or tile order.
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
#include <string_view>

namespace raypack {

enum class SamplerKind : std::uint8_t {
    Regular,     ///< cell centres of a grid of spp cells (aliases; no noise)
    Random,      ///< independent uniform points
    Stratified,  ///< one jittered point per grid cell, cells shuffled per dimension
    Sobol,       ///< Owen-scrambled Sobol' points, shuffled per pixel and dimension
};

std::optional<SamplerKind> sampler_from_name(std::string_view name);
const char* sampler_name(SamplerKind kind);

/// A 2D point in [0, 1)^2.
struct Sample2 {
    float x = 0, y = 0;
};

/// The grid of the regular and stratified samplers for `spp` samples: nx by
/// ny cells with nx * ny = spp and nx the largest divisor of spp that is at
/// most sqrt(spp) (a square for 1, 4, 9, 16 ...; 2 x 4 for 8; 1 x spp for a
/// prime).
struct StrataGrid {
    int nx = 1, ny = 1;
};
StrataGrid strata_grid(int spp);

/// Sample `index` (0 <= index < spp) of pixel `pixel` in the 2D dimension
/// `dimension` (0 = position in the pixel, then lens, light, lobe, time ...
/// as the integrator numbers them).
/// The sampler dimension of a camera sample's time (motion blur), apart
/// from the integrators' own (position, lens, lobes, bounces).
inline constexpr int kTimeDimension = 1 << 20;

class Sampler {
public:
    Sampler(SamplerKind kind, int spp, std::uint64_t seed);

    /// A pixel with the part of every draw's hash that depends on the pixel
    /// alone, for callers that draw many samples of one pixel.
    struct Pixel {
        std::uint64_t number;
        std::uint64_t hash;
    };
    Pixel pixel(std::uint64_t number) const;

    Sample2 get(const Pixel& pixel, int index, int dimension) const;
    Sample2 get(std::uint64_t pixel, int index, int dimension) const { return get(this->pixel(pixel), index, dimension); }

    /// A draw of sample `index` of `pixel`.
    struct Draw {
        Pixel pixel;
        int index;
    };
    /// out[j] = get(draws[j].pixel, draws[j].index, dimension) for every j,
    /// bit for bit, eight draws at a time in SIMD lanes where the build has
    /// AVX2 or AVX-512 (the random and Sobol' samplers, and the stratified
    /// one with power-of-two strata; the others draw one by one).
    void get_many(std::span<const Draw> draws, int dimension, Sample2* out) const;

    /// A point of [0, 1) from a 2D sample: the column of the strata grid
    /// that u.x falls in, refined by u.y, so that the regular and stratified
    /// samplers' spp samples fall one in each of spp equal intervals (a
    /// 1D stratification from the 2D one), and a uniform u gives a uniform
    /// point. For one-dimensional draws such as the time of a sample.
    float line(Sample2 u) const {
        const float column = std::floor(u.x * float(grid_.nx));
        const float t = (column + u.y) / float(grid_.nx);
        return t < 1.0f ? t : 0x1.fffffep-1f;
    }

    SamplerKind kind() const { return kind_; }
    int spp() const { return spp_; }

private:
    SamplerKind kind_;
    int spp_;
    std::uint64_t seed_;
    std::uint64_t seed_hash_;  ///< the seed's hash, computed once
    StrataGrid grid_;
    double inv_nx_, inv_ny_;
    int log2_nx_, log2_ny_;  ///< -1 unless the grid side is a power of two
    float jitter_unit_x_, jitter_unit_y_;  ///< 2^(log2 - 24): one step of a power-of-two stratum's jitter
};

}  // namespace raypack
