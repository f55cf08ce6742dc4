// The SAH k-d tree (accel/kdtree/) against the brute-force oracle, and its
// packet traversal against its single-ray traversal. The tree runs the very
// same primitive kernels as the oracle, so it must agree exactly: the same
// hit or miss on every ray, bit-identical t for the same primitive, another
// primitive only at a shared edge or vertex, and the same occlusion answers;
// packets of every width must equal single rays bit for bit.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <limits>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "tests/oracle_harness.h"
#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "accel/kdtree/kdtree_accel.h"
#include "accel/kdtree/kdtree_build.h"
#include "accel/kdtree/primitive_clipper.h"
#include "render/camera_rays.h"
#include "scene/load.h"

namespace raypack::kdtree_test {

using namespace raypack::oracle_harness;
namespace {

// ---- Tracing and comparing --------------------------------------------------------

/// Packets of every compiled width against single rays: the same kernels per
/// lane, so the same primitive, t, u and v bit for bit, and the same occlusion.
void expect_packets_equal_single(const Accel& tree, const std::vector<Rayf>& rays, const std::vector<Hitf>& single,
                                 const std::vector<std::uint8_t>& single_occ, const std::string& what) {
    for (int width : {4, 8, 16}) {
        if (!tree.supports_packet(width)) continue;
        const std::vector<Hitf> got = trace_hits(tree, rays, width);
        std::size_t differ = 0;
        std::string first;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Hitf& w = single[i];
            const Hitf& g = got[i];
            const bool same = g.prim == w.prim && std::bit_cast<std::uint32_t>(g.t) == std::bit_cast<std::uint32_t>(w.t) &&
                              (!w.found() || (std::bit_cast<std::uint32_t>(g.u) == std::bit_cast<std::uint32_t>(w.u) &&
                                              std::bit_cast<std::uint32_t>(g.v) == std::bit_cast<std::uint32_t>(w.v)));
            if (!same && ++differ <= 3)
                first += "\n  ray " + std::to_string(i) + ": " + describe(rays[i]) + "\n    single " + describe(w) +
                         ", packet " + describe(g);
        }
        EXPECT_EQ(differ, 0u) << what << " width " << width << ": " << differ << " of " << rays.size()
                              << " packet hits differ from single rays" << first;
        std::size_t n = 0;
        const std::string occ = occlusion_mismatches(rays, single_occ, trace_occlusion(tree, rays, width), n);
        EXPECT_EQ(n, 0u) << what << " width " << width << ": " << n << " packet occlusion answers differ" << occ;
    }
}

/// Closest hit and occlusion of every ray against brute force, then packets
/// against single rays.
void expect_agreement(const Scene& scene, const Accel& tree, const std::vector<Rayf>& rays, const std::string& what) {
    const BruteForce brute(scene, KernelChoice{});
    const std::vector<Hitf> truth = trace_hits(brute, rays);
    const std::vector<Hitf> got = trace_hits(tree, rays);
    std::size_t n = 0;
    const std::string hits = hit_mismatches(rays, truth, got, n);
    EXPECT_EQ(n, 0u) << what << ": " << n << " of " << rays.size() << " closest hits differ" << hits;
    // Brute force finds a closest hit iff some primitive is hit within the
    // ray's [tnear, tfar], which is its occlusion answer.
    std::vector<std::uint8_t> occluded(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) occluded[i] = truth[i].found() ? 1 : 0;
    const std::vector<std::uint8_t> got_occ = trace_occlusion(tree, rays);
    const std::string occ = occlusion_mismatches(rays, occluded, got_occ, n);
    EXPECT_EQ(n, 0u) << what << ": " << n << " of " << rays.size() << " occlusion answers differ" << occ;
    expect_packets_equal_single(tree, rays, got, got_occ, what);
}

// ---- Ray sets -----------------------------------------------------------------------

/// random_rays() (tests/oracle_harness.h) draws origins in the scene box
/// grown by this fraction per side, so that some start outside the structure.
constexpr float kOriginGrowth = 0.2f;

/// A split plane of the built tree, with the voxel of the node it splits.
struct SplitPlane {
    int axis;
    float pos;
    Box3f voxel;
};

std::vector<SplitPlane> split_planes(const raypack::KdTree& tree) {
    std::vector<SplitPlane> planes;
    if (tree.empty()) return planes;
    std::function<void(std::uint32_t, const Box3f&)> walk = [&](std::uint32_t n, const Box3f& voxel) {
        const KdNode& node = tree.nodes[n];
        if (node.is_leaf()) return;
        planes.push_back({node.axis(), node.split(), voxel});
        Box3f below = voxel, above = voxel;
        below.hi[node.axis()] = node.split();
        above.lo[node.axis()] = node.split();
        walk(n + 1, below);
        walk(node.above_child(), above);
    };
    walk(0, tree.bounds);
    return planes;
}

/// Rays that make a k-d tree traversal stumble, built from its own planes.
std::vector<Rayf> adversarial_rays(const raypack::KdTree& tree, const Scene& scene, std::mt19937& rng) {
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
    for (int i = 0; i < 200; ++i) {
        Rayf r;
        const Vec3f target = random_point(rng, box);
        r.org = target - random_direction(rng) * (10.0f * diag);
        r.dir = target - r.org;
        rays.push_back(r);
    }
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

std::unique_ptr<KdTreeAccel> make_tree(const Scene& scene, const KdTreeConfig& kc = {}) {
    return std::make_unique<KdTreeAccel>(scene, AccelConfig{}, kc);
}

/// Structural invariants: children in range, below child right after its
/// parent, split planes strictly inside their voxel, primitive numbers valid,
/// and every leaf's primitives within its voxel's reach.
void expect_well_formed(const KdTreeAccel& accel, const Scene& scene) {
    const raypack::KdTree& t = accel.tree();
    std::size_t leaves = 0, empty = 0, refs = 0;
    int depth = 0;
    std::function<void(std::uint32_t, const Box3f&, int)> walk = [&](std::uint32_t n, const Box3f& voxel, int d) {
        ASSERT_LT(n, t.nodes.size());
        depth = std::max(depth, d);
        const KdNode& node = t.nodes[n];
        if (node.is_leaf()) {
            ++leaves;
            empty += node.prim_count() == 0;
            refs += node.prim_count();
            const std::uint32_t* p = t.leaf_prims(node);
            for (std::uint32_t k = 0; k < node.prim_count(); ++k) {
                ASSERT_LT(p[k], scene.primitive_count());
                const Box3f b = primitive_bounds(scene, p[k]);
                for (int a = 0; a < 3; ++a) {
                    EXPECT_LE(b.lo[a], voxel.hi[a]);
                    EXPECT_GE(b.hi[a], voxel.lo[a]);
                }
            }
            return;
        }
        const int a = node.axis();
        EXPECT_GT(node.split(), voxel.lo[a]);
        EXPECT_LT(node.split(), voxel.hi[a]);
        EXPECT_GT(node.above_child(), n + 1);
        Box3f below = voxel, above = voxel;
        below.hi[a] = node.split();
        above.lo[a] = node.split();
        walk(n + 1, below, d + 1);
        walk(node.above_child(), above, d + 1);
    };
    if (!t.empty()) walk(0, t.bounds, 0);
    EXPECT_EQ(leaves, t.leaves);
    EXPECT_EQ(empty, accel.empty_leaves());
    EXPECT_EQ(refs, t.references);
    EXPECT_EQ(depth, accel.stats().depth);
    EXPECT_EQ(accel.stats().nodes, t.nodes.size());
    EXPECT_EQ(accel.stats().leaves, leaves);
    EXPECT_EQ(accel.stats().bytes, t.nodes.size() * 8 + t.prim_index.size() * 4);
}

// ---- Every shared scene -------------------------------------------------------------


// One fixture for the whole suite, so that every test is called KdTree.*.
class KdTree : public ::testing::TestWithParam<std::string> {};

TEST_P(KdTree, MatchesBruteForce) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    AccelConfig config;
    config.kind = "kdtree";
    const std::unique_ptr<Accel> accel = build_accel(scene, config);
    const auto& tree = dynamic_cast<const KdTreeAccel&>(*accel);
    std::mt19937 rng(20240607);
    const BruteForce brute(scene, KernelChoice{});

    const std::vector<Rayf> camera = camera_rays(scene, 48);
    expect_agreement(scene, tree, camera, GetParam() + " camera");
    expect_agreement(scene, tree, random_rays(scene, rng, 1500, kOriginGrowth), GetParam() + " random");
    expect_agreement(scene, tree, adversarial_rays(tree.tree(), scene, rng), GetParam() + " adversarial");
    const std::vector<Rayf> shadows = shadow_rays(scene, camera, trace_hits(brute, camera));
    std::size_t n = 0;
    const std::vector<std::uint8_t> occ = trace_occlusion(tree, shadows);
    const std::string diff = occlusion_mismatches(shadows, trace_occlusion(brute, shadows), occ, n);
    EXPECT_EQ(n, 0u) << GetParam() << " shadow: " << n << " of " << shadows.size() << " occlusion answers differ"
                     << diff;
    for (int width : {4, 8, 16}) {
        if (!tree.supports_packet(width)) continue;
        EXPECT_EQ(trace_occlusion(tree, shadows, width), occ) << "shadow width " << width;
    }

    // The statistics describe what was built.
    const AccelStats& s = tree.stats();
    EXPECT_EQ(s.name, "kdtree");
    EXPECT_EQ(s.builder, "sah-nlogn");
    EXPECT_GT(s.nodes, 1u);
    EXPECT_GT(s.sah_cost, 0.0);
    EXPECT_GE(tree.references_per_primitive(), 1.0);
    expect_well_formed(tree, scene);
    // The depth limit of pbrt: 8 + 1.3 log2 N.
    EXPECT_LE(s.depth, int(std::lround(8 + 1.3 * std::floor(std::log2(double(scene.primitive_count()))))));
    RecordProperty("nodes", std::to_string(s.nodes));
    RecordProperty("refs_per_prim", std::to_string(tree.references_per_primitive()));
}

INSTANTIATE_TEST_SUITE_P(, KdTree, ::testing::ValuesIn(shared_scene_files()), param_name);

// ---- Hand-made scenes -----------------------------------------------------------------

Scene scene_with(const std::function<void(Scene&)>& add) {
    Scene s;
    s.materials.push_back({});
    add(s);
    s.update_features();
    return s;
}

TEST_F(KdTree, SameTreeForAnyThreadCount) {
    // Subtrees of more than 4096 primitives near the root are built in
    // parallel and spliced in the serial order (kdtree_build.cpp): the tree
    // must come out the same with one thread and with two, its SAH cost to
    // the last bit. gen:mount:7 (32k triangles) takes the parallel path.
    const Scene scene = load_scene("gen:mount:7");
    auto build_with = [&](int threads) {
        tbb::task_arena arena(threads);
        std::unique_ptr<KdTreeAccel> accel;
        arena.execute([&] { accel = std::make_unique<KdTreeAccel>(scene, AccelConfig{}); });
        return accel;
    };
    const auto one = build_with(1), two = build_with(2);
    const raypack::KdTree &a = one->tree(), &b = two->tree();
    ASSERT_EQ(a.nodes.size(), b.nodes.size());
    for (std::size_t i = 0; i < a.nodes.size(); ++i) {
        ASSERT_EQ(a.nodes[i].word, b.nodes[i].word) << "node " << i;
        ASSERT_EQ(a.nodes[i].bits, b.nodes[i].bits) << "node " << i;
    }
    EXPECT_EQ(a.prim_index, b.prim_index);
    EXPECT_EQ(std::bit_cast<std::uint64_t>(a.sah_cost), std::bit_cast<std::uint64_t>(b.sah_cost));
    EXPECT_EQ(a.depth, b.depth);
    EXPECT_EQ(a.leaves, b.leaves);
    EXPECT_EQ(a.empty_leaves, b.empty_leaves);
    EXPECT_EQ(a.references, b.references);
    EXPECT_GT(scene.primitive_count(), 4096u);
}

TEST_F(KdTree, RegisteredAsAnAccelKind) {
    const auto kinds = accel_kinds();
    EXPECT_NE(std::find_if(kinds.begin(), kinds.end(), [](const char* k) { return std::string(k) == "kdtree"; }),
              kinds.end());
    EXPECT_NE(accel_kinds_list().find("kdtree"), std::string::npos);
    static_assert(sizeof(KdNode) == 8);
}

TEST_F(KdTree, OnePrimitiveOfEachKind) {
    const std::vector<Scene> scenes = {
        scene_with([](Scene& s) { s.add_sphere({1, 2, 3}, 0.5f, 0); }),
        scene_with([](Scene& s) { s.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 1}, 0); }),
        scene_with([](Scene& s) { s.add_cone({0, 0, 0}, 0.5f, {0, 0, 2}, 0.1f, 0); }),
    };
    std::mt19937 rng(7);
    for (const Scene& scene : scenes) {
        const auto tree = make_tree(scene);
        EXPECT_EQ(tree->tree().nodes.size(), 1u);  // one primitive: a leaf beats any split
        std::vector<Rayf> rays = random_rays(scene, rng, 500, kOriginGrowth);
        const std::vector<Rayf> adv = adversarial_rays(tree->tree(), scene, rng);
        rays.insert(rays.end(), adv.begin(), adv.end());
        expect_agreement(scene, *tree, rays, "one " + std::to_string(int(scene.prims[0].kind)));
    }
}

TEST_F(KdTree, EmptySceneMissesEverything) {
    const Scene scene;
    const auto tree = make_tree(scene);
    Rayf r;
    r.dir = {1, 1, 1};
    EXPECT_FALSE(tree->intersect1(r).found());
    EXPECT_FALSE(tree->occluded1(r));
    EXPECT_TRUE(tree->tree().empty());
    for (int width : {4, 8, 16}) {
        if (!tree->supports_packet(width)) continue;
        Hitf h;
        tree->intersect_packets(width, {&r, 1}, {&h, 1});
        EXPECT_FALSE(h.found());
    }
}

/// A triangulated square of n x n quads in the plane `axis` = 0.5, plus
/// random triangles in the same plane.
Scene flat_scene(int axis, int n, std::mt19937& rng) {
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

TEST_F(KdTree, FlatScenes) {
    std::mt19937 rng(11);
    for (int axis = 0; axis < 3; ++axis) {
        SCOPED_TRACE(axis);
        const Scene scene = flat_scene(axis, 24, rng);
        const auto tree = make_tree(scene);
        EXPECT_GT(tree->tree().nodes.size(), 100u);
        expect_well_formed(*tree, scene);
        // No plane along the flat axis: the root voxel has no thickness there.
        for (const SplitPlane& p : split_planes(tree->tree())) EXPECT_NE(p.axis, axis);

        std::vector<Rayf> rays = random_rays(scene, rng, 1000, kOriginGrowth);
        const std::vector<Rayf> adv = adversarial_rays(tree->tree(), scene, rng);
        rays.insert(rays.end(), adv.begin(), adv.end());
        std::uniform_real_distribution<float> u(0, 1);
        for (int i = 0; i < 1500; ++i) {
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
        expect_agreement(scene, *tree, rays, "flat " + std::to_string(axis));
    }
}

TEST_F(KdTree, PrimitivesSpanningManyLeaves) {
    std::mt19937 rng(13);
    std::uniform_real_distribution<float> u(0, 1);
    const Scene scene = scene_with([&](Scene& s) {
        for (int i = 0; i < 2000; ++i) {
            const Vec3f p{u(rng) * 10, u(rng) * 10, u(rng) * 10};
            s.add_triangle(p, p + Vec3f{0.2f, 0, 0}, p + Vec3f{0, 0.2f, 0.1f}, 0);
        }
        // Huge triangles across the whole box, a big sphere and a long thin cone.
        s.add_triangle({-1, -1, 5}, {11, -1, 5.5f}, {5, 11, 4}, 0);
        s.add_triangle({0, 0, 0}, {10, 10, 10}, {10, 0, 10}, 0);
        s.add_sphere({5, 5, 5}, 3, 0);
        s.add_cone({0, 10, 0}, 0.3f, {10, 0, 10}, 0.3f, 0);
    });
    const auto tree = make_tree(scene);
    expect_well_formed(*tree, scene);
    // The big primitives are each in many leaves.
    std::vector<std::size_t> leaves_of(scene.primitive_count(), 0);
    const raypack::KdTree& t = tree->tree();
    for (const KdNode& n : t.nodes) {
        if (!n.is_leaf()) continue;
        const std::uint32_t* p = t.leaf_prims(n);
        for (std::uint32_t k = 0; k < n.prim_count(); ++k) ++leaves_of[p[k]];
    }
    for (std::uint32_t p = 2000; p < 2004; ++p) EXPECT_GT(leaves_of[p], 20u) << p;
    std::vector<Rayf> rays = random_rays(scene, rng, 3000, kOriginGrowth);
    const std::vector<Rayf> adv = adversarial_rays(t, scene, rng);
    rays.insert(rays.end(), adv.begin(), adv.end());
    expect_agreement(scene, *tree, rays, "spanning");
}

TEST_F(KdTree, PerfectSplitsGiveFewerReferences) {
    // Long diagonal triangles: their boxes overlap many voxels they never meet.
    std::mt19937 rng(23);
    std::uniform_real_distribution<float> u(0, 1);
    const Scene scene = scene_with([&](Scene& s) {
        for (int i = 0; i < 3000; ++i) {
            const Vec3f p{u(rng) * 10, u(rng) * 10, u(rng) * 10};
            s.add_triangle(p, p + Vec3f{2, 2, 2}, p + Vec3f{2.05f, 2, 2}, 0);
        }
    });
    KdTreeConfig boxes_only;
    boxes_only.perfect_splits = false;
    const auto perfect = make_tree(scene), plain = make_tree(scene, boxes_only);
    EXPECT_LT(perfect->stats().sah_cost, plain->stats().sah_cost);
    expect_agreement(scene, *perfect, random_rays(scene, rng, 1500, kOriginGrowth), "perfect");
    expect_agreement(scene, *plain, random_rays(scene, rng, 1500, kOriginGrowth), "boxes only");
}

TEST_F(KdTree, ClippedTriangleBoundsAreTight) {
    // Triangle (0,0,0) (4,0,0) (0,4,0) in the voxel [1,3]^2 x [-1,1]: the
    // clipped polygon is the part below x + y = 4.
    Box3f voxel;
    voxel.lo = {1, 1, -1};
    voxel.hi = {3, 3, 1};
    Box3f b;
    ASSERT_TRUE(PrimitiveClipper::clip_triangle({0, 0, 0}, {4, 0, 0}, {0, 4, 0}, voxel, b));
    EXPECT_EQ(b.lo, (Vec3f{1, 1, 0}));
    EXPECT_EQ(b.hi, (Vec3f{3, 3, 0}));
    // Beyond the hypotenuse: nothing.
    voxel.lo = {2.5f, 2.5f, -1};
    EXPECT_FALSE(PrimitiveClipper::clip_triangle({0, 0, 0}, {4, 0, 0}, {0, 4, 0}, voxel, b));
    // Touching the voxel in one point counts (closed voxels).
    voxel.lo = {2, 2, -1};
    ASSERT_TRUE(PrimitiveClipper::clip_triangle({0, 0, 0}, {4, 0, 0}, {0, 4, 0}, voxel, b));
    EXPECT_EQ(b.lo, (Vec3f{2, 2, 0}));
    EXPECT_EQ(b.hi, (Vec3f{2, 2, 0}));
}

TEST_F(KdTree, SahTerminatesAndDepthIsLimited) {
    // Many copies of one triangle: no plane separates them, so the root stays a leaf.
    const Scene same = scene_with([](Scene& s) {
        for (int i = 0; i < 50; ++i) s.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 1}, 0);
    });
    EXPECT_EQ(make_tree(same)->tree().nodes.size(), 1u);
    // An explicit depth limit holds.
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/teapot.nff");
    KdTreeConfig kc;
    kc.max_depth = 6;
    const auto shallow = make_tree(scene, kc);
    EXPECT_LE(shallow->stats().depth, 6);
    std::mt19937 rng(3);
    expect_agreement(scene, *shallow, random_rays(scene, rng, 500, kOriginGrowth), "depth 6");
    // Cheaper intersections relative to traversal: fewer, bigger leaves.
    kc = {};
    kc.intersection_cost = 1;
    EXPECT_LT(make_tree(scene, kc)->stats().nodes, make_tree(scene)->stats().nodes);
}

TEST_F(KdTree, BuildIsDeterministic) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/tetra.nff");
    const auto a = make_tree(scene), b = make_tree(scene);
    ASSERT_EQ(a->tree().nodes.size(), b->tree().nodes.size());
    for (std::size_t i = 0; i < a->tree().nodes.size(); ++i) {
        EXPECT_EQ(a->tree().nodes[i].word, b->tree().nodes[i].word);
        EXPECT_EQ(a->tree().nodes[i].bits, b->tree().nodes[i].bits);
    }
    EXPECT_EQ(a->tree().prim_index, b->tree().prim_index);
}

TEST_F(KdTree, CountingModeAgreesAndCounts) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/teapot.nff");
    const auto tree = make_tree(scene);
    const std::vector<Rayf> rays = camera_rays(scene, 32);
    KdRayCounters c;
    for (const Rayf& r : rays) {
        const Hitf want = tree->intersect1(r);
        const Hitf got = tree->intersect_counting(r, c);
        EXPECT_EQ(want.prim, got.prim);
        EXPECT_EQ(want.t, got.t);
        EXPECT_EQ(tree->occluded1(r), tree->occluded_counting(r, c));
    }
    EXPECT_EQ(c.rays, 2 * rays.size());
    EXPECT_GT(c.nodes_visited, c.leaves_visited);
    EXPECT_GT(c.prim_tests, 0u);

    // Two tiny spheres far apart: a ray between them visits no primitive;
    // a ray that misses the tree visits no node.
    const Scene corners = scene_with([](Scene& s) {
        s.add_sphere({0, 0, 0}, 0.01f, 0);
        s.add_sphere({1, 1, 1}, 0.01f, 0);
    });
    const auto sparse = make_tree(corners);
    ASSERT_GT(sparse->stats().nodes, 1u);
    EXPECT_GT(sparse->empty_leaves(), 0u);
    Rayf r;
    r.org = {-1, 0.5f, 0.5f};
    r.dir = {1, 0, 0};
    KdRayCounters between;
    EXPECT_FALSE(sparse->intersect_counting(r, between).found());
    EXPECT_GT(between.nodes_visited, 0u);
    EXPECT_EQ(between.prim_tests, 0u);
    EXPECT_GT(between.leaves_visited, 0u);
    EXPECT_EQ(between.empty_leaves_visited, between.leaves_visited);  // only empty space between them
    EXPECT_GT(c.empty_leaves_visited, 0u);  // the teapot's tree has empty leaves its rays cross
    EXPECT_LT(c.empty_leaves_visited, c.leaves_visited);
    r.org = {-1, 5, 5};
    KdRayCounters none;
    EXPECT_FALSE(sparse->intersect_counting(r, none).found());
    EXPECT_EQ(none.nodes_visited, 0u);
}

TEST_F(KdTree, PacketsWithMixedDirectionsAndRaggedEnds) {
    // Incoherent packets: every lane its own direction signs, some lanes
    // finishing early (short tfar), and a ragged last packet.
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/gears.nff");
    const auto tree = make_tree(scene);
    std::mt19937 rng(29);
    std::vector<Rayf> rays = random_rays(scene, rng, 3001, kOriginGrowth);
    for (std::size_t i = 0; i < rays.size(); i += 7) rays[i].dir.y = (i % 2) ? 0.0f : -0.0f;
    expect_agreement(scene, *tree, rays, "mixed packets");
}

}  // namespace
}  // namespace raypack::kdtree_test
