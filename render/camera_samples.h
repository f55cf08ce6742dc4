#pragma once
// The camera samples of a batch of pixels for the sampled integrators
// (distribution and path tracing): every draw of the batch at once
// (Sampler::get_many), then the rays.
#include <immintrin.h>

#include <limits>
#include <span>
#include <vector>

#include "kernels/ray_transpose.h"
#include "render/thin_lens.h"
#include "render/tiles.h"

namespace raypack {

struct CameraSampleBatch {
    std::vector<Sampler::Draw> keys;  ///< per sample, pixel by pixel: samples k0 .. k1 of each
    std::vector<Sample2> position, lens, time_drawn;
    /// Per sample, its scene time (motion blur: scenes with moving
    /// placements), spread over the shutter; empty for a static scene.
    std::vector<float> time;

    /// Samples k0 .. k1 of every pixel of `pixels` (numbered y * width + x):
    /// their keys, and their rays in rays[0 .. pixels * (k1 - k0)). Positions
    /// come from sampler dimension 0 through the pixel filter, lens points
    /// from dimension 1; a pinhole draws none (skipping a draw changes no
    /// other).
    void draw(const CameraFrame& frame, const Camera& camera, const Sampler& sampler, PixelFilter filter,
              std::span<const PixelXY> pixels, int width, int k0, int k1, Rayf* rays) {
        draw(frame, camera, sampler, filter, pixels, width, k0, k1, rays, nullptr);
    }
    /// The same, and with a scene that moves (`scene` not null, with moving
    /// placements) each sample's time from sampler dimension kTimeDimension.
    void draw(const CameraFrame& frame, const Camera& camera, const Sampler& sampler, PixelFilter filter,
              std::span<const PixelXY> pixels, int width, int k0, int k1, Rayf* rays, const Scene* scene) {
        motion = scene != nullptr && !scene->moving_instances.empty();
        if (motion) shutter_open = scene->shutter_open, shutter_close = scene->shutter_close;
        // Sized once and written in place; the lens points only for a lens
        // (6% of this function's instructions).
        keys.resize(pixels.size() * std::size_t(k1 - k0));
        std::size_t key = 0;
        for (const PixelXY& px : pixels) {
            const Sampler::Pixel pixel = sampler.pixel(std::uint64_t(px.y) * std::uint64_t(width) + std::uint64_t(px.x));
            for (int k = k0; k < k1; ++k, ++key) keys[key] = {pixel, k};
        }
        position.resize(keys.size());
        sampler.get_many(keys, 0, position.data());
        const bool thin_lens = camera.lens_radius > 0;
        if (thin_lens) {
            lens.resize(keys.size());
            sampler.get_many(keys, 1, lens.data());
        }
        time.clear();
        if (motion) {
            time_drawn.resize(keys.size());
            sampler.get_many(keys, kTimeDimension, time_drawn.data());
            time.resize(keys.size());
            for (std::size_t j = 0; j < keys.size(); ++j) time[j] = shutter_time(sampler.line(time_drawn[j]));
        }
        std::size_t i = 0;
#if defined(__AVX2__)
        // A pinhole and the box filter, the common case: eight rays at once.
        if (!thin_lens && filter == PixelFilter::Box) return pinhole_box_rays(frame, pixels, k1 - k0, rays);
#endif
        for (const PixelXY& px : pixels)
            for (int k = k0; k < k1; ++k, ++i)
                rays[i] = camera_ray_of_sample(frame, camera, filter, position[i], thin_lens ? lens[i] : Sample2{},
                                               px.x, px.y);
    }

private:
#if defined(__AVX2__)
    /// The rays of `position` (per_pixel samples of each pixel), as
    /// camera_ray_of_sample computes them for a pinhole and the box filter:
    /// the same operations in the same order, eight samples in lanes.
    void pinhole_box_rays(const CameraFrame& f, std::span<const PixelXY> pixels, int per_pixel, Rayf* rays) const {
        const std::size_t n = position.size();
        const __m256 half = _mm256_set1_ps(0.5f), step = _mm256_set1_ps(f.step);
        const __m256 half_width = _mm256_set1_ps(0.5f * float(f.width));
        const __m256 half_height = _mm256_set1_ps(0.5f * float(f.height));
        // The x (or y) of 8 consecutive Sample2 held in a and b: the even
        // (odd) floats, in order.
        static_assert(sizeof(Sample2) == 2 * sizeof(float));
        const auto component = [](__m256 a, __m256 b, bool y) {
            const __m256 mixed = y ? _mm256_shuffle_ps(a, b, 0xDD) : _mm256_shuffle_ps(a, b, 0x88);
            return _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(mixed), 0xD8));
        };
        std::size_t i = 0, pixel = 0;
        int k = 0;  // samples of `pixel` done
        for (; i + 8 <= n; i += 8) {
            // The pixels' centres: one pixel's, or lane by lane across pixels.
            __m256 cx, cy;
            if (per_pixel - k >= 8) {
                cx = _mm256_set1_ps(float(pixels[pixel].x) + 0.5f);
                cy = _mm256_set1_ps(float(pixels[pixel].y) + 0.5f);
                if ((k += 8) == per_pixel) k = 0, ++pixel;
            } else {
                float x[8], y[8];
                for (int l = 0; l < 8; ++l) {
                    x[l] = float(pixels[pixel].x) + 0.5f;
                    y[l] = float(pixels[pixel].y) + 0.5f;
                    if (++k == per_pixel) k = 0, ++pixel;
                }
                cx = _mm256_setr_ps(x[0], x[1], x[2], x[3], x[4], x[5], x[6], x[7]);
                cy = _mm256_setr_ps(y[0], y[1], y[2], y[3], y[4], y[5], y[6], y[7]);
            }
            const __m256 a = _mm256_loadu_ps(&position[i].x), b = _mm256_loadu_ps(&position[i + 4].x);
            const __m256 ux = component(a, b, false), uy = component(a, b, true);
            // filter_offset (box), then camera_ray.
            const __m256 px = _mm256_add_ps(cx, _mm256_sub_ps(ux, half));
            const __m256 py = _mm256_add_ps(cy, _mm256_sub_ps(uy, half));
            const __m256 sx = _mm256_mul_ps(_mm256_sub_ps(px, half_width), step);
            const __m256 sy = _mm256_mul_ps(_mm256_sub_ps(half_height, py), step);
            const auto axis = [&](float forward, float right, float up) {
                return _mm256_add_ps(_mm256_add_ps(_mm256_set1_ps(forward), _mm256_mul_ps(_mm256_set1_ps(right), sx)),
                                     _mm256_mul_ps(_mm256_set1_ps(up), sy));
            };
            __m256 row[8] = {_mm256_set1_ps(f.origin.x),
                             _mm256_set1_ps(f.origin.y),
                             _mm256_set1_ps(f.origin.z),
                             axis(f.forward.x, f.right.x, f.up.x),
                             axis(f.forward.y, f.right.y, f.up.y),
                             axis(f.forward.z, f.right.z, f.up.z),
                             _mm256_set1_ps(f.tnear),
                             _mm256_set1_ps(std::numeric_limits<float>::infinity())};
            store_rays8(row, rays + i);
        }
        for (; i < n; ++i) {
            rays[i] = camera_ray(f, float(pixels[pixel].x) + 0.5f + (position[i].x - 0.5f),
                                 float(pixels[pixel].y) + 0.5f + (position[i].y - 0.5f));
            if (++k == per_pixel) k = 0, ++pixel;
        }
    }
#endif

    bool motion = false;
    float shutter_open = 0, shutter_close = 1;
    /// (1 - u) t0 + u t1: t0 at u = 0.
    float shutter_time(float u) const { return (1.0f - u) * shutter_open + u * shutter_close; }
};

}  // namespace raypack
