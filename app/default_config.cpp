#include "app/default_config.h"

#include <algorithm>

#include "kernels/simd.h"

namespace raypack::app {

const char* workload_name(RayWorkload workload) {
    switch (workload) {
        case RayWorkload::Camera: return "camera";
        case RayWorkload::Shadow: return "shadow";
        case RayWorkload::Diffuse: return "diffuse";
    }
    return "camera";
}

RayWorkload classify_workload(std::span<const Rayf> rays, bool any_hit) {
    if (any_hit) return RayWorkload::Shadow;
    if (rays.empty()) return RayWorkload::Camera;
    const Vec3f o = rays.front().org;
    const bool one_origin = std::all_of(rays.begin(), rays.end(), [&](const Rayf& r) {
        return r.org.x == o.x && r.org.y == o.y && r.org.z == o.z;
    });
    return one_origin ? RayWorkload::Camera : RayWorkload::Diffuse;
}

TraceConfig fastest_config(RayWorkload workload) {
    // From the structure table of README.md at e7139a3, "Against Embree on
    // the same rays" (one thread, 1024 x 1024, geometric mean over balls,
    // mount, tetra, teapot and the bunny, median of three runs): wide
    // BVHs with packets of 16 for every kind; BVH4 and BVH8 are within 2-8% of
    // each other throughout, and the packets' single-ray fallback (Benthin et
    // al. 2012) keeps them ahead of one-ray-at-a-time on diffuse rays too.
    TraceConfig c{"bvh8", 16};
    switch (workload) {
        case RayWorkload::Camera: c = {"bvh4", 16}; break;
        case RayWorkload::Shadow: c = {"bvh8", 16}; break;
        case RayWorkload::Diffuse: c = {"bvh4", 16}; break;
    }
    if (c.packet == 16 && !kWidthCompiled<16>) c.packet = 8;
    // Without AVX-512, diffuse rays run faster one at a time through the
    // BVH8 than in packets of 8 (AMD EPYC Zen 3, session 23, 1024 x 1024
    // diffuse rays in tiles, fastest of 3 alternating runs: gears 1.15x,
    // tetra 1.10x, teapot 1.07x, the bunny 1.01x).
    if (workload == RayWorkload::Diffuse && !kWidthCompiled<16>) c = {"bvh8", 1};
    // With AVX-512, diffuse rays as streams (accel/bvh/wide_stream_traversal.h):
    // 1.25-1.45x faster than packets of 16 on balls, gears, teapot and the
    // bunny (session 38, 512 x 512 `rays --kind diffuse`, one thread; BVH4
    // and BVH8 within 2.5%). Shadow rays from camera hits stay packets:
    // streams were 1.2-1.45x slower on them.
    if (workload == RayWorkload::Diffuse && kWidthCompiled<16>) c.stream = true;
    return c;
}

}  // namespace raypack::app
