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
    for (int y = 0; y < sum_.height; ++y)
        for (int x = 0; x < sum_.width; ++x) {
            const int n = count_[std::size_t(y) * std::size_t(sum_.width) + std::size_t(x)];
            out.set(x, y, n > 0 ? sum_.at(x, y) / float(n) : Vec3f{});
        }
}

double Film::noise_rms() const {
    double total = 0;
    std::size_t values = 0;
    for (int y = 0; y < sum_.height; ++y)
        for (int x = 0; x < sum_.width; ++x) {
            const int n = count_[std::size_t(y) * std::size_t(sum_.width) + std::size_t(x)];
            if (n < 2) continue;
            for (int c = 0; c < 3; ++c) {
                const double mean = double(sum_.at(x, y)[c]) / n;
                const double var = std::max(0.0, (double(sum_sq_.at(x, y)[c]) - n * mean * mean) / (n - 1));
                total += var / n;
                ++values;
            }
        }
    return values ? std::sqrt(total / double(values)) : 0.0;
}

}  // namespace raypack
