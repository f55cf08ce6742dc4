#include "render/film.h"

#include <algorithm>
#include <cmath>

#include "render/sin_cos_turns.h"

namespace raypack {

std::optional<PixelFilter> pixel_filter_from_name(std::string_view name) {
    if (name == "box") return PixelFilter::Box;
    if (name == "tent") return PixelFilter::Tent;
    if (name == "gaussian") return PixelFilter::Gaussian;
    return std::nullopt;
}

const char* pixel_filter_name(PixelFilter filter) {
    switch (filter) {
        case PixelFilter::Box: return "box";
        case PixelFilter::Tent: return "tent";
        case PixelFilter::Gaussian: return "gaussian";
    }
    return "?";
}

namespace {

/// Inverse of the tent's distribution function on [-1, 1].
float tent_inverse(float u) { return u < 0.5f ? std::sqrt(2.0f * u) - 1.0f : 1.0f - std::sqrt(2.0f - 2.0f * u); }

}  // namespace

Sample2 shaped_filter_offset(PixelFilter filter, Sample2 u) {
    switch (filter) {
        case PixelFilter::Box: return {u.x - 0.5f, u.y - 0.5f};
        case PixelFilter::Tent: return {tent_inverse(u.x), tent_inverse(u.y)};
        case PixelFilter::Gaussian: {
            // Box-Muller: one 2D point gives a 2D normal point exactly.
            const float r = 0.5f * std::sqrt(-2.0f * std::log(1.0f - u.x));
            float sin_phi, cos_phi;
            sin_cos_turns(u.y, sin_phi, cos_phi);
            return {r * cos_phi, r * sin_phi};
        }
    }
    return {};
}

Image Film::resolve() const {
    Image out;
    resolve(out);
    return out;
}

void Film::resolve(Image& out) const {
    if (out.width != sum_.width || out.height != sum_.height) out = Image(sum_.width, sum_.height);
    resolve(0, 0, sum_.width, sum_.height, out);
}

FilmNoise Film::resolve(int x0, int y0, int x1, int y1, Image& out) const { return region(x0, y0, x1, y1, &out); }

FilmNoise Film::region(int x0, int y0, int x1, int y1, Image* out) const {
    FilmNoise noise;
    // Two partial sums, so that the additions of consecutive pixels overlap.
    double partial[2] = {0, 0};
    // Most pixels hold as many samples as their neighbours: the factors of
    // the last count are reused instead of two double divisions a pixel.
    int last = -1;
    double inv_n = 0, inv_var_n = 0;
    for (int y = y0; y < y1; ++y)
        for (int x = x0; x < x1; ++x) {
            const int n = count_[std::size_t(y) * std::size_t(sum_.width) + std::size_t(x)];
            const Vec3f sum = sum_.at(x, y);
            if (out) out->set(x, y, n > 0 ? sum / float(n) : Vec3f{});
            if (n < 2) continue;
            // Per channel (sum_sq - sum^2 / n) / (n - 1), the sample
            // variance, over n: the variance of the mean.
            const Vec3f sq = sum_sq_.at(x, y);
            if (n != last) {
                last = n;
                inv_n = 1.0 / n;
                inv_var_n = 1.0 / (double(n - 1) * n);
            }
            double v = 0;
            for (int c = 0; c < 3; ++c) {
                const double s = sum[c];
                v += std::max(0.0, double(sq[c]) - s * s * inv_n) * inv_var_n;
            }
            partial[x & 1] += v;
            noise.values += 3;
        }
    noise.sum = partial[0] + partial[1];
    return noise;
}

double Film::noise_rms() const { return region(0, 0, sum_.width, sum_.height, nullptr).rms(); }

}  // namespace raypack
