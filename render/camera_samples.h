#pragma once
// The camera samples of a batch of pixels for the sampled integrators
// (distribution and path tracing): every draw of the batch at once
// (Sampler::get_many), then the rays.
#include <span>
#include <vector>

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
        for (const PixelXY& px : pixels)
            for (int k = k0; k < k1; ++k, ++i)
                rays[i] = camera_ray_of_sample(frame, camera, filter, position[i], thin_lens ? lens[i] : Sample2{},
                                               px.x, px.y);
    }

private:
    bool motion = false;
    float shutter_open = 0, shutter_close = 1;
    /// (1 - u) t0 + u t1: t0 at u = 0.
    float shutter_time(float u) const { return (1.0f - u) * shutter_open + u * shutter_close; }
};

}  // namespace raypack
