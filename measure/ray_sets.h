#pragma once
// The standard ray sets traced by benchmarks and comparisons.
#include <cstdint>
#include <vector>

#include "kernels/ray.h"
#include "render/ray_offset.h"
#include "scene/scene.h"

namespace raypack {

// Scenes that move (Scene::moving_instances): with `times`, each set gives
// every ray a scene time, one per pixel drawn uniformly over the shutter
// (the same every run), and shadow and diffuse rays leave the surface their
// camera ray met at that time; times->size() == the set's size. Without
// `times` (or for a static scene) rays have no time: the shutter's opening.

/// The order of the pixels in a set: image rows from the top, or tiles of
/// 8 x 8 pixels (rows of tiles from the top) whose pixels come in 4 x 4
/// blocks, each block row by row (render/tiles.h): every 8, 16, 32 and 64
/// consecutive rays of a tile are a 4 x 2, 4 x 4, 8 x 4 and 8 x 8 patch, as
/// a renderer's packets are. Shadow and diffuse sets follow their camera
/// rays' order.
enum class PixelOrder { Rows, Tiles };

/// One ray through each pixel centre.
std::vector<Rayf> camera_ray_set(const Scene& scene, int width, int height, std::vector<float>* times = nullptr,
                                 PixelOrder order = PixelOrder::Rows);

/// From each camera-ray hit (found with the reference BVH2) toward the first
/// light, offset off the surface by `offset`; tfar stops just short of the
/// light. Empty when the scene has no light.
std::vector<Rayf> shadow_ray_set(const Scene& scene, int width, int height, OffsetPolicy offset = kDefaultOffset,
                                 std::vector<float>* times = nullptr, PixelOrder order = PixelOrder::Rows);

/// From each camera-ray hit, one diffuse bounce: a cosine-weighted unit
/// direction about the shading normal turned toward the incoming ray (Malley's
/// method: a uniform point on the unit disk lifted onto the hemisphere, Pharr,
/// Jakob, Humphreys, PBR 4th ed., 13.6.3). Pixel i draws from a generator
/// seeded by (seed, i) (i: the pixel's place in the set), so the set is the same every run and for any thread
/// count. Origins are offset off the surface as for shadow rays; tfar = inf.
std::vector<Rayf> diffuse_ray_set(const Scene& scene, int width, int height, std::uint64_t seed = 1,
                                  OffsetPolicy offset = kDefaultOffset, std::vector<float>* times = nullptr,
                                  PixelOrder order = PixelOrder::Rows);

}  // namespace raypack
