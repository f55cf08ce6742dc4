#pragma once
// The film: where each camera sample lands in its pixel (the pixel filter,
// importance-sampled as pbrt-v4 does: sample positions follow the filter's
// shape and every sample weighs the same) and the average of a pixel's
// samples.
#include <optional>
#include <string_view>
#include <vector>

#include "render/image.h"
#include "render/sampler.h"

namespace raypack {

enum class PixelFilter : std::uint8_t {
    Box,       ///< uniform over the pixel (radius 1/2)
    Tent,      ///< triangle of radius 1 pixel per axis
    Gaussian,  ///< standard deviation 1/2 pixel, untruncated
};

std::optional<PixelFilter> pixel_filter_from_name(std::string_view name);
const char* pixel_filter_name(PixelFilter filter);

/// Offset from the pixel's centre, in pixels, of the sample drawn from the
/// filter by the unit-square point `u`.
Sample2 filter_offset(PixelFilter filter, Sample2 u);

/// Sums of samples per pixel (and of their squares), resolved into their
/// average and an estimate of its noise.
class Film {
public:
    Film(int width, int height)
        : sum_(width, height), sum_sq_(width, height), count_(std::size_t(width) * std::size_t(height), 0) {}
    void add(int x, int y, const Vec3f& color) {
        sum_.set(x, y, sum_.at(x, y) + color);
        sum_sq_.set(x, y, sum_sq_.at(x, y) + color * color);
        ++count_[std::size_t(y) * std::size_t(sum_.width) + std::size_t(x)];
    }
    Image resolve() const;
    /// The standard error of each pixel's mean (sample variance / count,
    /// per channel), as the root mean square over pixels and channels: how
    /// far the image is likely to be from the converged one.
    double noise_rms() const;

private:
    Image sum_, sum_sq_;
    std::vector<int> count_;
};

}  // namespace raypack
