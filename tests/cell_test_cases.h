#pragma once
// What the tests of the cell structures (uniform grid, two-level grid,
// octree, k-d tree) share: the hand-made scenes they are all held to brute
// force on, and the rays built from each structure's own planes that make its
// walk stumble (the grid's are in tests/grid_test_rays.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <vector>

#include "accel/accel.h"
#include "accel/kdtree/kdtree.h"
#include "accel/octree/octree.h"
#include "scene/scene.h"
#include "tests/oracle_harness.h"

namespace raypack::cell_test_cases {

using namespace raypack::oracle_harness;

// ---- Scenes -------------------------------------------------------------------------

/// A scene with one default material and what `add` puts in it.
inline Scene scene_with(const std::function<void(Scene&)>& add) {
    Scene s;
    s.materials.push_back({});
    add(s);
    s.update_features();
    return s;
}

/// One sphere, one triangle, one cone: a scene each.
inline std::vector<Scene> one_primitive_scenes() {
    return {
        scene_with([](Scene& s) { s.add_sphere({1, 2, 3}, 0.5f, 0); }),
        scene_with([](Scene& s) { s.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 1}, 0); }),
        scene_with([](Scene& s) { s.add_cone({0, 0, 0}, 0.5f, {0, 0, 2}, 0.1f, 0); }),
    };
}

/// A triangulated square of n x n quads in the plane `axis` = 0.5, plus
/// random triangles in the same plane.
inline Scene flat_scene(int axis, int n, std::mt19937& rng) {
    return scene_with([&](Scene& s) {
        auto point = [&](float u, float v) {
            Vec3f p;
            p[axis] = 0.5f;
            p[(axis + 1) % 3] = u;
            p[(axis + 2) % 3] = v;
            return p;
        };
        const float h = 1.0f / float(n);
        for (int i = 0; i < n; ++i) {
            for (int j = 0; j < n; ++j) {
                const float u = float(i) * h, v = float(j) * h;
                s.add_triangle(point(u, v), point(u + h, v), point(u + h, v + h), 0);
                s.add_triangle(point(u, v), point(u + h, v + h), point(u, v + h), 0);
            }
        }
        std::uniform_real_distribution<float> u(0, 1);
        for (int i = 0; i < 100; ++i) s.add_triangle(point(u(rng), u(rng)), point(u(rng), u(rng)), point(u(rng), u(rng)), 0);
    });
}

/// Rays in the plane of flat_scene(axis) (that direction component +-0),
/// across it from off the plane, and straight at it, origins around the
/// unit square.
inline std::vector<Rayf> flat_scene_rays(int axis, std::mt19937& rng, int n) {
    std::vector<Rayf> rays;
    std::uniform_real_distribution<float> u(0, 1);
    for (int i = 0; i < n; ++i) {
        Rayf r;
        r.org[axis] = 0.5f;
        r.org[(axis + 1) % 3] = u(rng) * 1.4f - 0.2f;
        r.org[(axis + 2) % 3] = u(rng) * 1.4f - 0.2f;
        r.dir = random_direction(rng);
        if (i % 3 == 0) {
            r.dir[axis] = signed_zero(rng);  // in the plane
        } else if (i % 3 == 1) {
            r.org -= r.dir * (0.5f + u(rng));  // across the plane, starting off it
        } else {
            r.dir = {signed_zero(rng), signed_zero(rng), signed_zero(rng)};  // straight at the plane
            r.dir[axis] = rng() % 2 ? 1.0f : -1.0f;
            r.org[axis] -= r.dir[axis];
        }
        rays.push_back(r);
    }
    return rays;
}

/// 2000 small triangles in a 10-unit box, then (primitives 2000-2003) two
/// huge triangles across the whole box, a big sphere and a long thin cone:
/// primitives that every structure must place in many cells or leaves.
inline Scene spanning_scene(std::mt19937& rng) {
    std::uniform_real_distribution<float> u(0, 1);
    return scene_with([&](Scene& s) {
        for (int i = 0; i < 2000; ++i) {
            const Vec3f p{u(rng) * 10, u(rng) * 10, u(rng) * 10};
            s.add_triangle(p, p + Vec3f{0.2f, 0, 0}, p + Vec3f{0, 0.2f, 0.1f}, 0);
        }
        s.add_triangle({-1, -1, 5}, {11, -1, 5.5f}, {5, 11, 4}, 0);
        s.add_triangle({0, 0, 0}, {10, 10, 10}, {10, 0, 10}, 0);
        s.add_sphere({5, 5, 5}, 3, 0);
        s.add_cone({0, 10, 0}, 0.3f, {10, 0, 10}, 0.3f, 0);
    });
}

// ---- Adversarial rays -----------------------------------------------------------------

/// Rays that make an octree traversal stumble, from the tree's own planes:
/// the cube's midplanes at depths 1 to 6 (node faces at those depths).
inline std::vector<Rayf> octree_adversarial_rays(const Octree& tree, const Scene& scene, std::mt19937& rng) {
    std::vector<Rayf> rays;
    const Box3f box = tree.cube;
    const float side = box.hi.x - box.lo.x;
    std::uniform_real_distribution<float> u(0, 1);
    // A node plane at a random depth 1..6: lo + side * k / 2^d, as the traversal sees it.
    auto plane = [&](int axis) {
        const int d = 1 + int(rng() % 6);
        const int k = int(rng() % ((1u << d) + 1));
        return box.lo[axis] + (box.hi[axis] - box.lo[axis]) * (float(k) / float(1 << d));
    };
    auto corner = [&] { return Vec3f{plane(0), plane(1), plane(2)}; };
    // 1. Along node edges: the two other coordinates on node planes, axis-parallel, from outside.
    append_edge_rays(rays, rng, box, corner, 600);
    // 2. Inside a node plane (that direction component +-0), from inside the cube.
    append_in_plane_rays(rays, rng, box, plane, 600);
    // 3. Axis-parallel from random origins in and around the cube; half with a finite tfar.
    append_axis_parallel_rays(rays, rng, box, 600);
    // 4. Starting inside the octree (in leaves), some from tnear > 0.
    append_inside_rays(rays, rng, box, 600);
    // 5. Starting exactly on node boundaries (faces, edges, corners).
    for (int i = 0; i < 600; ++i) {
        Rayf r;
        r.org = random_point(rng, box);
        for (int a = 0; a < 3; ++a)
            if (a == i % 3 || rng() % 3 == 0) r.org[a] = plane(a);
        r.dir = random_direction(rng);
        rays.push_back(r);
    }
    // 6. Through node corners, and from node corners.
    append_corner_rays(rays, rng, box, corner, 900);
    // 7. Along node diagonals: ties between all three axes at every midplane.
    append_diagonal_rays(
        rays, rng,
        [&] {
            const float s = side / float(1 << (1 + rng() % 5));
            return Vec3f{s, s, s};
        },
        corner, 300);
    // 8. From far away (10 cube diagonals), aimed into the cube.
    append_far_rays(rays, rng, box, 300);
    // 9. Aimed at triangle vertices and sphere poles.
    append_vertex_rays(rays, scene, rng, grown(box, 0.2f), 300);
    return rays;
}

/// A split plane of a k-d tree, with the voxel of the node it splits.
struct SplitPlane {
    int axis;
    float pos;
    Box3f voxel;
};

inline std::vector<SplitPlane> split_planes(const raypack::KdTree& tree) {
    std::vector<SplitPlane> planes;
    if (tree.empty()) return planes;
    std::function<void(std::uint32_t, const Box3f&)> walk = [&](std::uint32_t n, const Box3f& voxel) {
        const KdNode& node = tree.nodes[n];
        if (node.is_leaf()) return;
        planes.push_back({node.axis(), node.split(), voxel});
        Box3f below = voxel, above = voxel;
        below.hi[node.axis()] = node.split();
        above.lo[node.axis()] = node.split();
        if (node.below_child(n)) walk(node.below_child(n), below);  // 0: empty space
        if (node.above_child()) walk(node.above_child(), above);
    };
    walk(0, tree.bounds);
    return planes;
}

/// Rays that make a k-d tree traversal stumble, built from its own planes.
inline std::vector<Rayf> kdtree_adversarial_rays(const raypack::KdTree& tree, const Scene& scene, std::mt19937& rng) {
    std::vector<Rayf> rays;
    const Box3f box = tree.bounds;
    const float diag = length(box.extent());
    std::uniform_real_distribution<float> u(0, 1);
    const std::vector<SplitPlane> planes = split_planes(tree);
    auto plane = [&]() -> const SplitPlane& { return planes[rng() % planes.size()]; };
    auto plane_on = [&](int axis) {
        for (int tries = 0; tries < 64; ++tries) {
            const SplitPlane& p = plane();
            if (p.axis == axis) return p.pos;
        }
        return box.center()[axis];
    };
    auto axis_dir = [&](int axis, float sign) {
        Vec3f d{signed_zero(rng), signed_zero(rng), signed_zero(rng)};
        d[axis] = sign;
        return d;
    };
    if (!planes.empty()) {
        // 1. Exactly in a split plane (that direction component +-0), starting in its voxel.
        for (int i = 0; i < 400; ++i) {
            const SplitPlane& p = plane();
            Rayf r;
            r.org = random_point(rng, p.voxel);
            r.org[p.axis] = p.pos;
            r.dir = random_direction(rng);
            r.dir[p.axis] = signed_zero(rng);
            rays.push_back(r);
        }
        // 2. In a split plane from outside the tree, aimed across it.
        for (int i = 0; i < 300; ++i) {
            const SplitPlane& p = plane();
            Rayf r;
            Vec3f target = random_point(rng, p.voxel);
            target[p.axis] = p.pos;
            r.org = random_point(rng, grown(box, 0.3f));
            r.org[p.axis] = p.pos;
            r.dir = target - r.org;
            r.dir[p.axis] = signed_zero(rng);
            if (!(dot(r.dir, r.dir) > 0)) r.dir = axis_dir((p.axis + 1) % 3, 1.0f);
            rays.push_back(r);
        }
        // 3. Along the line where split planes of two axes meet, axis-parallel, from outside.
        for (int i = 0; i < 300; ++i) {
            const int a = i % 3;
            const float sign = (i / 3) % 2 ? 1.0f : -1.0f;
            Rayf r;
            r.org[(a + 1) % 3] = plane_on((a + 1) % 3);
            r.org[(a + 2) % 3] = plane_on((a + 2) % 3);
            r.org[a] = sign > 0 ? box.lo[a] - 0.1f * diag : box.hi[a] + 0.1f * diag;
            r.dir = axis_dir(a, sign);
            rays.push_back(r);
        }
        // 4. Starting exactly on a split plane, in all directions.
        for (int i = 0; i < 300; ++i) {
            const SplitPlane& p = plane();
            Rayf r;
            r.org = random_point(rng, p.voxel);
            r.org[p.axis] = p.pos;
            r.dir = random_direction(rng);
            if (i % 3 == 0) r.dir = axis_dir(int(rng() % 3), rng() % 2 ? 1.0f : -1.0f);
            rays.push_back(r);
        }
    }
    // 5. Axis-parallel from random origins in and around the tree; half with a finite tfar.
    append_axis_parallel_rays(rays, rng, box, 400);
    // 6. Starting inside the tree, some from tnear > 0 (the walk begins mid-tree).
    append_inside_rays(rays, rng, box, 400);
    // 7. From far away (10 diagonals), aimed into the tree.
    append_far_rays(rays, rng, box, 200);
    // 8. Aimed at triangle vertices and sphere poles: perfect splits put planes through them.
    const auto nprims = std::uint32_t(scene.primitive_count());
    for (int i = 0; nprims && i < 400; ++i) {
        const PrimRef ref = scene.prims[rng() % nprims];
        Vec3f target;
        if (ref.kind == PrimKind::Triangle) {
            const Vec3f* v[3] = {&scene.triangles.p0[ref.index], &scene.triangles.p1[ref.index],
                                 &scene.triangles.p2[ref.index]};
            target = *v[rng() % 3];
        } else if (ref.kind == PrimKind::Sphere) {
            target = scene.spheres.center[ref.index];
            target[int(rng() % 3)] += scene.spheres.radius[ref.index];
        } else {
            target = scene.cones.apex[ref.index];
        }
        Rayf r;
        r.org = random_point(rng, grown(box, 0.2f));
        r.dir = target - r.org;
        if (i % 4 == 0) {  // axis-parallel through the vertex
            const int a = int(rng() % 3);
            r.org = target;
            r.org[a] -= 0.3f * diag;
            r.dir = axis_dir(a, 1.0f);
        }
        if (!(dot(r.dir, r.dir) > 0)) r.dir = {0, 0, 1};
        rays.push_back(r);
    }
    return rays;
}

// ---- Packets in groups ------------------------------------------------------------------

/// The rays the group walks (k-d tree, octree) are held to their packets
/// alone and to single rays with: `rays` (camera rays, whose hits are
/// `hits`), then 512 rays from a point inside the scene in each direction
/// octant and 512 in mixed octants, then rays from the first light to the
/// camera rays' hits (one origin, many ends; for occlusion).
inline std::vector<Rayf> packet_group_rays(const Scene& scene, std::vector<Rayf> rays, const std::vector<Hitf>& hits,
                                           unsigned seed) {
    std::vector<Rayf> from_light;
    const Vec3f light = scene.lights.empty() ? scene.camera.from : scene.lights.front().position;
    for (std::size_t i = 0; i < hits.size(); ++i)
        if (hits[i].found()) from_light.push_back(Rayf{light, rays[i].org + rays[i].dir * hits[i].t - light, 0.0f, 0.999f});
    std::mt19937 rng(seed);
    const Box3f box = scene_bounds(scene);
    const Vec3f inside = box.lo + box.extent() * 0.37f;
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (int octant = 0; octant < 9; ++octant)  // 8 one-octant runs, then mixed directions
        for (int i = 0; i < 512; ++i) {
            Vec3f d{std::fabs(u(rng)), std::fabs(u(rng)), std::fabs(u(rng))};
            for (int a = 0; a < 3; ++a)
                if (octant == 8 ? u(rng) < 0.0f : ((octant >> a) & 1) != 0) d[a] = -d[a];
            rays.push_back(Rayf{inside, d, 0.0f, std::numeric_limits<float>::infinity()});
        }
    // The camera rays again, each run of 128 led by 16 from the camera and
    // followed by rays from origins spread over 2% of the scene, aimed at
    // the same points: a group led by one point must not take its
    // followers for rays from one point too.
    std::vector<Rayf> spread;
    const float jitter = 0.02f * std::max({box.extent().x, box.extent().y, box.extent().z});
    for (std::size_t i = 0; i < hits.size(); ++i) {
        Rayf r = rays[i];
        if (i % 128 >= 16) {
            const Vec3f target = hits[i].found() ? r.org + r.dir * hits[i].t : r.org + r.dir;
            r.org = r.org + Vec3f{u(rng), u(rng), u(rng)} * jitter;
            r.dir = target - r.org;
            r.tfar = std::numeric_limits<float>::infinity();
        }
        spread.push_back(r);
    }
    rays.insert(rays.end(), from_light.begin(), from_light.end());
    rays.insert(rays.end(), spread.begin(), spread.end());
    return rays;
}

/// How many of `rays`' closest hits or occlusion answers in packets of
/// `width` differ, bit for bit, between a structure walking packets in
/// groups and the same structure walking them alone, and between it and its
/// single rays.
struct GroupDifferences {
    std::size_t against_alone = 0, against_single = 0;
};
inline GroupDifferences group_differences(const Accel& grouped, const Accel& alone, const std::vector<Rayf>& rays,
                                          int width) {
    const std::vector<Hitf> single = trace_hits(grouped, rays), got = trace_hits(grouped, rays, width),
                            want = trace_hits(alone, rays, width);
    const std::vector<std::uint8_t> single_occ = trace_occlusion(grouped, rays),
                                    got_occ = trace_occlusion(grouped, rays, width),
                                    want_occ = trace_occlusion(alone, rays, width);
    GroupDifferences d;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        d.against_alone += !same_bits(got[i], want[i]) || got_occ[i] != want_occ[i];
        d.against_single += !same_bits(got[i], single[i]) || got_occ[i] != single_occ[i];
    }
    return d;
}

}  // namespace raypack::cell_test_cases
