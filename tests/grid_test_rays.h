#pragma once
// What the uniform grid's and the two-level grid's tests share: tracing a
// ray set through any structure, comparing with brute force (exact hits,
// ties at shared edges aside), and the ray sets that make a grid walk
// stumble.
#include <gtest/gtest.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "accel/grid/grid.h"
#include "tests/oracle_harness.h"

namespace raypack::grid_test_rays {

using namespace raypack::oracle_harness;

// ---- Tracing and comparing --------------------------------------------------------

inline std::vector<Hitf> trace(const Accel& accel, const std::vector<Rayf>& rays) {
    std::vector<Hitf> hits(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 64), [&](const auto& r) {
        accel.intersect(std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                        std::span<Hitf>(hits).subspan(r.begin(), r.size()));
    });
    return hits;
}

inline std::vector<std::uint8_t> trace_occluded(const Accel& accel, const std::vector<Rayf>& rays) {
    std::vector<std::uint8_t> occ(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 64), [&](const auto& r) {
        accel.occluded(std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                       std::span<std::uint8_t>(occ).subspan(r.begin(), r.size()));
    });
    return occ;
}

/// Closest hit and occlusion of every ray, grid against brute force.
inline void expect_agreement(const Scene& scene, const Accel& grid, const std::vector<Rayf>& rays,
                             const std::string& what) {
    const BruteForce brute(scene, KernelChoice{});
    const std::vector<Hitf> truth = trace(brute, rays);
    std::size_t n = 0;
    const std::string hits = hit_mismatches(rays, truth, trace(grid, rays), n);
    EXPECT_EQ(n, 0u) << what << ": " << n << " of " << rays.size() << " closest hits differ" << hits;
    // Brute force finds a closest hit iff some primitive is hit within the
    // ray's original [tnear, tfar], which is its occlusion answer.
    std::vector<std::uint8_t> occluded(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = truth[i].found() ? 1 : 0;
    const std::string occ = occlusion_mismatches(rays, occluded, trace_occluded(grid, rays), n);
    EXPECT_EQ(n, 0u) << what << ": " << n << " of " << rays.size() << " occlusion answers differ" << occ;
}

// ---- Ray sets -----------------------------------------------------------------------

/// Rays that make a 3D-DDA stumble, built from the grid's own planes.
inline std::vector<Rayf> grid_adversarial_rays(const GridGeometry& g, const Scene& scene, std::mt19937& rng) {
    std::vector<Rayf> rays;
    const Box3f box = g.bounds;
    std::uniform_real_distribution<float> u(0, 1);
    auto plane = [&](int axis) { return g.plane(axis, int(rng() % std::uint32_t(g.res[axis] + 1))); };
    auto corner = [&] { return Vec3f{plane(0), plane(1), plane(2)}; };
    // 1. Along cell edges: the two other coordinates exactly on cell planes,
    //    axis-parallel, from outside the grid.
    append_edge_rays(rays, rng, box, corner, 600);
    // 2. Inside a cell plane (that direction component +-0), from inside the grid.
    append_in_plane_rays(rays, rng, box, plane, 600);
    // 3. Axis-parallel from random origins in and around the grid; half with a finite tfar.
    append_axis_parallel_rays(rays, rng, box, 600);
    // 4. Starting inside cells, some from tnear > 0 (the walk begins mid-grid).
    append_inside_rays(rays, rng, box, 600);
    // 5. Through cell corners, and from cell corners.
    append_corner_rays(rays, rng, box, corner, 900);
    // 6. Along cell diagonals: ties between all three axes at every step.
    append_diagonal_rays(rays, rng, [&] { return g.cell_size; }, corner, 300);
    // 7. From far away (10 grid diagonals), aimed into the grid.
    append_far_rays(rays, rng, box, 300);
    // 8. On the grid's faces, the far ones included: inwards and along the face.
    append_face_rays(rays, rng, box, 300);
    // 9. Aimed at triangle vertices and sphere poles, which lie on cell planes only by chance.
    append_vertex_rays(rays, scene, rng, grown(box, 0.2f), 300);
    return rays;
}

/// Bundles of `rays_per_base` rays around each base ray that share its major direction:
/// the base ray itself (unchanged, so the bundle keeps its edge case) and
/// copies with origins moved by up to `spread_origin` and directions tilted
/// by up to `spread_dir` radians.
inline std::vector<Rayf> bundles(const std::vector<Rayf>& base, std::mt19937& rng, float spread_origin,
                                 float spread_dir, int rays_per_base = 16) {
    std::uniform_real_distribution<float> u(-1, 1);
    std::vector<Rayf> rays;
    for (const Rayf& b : base) {
        const float len = length(b.dir);
        for (int l = 0; l < rays_per_base; ++l) {
            Rayf r = b;
            if (l > 0) {
                r.org = b.org + Vec3f{u(rng), u(rng), u(rng)} * spread_origin;
                r.dir = b.dir + Vec3f{u(rng), u(rng), u(rng)} * (spread_dir * len);
            }
            rays.push_back(r);
        }
    }
    return rays;
}

}  // namespace raypack::grid_test_rays
