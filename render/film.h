#pragma once
// The film: where each camera sample lands in its pixel (the pixel filter,
// importance-sampled as pbrt-v4 does: sample positions follow the filter's
// shape and every sample weighs the same) and the average of a pixel's
// samples.
#include <cmath>
#include <cstdint>
#include <optional>
#include <span>
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

/// filter_offset for the tent and the Gaussian.
Sample2 shaped_filter_offset(PixelFilter filter, Sample2 u);

/// Offset from the pixel's centre, in pixels, of the sample drawn from the
/// filter by the unit-square point `u`. The box inline: it runs for every
/// camera sample.
inline Sample2 filter_offset(PixelFilter filter, Sample2 u) {
    if (filter == PixelFilter::Box) return {u.x - 0.5f, u.y - 0.5f};
    return shaped_filter_offset(filter, u);
}

/// Film::noise_rms's sum over part of the film: per pixel and channel, the
/// sample variance of the pixel's mean. Parts add up in a fixed order (a
/// render's tiles in tile order), so the figure does not depend on threads.
struct FilmNoise {
    double sum = 0;
    std::uint64_t values = 0;
    FilmNoise& operator+=(const FilmNoise& o) {
        sum += o.sum;
        values += o.values;
        return *this;
    }
    double rms() const { return values ? std::sqrt(sum / double(values)) : 0.0; }
};

/// Sums of samples per pixel (and of their squares), resolved into their
/// average and an estimate of its noise.
class Film {
public:
    Film(int width, int height)
        : sum_(width, height), sum_sq_(width, height), count_(std::size_t(width) * std::size_t(height), 0) {}
    void add(int x, int y, const Vec3f& color) { add(x, y, {&color, 1}); }
    /// Samples of one pixel, added in order (the same sums as one add each).
    void add(int x, int y, std::span<const Vec3f> colors) {
        Vec3f sum = sum_.at(x, y), sum_sq = sum_sq_.at(x, y);
        for (const Vec3f& c : colors) {
            sum = sum + c;
            sum_sq = sum_sq + c * c;
        }
        sum_.set(x, y, sum);
        sum_sq_.set(x, y, sum_sq);
        count_[std::size_t(y) * std::size_t(sum_.width) + std::size_t(x)] += int(colors.size());
    }
    Image resolve() const;
    /// The same into `out`, whose memory is reused when it has the film's size.
    void resolve(Image& out) const;
    /// The pixels [x0, x1) x [y0, y1) into `out` (of the film's size), and
    /// their part of noise_rms: a render resolves each tile once its
    /// samples are in, on the tile's thread.
    FilmNoise resolve(int x0, int y0, int x1, int y1, Image& out) const;
    bool has_size(int width, int height) const { return sum_.width == width && sum_.height == height; }
    /// The standard error of each pixel's mean (sample variance / count,
    /// per channel), as the root mean square over pixels and channels: how
    /// far the image is likely to be from the converged one.
    double noise_rms() const;

private:
    /// resolve's loop; `out` may be null (noise alone).
    FilmNoise region(int x0, int y0, int x1, int y1, Image* out) const;

    Image sum_, sum_sq_;
    std::vector<int> count_;
};

}  // namespace raypack
