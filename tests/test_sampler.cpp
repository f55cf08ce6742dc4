// The pixel samplers (render/sampler.h): ranges, determinism, the
// stratification each one promises, and integration error in the order the
// theory gives (random > stratified > Owen-scrambled Sobol' on a smooth
// integrand).
#include <gtest/gtest.h>

#include <bit>

#include <cmath>
#include <numbers>
#include <set>
#include <vector>

#include "render/sampler.h"

namespace {

using raypack::Sample2;
using raypack::Sampler;
using raypack::SamplerKind;

constexpr SamplerKind kAll[] = {SamplerKind::Regular, SamplerKind::Random, SamplerKind::Stratified, SamplerKind::Sobol};

/// RMS error over `pixels` pixels of the spp-sample estimate of the integral
/// of f over the unit square.
template <class F>
double rms_error(SamplerKind kind, int spp, int pixels, F f, double exact) {
    const Sampler s(kind, spp, 7);
    double sum_sq = 0;
    for (int p = 0; p < pixels; ++p) {
        double est = 0;
        for (int i = 0; i < spp; ++i) {
            const Sample2 u = s.get(std::uint64_t(p), i, 0);
            est += f(u.x, u.y);
        }
        est /= spp;
        sum_sq += (est - exact) * (est - exact);
    }
    return std::sqrt(sum_sq / pixels);
}

}  // namespace

TEST(Sampler, NamesRoundTrip) {
    for (SamplerKind k : kAll) EXPECT_EQ(raypack::sampler_from_name(raypack::sampler_name(k)), k);
    EXPECT_FALSE(raypack::sampler_from_name("halton").has_value());
}

TEST(Sampler, StrataGridIsTheMostSquareFactorisation) {
    EXPECT_EQ(raypack::strata_grid(1).nx, 1);
    EXPECT_EQ(raypack::strata_grid(16).nx, 4);
    EXPECT_EQ(raypack::strata_grid(8).nx, 2);
    EXPECT_EQ(raypack::strata_grid(8).ny, 4);
    EXPECT_EQ(raypack::strata_grid(7).nx, 1);
    EXPECT_EQ(raypack::strata_grid(12).nx, 3);
    EXPECT_THROW(raypack::strata_grid(0), std::invalid_argument);
}

TEST(Sampler, PointsInTheUnitSquareAndAPureFunctionOfTheirKeys) {
    for (SamplerKind k : kAll)
        for (int spp : {1, 5, 16, 64}) {
            const Sampler a(k, spp, 42), b(k, spp, 42);
            for (std::uint64_t pixel : {0ull, 1ull, 123457ull, 1ull << 40})
                for (int dim = 0; dim < 4; ++dim) {
                    // b answers in the opposite order, as another thread might.
                    std::vector<Sample2> backwards(static_cast<std::size_t>(spp));
                    for (int i = spp - 1; i >= 0; --i) backwards[std::size_t(i)] = b.get(pixel, i, dim);
                    for (int i = 0; i < spp; ++i) {
                        const Sample2 u = a.get(pixel, i, dim);
                        ASSERT_GE(u.x, 0.0f);
                        ASSERT_LT(u.x, 1.0f);
                        ASSERT_GE(u.y, 0.0f);
                        ASSERT_LT(u.y, 1.0f);
                        ASSERT_EQ(u.x, backwards[std::size_t(i)].x);
                        ASSERT_EQ(u.y, backwards[std::size_t(i)].y);
                    }
                }
        }
}

TEST(Sampler, RandomizedSamplersDifferBetweenPixelsDimensionsAndSeeds) {
    for (SamplerKind k : {SamplerKind::Random, SamplerKind::Stratified, SamplerKind::Sobol}) {
        const Sampler s(k, 16, 1), t(k, 16, 2);
        std::set<std::pair<float, float>> seen;
        for (std::uint64_t pixel = 0; pixel < 8; ++pixel)
            for (int dim = 0; dim < 4; ++dim) {
                const Sample2 u = s.get(pixel, 3, dim);
                seen.insert({u.x, u.y});
            }
        EXPECT_EQ(seen.size(), 32u) << raypack::sampler_name(k);
        const Sample2 a = s.get(5, 3, 1), b = t.get(5, 3, 1);
        EXPECT_TRUE(a.x != b.x || a.y != b.y) << raypack::sampler_name(k);
    }
}

TEST(Sampler, RegularIsTheGridOfCellCentres) {
    const Sampler s(SamplerKind::Regular, 8, 0);  // 2 x 4
    for (int i = 0; i < 8; ++i) {
        const Sample2 u = s.get(99, i, 0);
        EXPECT_FLOAT_EQ(u.x, (float(i % 2) + 0.5f) / 2);
        EXPECT_FLOAT_EQ(u.y, (float(i / 2) + 0.5f) / 4);
    }
}

TEST(Sampler, StratifiedPutsOnePointInEachCellOfEveryDimension) {
    for (int spp : {1, 4, 7, 8, 9, 16, 64}) {
        const raypack::StrataGrid g = raypack::strata_grid(spp);
        const Sampler s(SamplerKind::Stratified, spp, 3);
        for (std::uint64_t pixel = 0; pixel < 20; ++pixel)
            for (int dim = 0; dim < 5; ++dim) {
                std::vector<int> count(std::size_t(spp), 0);
                for (int i = 0; i < spp; ++i) {
                    const Sample2 u = s.get(pixel, i, dim);
                    ++count[std::size_t(int(double(u.y) * g.ny) * g.nx + int(double(u.x) * g.nx))];
                }
                for (int c : count) ASSERT_EQ(c, 1) << "spp " << spp << " pixel " << pixel << " dim " << dim;
            }
    }
}

TEST(Sampler, SobolPointsOfOnePixelFormA0m2Net) {
    // For 2^m samples, every elementary interval of area 2^-m (2^j by
    // 2^(m-j) cells, for each j) holds exactly one point: Owen scrambling
    // and the index shuffle both keep this property of Sobol' points.
    for (int m = 0; m <= 8; ++m) {
        const int spp = 1 << m;
        const Sampler s(SamplerKind::Sobol, spp, 11);
        for (std::uint64_t pixel : {0ull, 17ull, 9999ull})
            for (int dim = 0; dim < 3; ++dim)
                for (int j = 0; j <= m; ++j) {
                    const int nx = 1 << j, ny = 1 << (m - j);
                    std::vector<int> count(std::size_t(spp), 0);
                    for (int i = 0; i < spp; ++i) {
                        const Sample2 u = s.get(pixel, i, dim);
                        ++count[std::size_t(int(u.y * float(ny)) * nx + int(u.x * float(nx)))];
                    }
                    for (int c : count) ASSERT_EQ(c, 1) << "m " << m << " j " << j << " dim " << dim;
                }
    }
}

TEST(Sampler, ErrorOrderOnASmoothIntegrand) {
    // Integral of exp(-(x^2 + y^2)) over the unit square: (sqrt(pi)/2 erf(1))^2.
    const double one_d = std::sqrt(std::numbers::pi) / 2 * std::erf(1.0);
    const auto f = [](float x, float y) { return std::exp(-double(x) * x - double(y) * y); };
    const int spp = 64, pixels = 2000;
    const double random = rms_error(SamplerKind::Random, spp, pixels, f, one_d * one_d);
    const double stratified = rms_error(SamplerKind::Stratified, spp, pixels, f, one_d * one_d);
    const double sobol = rms_error(SamplerKind::Sobol, spp, pixels, f, one_d * one_d);
    // Monte Carlo: sigma / sqrt(n), sigma^2 = E[f^2] - E[f]^2 with
    // E[f^2] = (sqrt(pi / 8) erf(sqrt 2))^2.
    const double second = std::sqrt(std::numbers::pi / 8) * std::erf(std::sqrt(2.0));
    const double sigma = std::sqrt(second * second - std::pow(one_d, 4));
    EXPECT_NEAR(random, sigma / std::sqrt(double(spp)), 0.1 * sigma / std::sqrt(double(spp)));
    // Jittered: O(n^-1) in 2D; scrambled nets O(n^-1.5) (Owen 1997).
    EXPECT_LT(stratified, random / 3) << stratified << " vs " << random;
    EXPECT_LT(sobol, stratified / 2) << sobol << " vs " << stratified;
}

TEST(Sampler, ErrorOrderOnAnEdge) {
    // Area of the disc of radius 0.75 about the origin inside the unit
    // square: a quarter disc, pi 0.75^2 / 4. A discontinuous integrand, as
    // pixels cut by an edge are: stratification still pays (O(n^-3/4)).
    const auto f = [](float x, float y) { return x * x + y * y < 0.5625f ? 1.0 : 0.0; };
    const double exact = std::numbers::pi * 0.5625 / 4;
    const int spp = 64, pixels = 2000;
    const double random = rms_error(SamplerKind::Random, spp, pixels, f, exact);
    const double stratified = rms_error(SamplerKind::Stratified, spp, pixels, f, exact);
    const double sobol = rms_error(SamplerKind::Sobol, spp, pixels, f, exact);
    EXPECT_LT(stratified, random / 2);
    EXPECT_LT(sobol, random / 2);
}

TEST(Sampler, ManyDrawsAtOnceAreTheOneByOneDrawsBitForBit) {
    // get_many runs eight draws in SIMD lanes (AVX2 or AVX-512) for the
    // random, Sobol' and stratified (power-of-two strata) samplers; every
    // kind and grid must give get's bits, for draws of mixed pixels and
    // indices and a ragged tail.
    for (const SamplerKind kind :
         {SamplerKind::Regular, SamplerKind::Random, SamplerKind::Stratified, SamplerKind::Sobol}) {
        for (const int spp : {1, 2, 4, 6, 8, 16, 32, 64, 256}) {
            const Sampler sampler(kind, spp, 12345);
            std::vector<Sampler::Draw> draws;
            for (std::uint64_t p = 0; p < 37; ++p)
                for (int k = 0; k < spp; k += 1 + int(p % 3))
                    draws.push_back({sampler.pixel(p * 7919 + 3), k});
            for (const int dim : {0, 1, 5, 63, 200}) {
                std::vector<Sample2> many(draws.size());
                sampler.get_many(draws, dim, many.data());
                for (std::size_t j = 0; j < draws.size(); ++j) {
                    const Sample2 one = sampler.get(draws[j].pixel, draws[j].index, dim);
                    ASSERT_EQ(std::bit_cast<std::uint32_t>(many[j].x), std::bit_cast<std::uint32_t>(one.x))
                        << sampler_name(kind) << " spp " << spp << " dim " << dim << " draw " << j;
                    ASSERT_EQ(std::bit_cast<std::uint32_t>(many[j].y), std::bit_cast<std::uint32_t>(one.y))
                        << sampler_name(kind) << " spp " << spp << " dim " << dim << " draw " << j;
                }
            }
        }
    }
}
