// The four BVH builders (binned, sweep, morton, sbvh) under every layout
// (bvh2, bvh4, bvh8) and packet width (1, 4, 8, 16) against the brute-force
// oracle on every shared scene: the same hit or miss, t within relative 1e-5
// (the same primitive, or another one at a shared edge), the same occlusion.
// Rays: camera, random, adversarial (axis-parallel with +-0 components,
// origins on the faces of the tree's boxes, rays aimed at vertices, edges and
// sphere silhouettes) and shadow rays. Then what each builder promises about
// its tree, SAH ordering on the bunny, and the same tree for any thread count.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <random>
#include <sstream>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "accel/bvh/build_from_scene.h"
#include "accel/bvh/bvh2_finalize.h"
#include "accel/bvh/bvh_builders.h"
#include "render/camera_rays.h"
#include "scene/load.h"
#include "tests/oracle_harness.h"

namespace raypack::bvh_builders_test {

using namespace raypack::oracle_harness;
namespace {

std::vector<std::string> scene_specs() {
    std::vector<std::string> specs = {"gen:balls:2", "gen:tetra:3", "gen:mount:3"};
    std::vector<std::string> files;
    for (const auto& e : std::filesystem::directory_iterator(std::string(RAYPACK_SOURCE_DIR) + "/scenes"))
        if (e.path().extension() == ".nff") files.push_back(e.path().filename().string());
    std::sort(files.begin(), files.end());
    specs.insert(specs.end(), files.begin(), files.end());
    specs.push_back("bunny.obj");
    return specs;
}

std::vector<std::string> builders() { return {bvh_builder_names().begin(), bvh_builder_names().end()}; }

Scene load_spec(const std::string& spec) {
    return load_scene(spec.rfind("gen:", 0) == 0 ? spec : std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + spec);
}

// ---- Rays ----------------------------------------------------------------------

/// Camera rays, random rays, then adversarial ones; fewer on large scenes,
/// where the oracle pays for every primitive.
std::vector<Rayf> test_rays(const Scene& scene, const Bvh2& bvh) {
    std::mt19937 rng(20240611u + std::uint32_t(scene.primitive_count()));
    std::uniform_real_distribution<float> u(0, 1);
    const int scale = scene.primitive_count() > 20000 ? 1 : 2;
    std::vector<Rayf> rays;
    const int res = 16 * scale;
    const CameraFrame frame = make_camera_frame(scene.camera, res, res);
    for (int y = 0; y < res; ++y)
        for (int x = 0; x < res; ++x) rays.push_back(camera_ray(frame, float(x) + 0.5f, float(y) + 0.5f));

    const Box3f box = scene_bounds(scene);
    const Box3f around = grown(box, 0.2f);
    for (int i = 0; i < 200 * scale; ++i) {
        Rayf r;
        r.org = random_point(rng, around);
        r.dir = random_direction(rng);
        if (i % 2) r.tfar = u(rng) * length(box.extent());
        rays.push_back(r);
    }

    // Along an axis, the other direction components +0 or -0.
    auto along = [&](int axis, float sign) {
        Vec3f d{signed_zero(rng), signed_zero(rng), signed_zero(rng)};
        d[axis] = sign;
        return d;
    };
    const auto n = std::uint32_t(scene.primitive_count());
    // A point the primitive touches on its box: a vertex or a sphere's pole.
    auto touch_point = [&](std::uint32_t prim) {
        const PrimRef ref = scene.prims[prim];
        switch (ref.kind) {
            case PrimKind::Triangle: {
                const std::uint32_t k = rng() % 3;
                return k == 0 ? scene.triangles.p0[ref.index] : k == 1 ? scene.triangles.p1[ref.index]
                                                                       : scene.triangles.p2[ref.index];
            }
            case PrimKind::Sphere: {
                Vec3f p = scene.spheres.center[ref.index];
                p[int(rng() % 3)] -= scene.spheres.radius[ref.index];
                return p;
            }
            case PrimKind::Cone: return scene.cones.apex[ref.index];
            case PrimKind::HeightField: return scene.height_fields[ref.index].peak();
            case PrimKind::Instance: break;  // no instances here
        }
        return box.center();
    };
    for (int i = 0; i < 100 * scale; ++i) {
        // Axis-parallel through a primitive's extreme point, from outside the scene.
        const int axis = i % 3;
        const float sign = i % 2 ? 1.0f : -1.0f;
        Rayf r;
        r.org = touch_point(rng() % n);
        r.org[axis] = sign > 0 ? box.lo[axis] - 1.0f : box.hi[axis] + 1.0f;
        r.dir = along(axis, sign);
        rays.push_back(r);
    }
    for (int i = 0; i < 100 * scale; ++i) {
        // From a face of a node box of the tree, parallel to it or along an axis in it.
        const Box3f& b = bvh.nodes[rng() % bvh.nodes.size()].box;
        const int axis = int(rng() % 3);
        Rayf r;
        r.org = random_point(rng, b);
        r.org[axis] = rng() % 2 ? b.hi[axis] : b.lo[axis];
        r.dir = i % 2 ? random_direction(rng) : along((axis + 1 + int(rng() % 2)) % 3, rng() % 2 ? 1.0f : -1.0f);
        r.dir[axis] = signed_zero(rng);
        rays.push_back(r);
    }
    for (int i = 0; i < 100 * scale; ++i) {
        // At a vertex, a point of an edge, or tangent to a sphere.
        const std::uint32_t p = rng() % n;
        const PrimRef ref = scene.prims[p];
        Rayf r;
        if (ref.kind == PrimKind::Sphere) {
            // At the silhouette as seen from a random origin: nearly tangent.
            const Vec3f c = scene.spheres.center[ref.index];
            r.org = random_point(rng, around);
            const Vec3f rim = normalize(cross(c - r.org, random_direction(rng)));
            r.dir = c + rim * scene.spheres.radius[ref.index] - r.org;
        } else {
            Vec3f target = touch_point(p);
            if (ref.kind == PrimKind::Triangle && i % 2)
                target = scene.triangles.p0[ref.index] +
                         (scene.triangles.p1[ref.index] - scene.triangles.p0[ref.index]) * u(rng);
            r.org = random_point(rng, around);
            r.dir = target - r.org;
        }
        rays.push_back(r);
    }
    return rays;
}

// ---- The oracle, once per scene ----------------------------------------------------

/// Scenes are loaded once per process, the oracle's answers only when asked for.
const Scene& scene_for(const std::string& spec) {
    static std::map<std::string, std::unique_ptr<Scene>> cache;
    auto& slot = cache[spec];
    if (!slot) slot = std::make_unique<Scene>(load_spec(spec));
    return *slot;
}

struct OracleAnswers {
    const Scene& scene;
    std::vector<Rayf> rays;     ///< closest-hit rays
    std::vector<Hitf> hits;
    std::vector<Rayf> shadow;   ///< any-hit rays
    std::vector<std::uint8_t> occluded;
};

template <class Fn>
void in_chunks(std::size_t n, Fn&& fn) {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 32), [&](const auto& r) { fn(r.begin(), r.size()); });
}

const OracleAnswers& oracle(const std::string& spec) {
    static std::map<std::string, std::unique_ptr<OracleAnswers>> cache;
    auto& slot = cache[spec];
    if (slot) return *slot;
    slot = std::make_unique<OracleAnswers>(OracleAnswers{scene_for(spec), {}, {}, {}, {}});
    OracleAnswers& o = *slot;
    AccelConfig config;
    o.rays = test_rays(o.scene, build_scene_bvh2(o.scene, config));
    const BruteForce brute(o.scene, config.kernels);
    o.hits.resize(o.rays.size());
    in_chunks(o.rays.size(), [&](std::size_t b, std::size_t n) {
        brute.intersect(std::span(o.rays).subspan(b, n), std::span(o.hits).subspan(b, n));
    });
    o.shadow = shadow_rays(o.scene, o.rays, o.hits);
    o.occluded.resize(o.shadow.size());
    in_chunks(o.shadow.size(), [&](std::size_t b, std::size_t n) {
        brute.occluded(std::span(o.shadow).subspan(b, n), std::span(o.occluded).subspan(b, n));
    });
    return o;
}

// ---- Comparison ----------------------------------------------------------------------

bool same_hit(const Hitf& want, const Hitf& got) {
    if (want.found() != got.found()) return false;
    if (!want.found()) return true;
    const float tol = 1e-5f * std::max(std::fabs(want.t), std::fabs(got.t));
    return std::fabs(want.t - got.t) <= tol;  // another primitive only at a shared edge or vertex
}

/// Failures as readable text, at most a few, with the rays that reproduce them.
std::string differences(const OracleAnswers& o, const std::vector<Hitf>& hits, const std::vector<std::uint8_t>& occ) {
    std::ostringstream out;
    int shown = 0;
    std::size_t failures = 0;
    for (std::size_t i = 0; i < o.rays.size(); ++i) {
        if (same_hit(o.hits[i], hits[i])) continue;
        const bool excused = o.hits[i].found() && (!hits[i].found() || hits[i].t > o.hits[i].t) &&
                             outside_own_box(o.scene, o.rays[i], o.hits[i].prim, o.hits[i].t);
        if (excused) continue;
        ++failures;
        if (shown++ < 4)
            out << "\n  ray " << i << ": " << describe(o.rays[i]) << "\n    oracle " << describe(o.hits[i]) << ", got "
                << describe(hits[i]);
    }
    for (std::size_t i = 0; i < o.shadow.size(); ++i) {
        if (o.occluded[i] == occ[i]) continue;
        if (o.occluded[i] && !hit_inside_own_box(o.scene, KernelChoice{}, o.shadow[i])) continue;
        ++failures;
        if (shown++ < 8)
            out << "\n  shadow ray " << i << ": " << describe(o.shadow[i]) << "\n    oracle "
                << int(o.occluded[i]) << ", got " << int(occ[i]);
    }
    if (failures) out << "\n  " << failures << " rays differ";
    return out.str();
}

bool layout_compiled(const std::string& kind) {
    for (const char* k : accel_kinds())
        if (kind == k) return true;
    return false;
}

// ---- Against the oracle -----------------------------------------------------------------

/// Every layout and packet width against the oracle.
void check_against_oracle(const std::string& spec, const std::string& builder) {
    const OracleAnswers& o = oracle(spec);
    for (const char* layout : {"bvh2", "bvh4", "bvh8"}) {
        if (!layout_compiled(layout)) continue;
        AccelConfig config;
        config.kind = layout;
        config.builder = builder;
        const auto accel = build_accel(o.scene, config);
        EXPECT_EQ(accel->stats().builder, builder);
        for (int width : {1, 4, 8, 16}) {
            // bvh2 has no fallback for a width this build does not compile.
            if (std::string(layout) == "bvh2" && !accel->supports_packet(width)) continue;
            SCOPED_TRACE(std::string(layout) + ", packets of " + std::to_string(width));
            std::vector<Hitf> hits(o.rays.size());
            std::vector<std::uint8_t> occ(o.shadow.size());
            // Chunks of 64: whole packets, traced in parallel.
            tbb::parallel_for(tbb::blocked_range<std::size_t>(0, (o.rays.size() + 63) / 64), [&](const auto& r) {
                for (std::size_t c = r.begin(); c < r.end(); ++c) {
                    const std::size_t b = c * 64, n = std::min<std::size_t>(64, o.rays.size() - b);
                    accel->intersect_packets(width, std::span(o.rays).subspan(b, n), std::span(hits).subspan(b, n));
                }
            });
            if (!o.shadow.empty()) accel->occluded_packets(width, o.shadow, occ);
            const std::string diff = differences(o, hits, occ);
            EXPECT_TRUE(diff.empty()) << spec << ", " << builder << diff;
        }
    }
}

// ---- What each builder promises about its tree ---------------------------------------------

bool inside(const Box3f& inner, const Box3f& outer) {
    return inner.lo.x >= outer.lo.x && inner.lo.y >= outer.lo.y && inner.lo.z >= outer.lo.z &&
           inner.hi.x <= outer.hi.x && inner.hi.y <= outer.hi.y && inner.hi.z <= outer.hi.z;
}

bool overlaps(const Box3f& a, const Box3f& b) {
    return a.lo.x <= b.hi.x && a.lo.y <= b.hi.y && a.lo.z <= b.hi.z && b.lo.x <= a.hi.x && b.lo.y <= a.hi.y &&
           b.lo.z <= a.hi.z;
}

/// Every primitive in a leaf (once, or at least once for sbvh), leaves within
/// max_leaf_size, children inside their parents, leaves around their primitives.
void check_tree(const Scene& scene, const std::string& builder) {
    AccelConfig config;
    config.builder = builder;
    const Bvh2 bvh = build_scene_bvh2(scene, config);
    const std::size_t n = scene.primitive_count();
    ASSERT_FALSE(bvh.nodes.empty());
    EXPECT_LE(bvh.depth, kBvhMaxDepth);

    std::vector<int> seen(n, 0);
    std::size_t leaves = 0, entries = 0;
    for (std::size_t i = 0; i < bvh.nodes.size(); ++i) {
        const Bvh2Node& node = bvh.nodes[i];
        if (node.is_leaf()) {
            ++leaves;
            entries += node.count;
            // Every builder keeps leaves within max_leaf_size on these scenes
            // (only coincident centres at the depth limit could exceed it).
            EXPECT_LE(node.count, std::uint32_t(config.max_leaf_size)) << "leaf " << i;
            ASSERT_LE(std::size_t(node.first) + node.count, bvh.prim_index.size());
            for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
                const std::uint32_t p = bvh.prim_index[k];
                ASSERT_LT(p, n);
                ++seen[p];
                const Box3f pb = primitive_bounds(scene, p);
                // A split reference covers part of its primitive's box; a whole one all of it.
                const bool covered = builder == "sbvh" ? overlaps(pb, node.box) : inside(pb, node.box);
                EXPECT_TRUE(covered) << "leaf " << i << " prim " << p;
            }
        } else {
            ASSERT_LT(node.first, bvh.nodes.size());
            ASSERT_GT(node.first, i + 1);  // the left child follows, the right one after its subtree
            EXPECT_TRUE(inside(bvh.nodes[i + 1].box, node.box)) << "left child of " << i;
            EXPECT_TRUE(inside(bvh.nodes[node.first].box, node.box)) << "right child of " << i;
        }
    }
    EXPECT_EQ(leaves, bvh.leaves);
    EXPECT_EQ(entries, bvh.prim_index.size());
    EXPECT_EQ(bvh.nodes.size(), 2 * leaves - 1);
    for (std::size_t p = 0; p < n; ++p) {
        ASSERT_GE(seen[p], 1) << "primitive " << p << " is in no leaf";
        if (builder != "sbvh") {
            ASSERT_EQ(seen[p], 1) << "primitive " << p << " is in several leaves";
        }
    }
    if (builder == "sbvh") {
        EXPECT_LE(bvh.prim_index.size(), std::size_t(double(n) * double(config.reference_budget)));
    }
}

// ---- Each builder on each scene (one test, one process: the scene loads once) ----------------

using SceneAndBuilder = std::tuple<std::string, std::string>;

class BuilderOnScene : public ::testing::TestWithParam<SceneAndBuilder> {};

TEST_P(BuilderOnScene, TreeIsWellFormedAndEveryLayoutMatchesBruteForce) {
    const auto& [spec, builder] = GetParam();
    {
        SCOPED_TRACE("tree");
        check_tree(scene_for(spec), builder);
    }
    check_against_oracle(spec, builder);
}

std::string case_name(const ::testing::TestParamInfo<SceneAndBuilder>& info) {
    std::string s = std::get<0>(info.param) + "_" + std::get<1>(info.param);
    for (char& c : s)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
    return s;
}

INSTANTIATE_TEST_SUITE_P(, BuilderOnScene,
                         ::testing::Combine(::testing::ValuesIn(scene_specs()),
                                            ::testing::ValuesIn(builders())),
                         case_name);


// ---- Across builders and thread counts ------------------------------------------------------

TEST(BvhBuilders, SahCostOrderOnTheBunny) {
    const Scene& scene = scene_for("bunny.obj");
    std::map<std::string, double> cost;
    for (const char* b : bvh_builder_names()) {
        AccelConfig config;
        config.builder = b;
        cost[b] = sah_cost(build_scene_bvh2(scene, config), config.traversal_cost, config.intersection_cost);
    }
    // Spatial splits only add candidates to binned object splits; Morton codes
    // ignore the SAH that the full sweep minimises exactly at every node.
    EXPECT_LE(cost["sbvh"], cost["binned"]);
    EXPECT_GE(cost["morton"], cost["sweep"]);
    EXPECT_GE(cost["morton"], cost["binned"]);
}

TEST(BvhBuilders, SpatialSplitsDuplicateReferencesOnSpheres) {
    // balls.nff: spheres of very different sizes; the duplicates must reach
    // the leaves (and the oracle test above then covers them).
    const Scene& scene = scene_for("balls.nff");
    AccelConfig config;
    config.builder = "sbvh";
    const Bvh2 bvh = build_scene_bvh2(scene, config);
    EXPECT_GT(bvh.prim_index.size(), scene.primitive_count());
}

bool contains(const Box3f& b, const Vec3f& p) {
    return p.x >= b.lo.x && p.x <= b.hi.x && p.y >= b.lo.y && p.y <= b.hi.y && p.z >= b.lo.z && p.z <= b.hi.z;
}

TEST(BvhBuilders, SpatialSplitsCutConesAtTheDiscsThatReachThePlane) {
    // Random cones (cylinders among them) cut by random planes through their
    // boxes: every sampled surface point lies in the part of its side, and a
    // diagonal cylinder cut across its middle keeps about half its box per
    // side, not the whole box clipped at the plane.
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> coord(-5.0f, 5.0f), radius(0.0f, 1.0f), unit(0.0f, 1.0f);
    constexpr double kTwoPi = 6.283185307179586;
    for (int c = 0; c < 400; ++c) {
        const Vec3f base{coord(rng), coord(rng), coord(rng)};
        const Vec3f apex = c % 4 == 0 ? base + Vec3f{0, 0, coord(rng)} : Vec3f{coord(rng), coord(rng), coord(rng)};
        const float rb = radius(rng), ra = c % 3 == 0 ? rb : radius(rng);
        Scene scene;
        scene.materials.emplace_back();
        scene.add_cone(base, rb, apex, ra, 0);
        const Box3f box = primitive_bounds(scene, 0);
        const int axis = c % 3;
        const float position = box.lo[axis] + unit(rng) * (box.hi[axis] - box.lo[axis]);
        Box3f left, right;
        split_cone(base, rb, apex, ra, box, axis, position, left, right);
        // Surface points around the axis (a float frame, the points in double).
        const Vec3f w = normalize(apex - base);
        const Vec3f t = normalize(std::fabs(w.x) < 0.9f ? cross(w, Vec3f{1, 0, 0}) : cross(w, Vec3f{0, 1, 0}));
        const Vec3f b = cross(w, t);
        for (int k = 0; k < 2000; ++k) {
            const double s = unit(rng), phi = kTwoPi * unit(rng);
            const double r = rb + s * (double(ra) - rb);
            Vec3f p;
            for (int a = 0; a < 3; ++a)
                p[a] = float(base[a] + s * (double(apex[a]) - base[a]) + r * (std::cos(phi) * t[a] + std::sin(phi) * b[a]));
            if (!contains(box, p)) continue;  // the point's own rounding
            if (p[axis] <= position) {
                EXPECT_TRUE(contains(left, p)) << "cone " << c << " point " << k << " left";
            }
            if (p[axis] >= position) {
                EXPECT_TRUE(contains(right, p)) << "cone " << c << " point " << k << " right";
            }
        }
    }
    const Vec3f base{0, 0, 0}, apex{4, 4, 0};
    Scene scene;
    scene.materials.emplace_back();
    scene.add_cone(base, 0.1f, apex, 0.1f, 0);
    const Box3f box = primitive_bounds(scene, 0);
    Box3f left, right;
    split_cone(base, 0.1f, apex, 0.1f, box, 0, 2.0f, left, right);
    EXPECT_LT(left.hi.y, 2.2f);   // clipped boxes would reach 4.07
    EXPECT_GT(right.lo.y, 1.8f);
    EXPECT_GE(left.hi.x, 2.0f);
    EXPECT_LE(right.lo.x, 2.0f);
}

TEST(BvhBuilders, BinnedTreeDoesNotDependOnThreadCount) {
    // The bunny is large enough for parallel binning at the top and parallel subtrees below.
    const Scene& scene = scene_for("bunny.obj");
    const AccelConfig config;
    std::vector<Bvh2> trees;
    for (int threads : {1, 2, 4}) {
        tbb::task_arena arena(threads);
        arena.execute([&] { trees.push_back(build_scene_bvh2(scene, config)); });
    }
    for (std::size_t t = 1; t < trees.size(); ++t) {
        ASSERT_EQ(trees[t].nodes.size(), trees[0].nodes.size());
        EXPECT_EQ(0, std::memcmp(trees[t].nodes.data(), trees[0].nodes.data(), trees[0].nodes.size() * sizeof(Bvh2Node)));
        EXPECT_EQ(trees[t].prim_index, trees[0].prim_index);
    }
}

/// Scenes that break naive builders: nothing, one primitive, piles of
/// primitives with the same centre (no SAH split separates them), and a
/// nest of triangles of every size around one centre.
std::vector<std::pair<std::string, Scene>> degenerate_scenes() {
    std::vector<std::pair<std::string, Scene>> scenes(4);
    for (auto& entry : scenes) entry.second.materials.emplace_back();
    scenes[0].first = "empty";
    scenes[1].first = "one triangle";
    scenes[1].second.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0);
    scenes[2].first = "coincident";
    for (int i = 0; i < 60; ++i) {
        scenes[2].second.add_triangle({-1, -1, 0}, {1, -1, 0}, {0, 1, 0}, 0);
        scenes[2].second.add_sphere({0, 0, 0}, 0.5f, 0);
    }
    scenes[3].first = "nested";
    for (int i = 0; i < 300; ++i) {
        const float s = std::ldexp(1.0f, i % 40 - 20) * (1.0f + float(i) / 300.0f);
        scenes[3].second.add_triangle({-s, -s, float(i) * 1e-3f}, {s, -s, 0}, {0, s, -float(i) * 1e-3f}, 0);
    }
    for (auto& [name, scene] : scenes) scene.update_features();
    return scenes;
}

TEST(BvhBuilders, DegenerateScenesMatchBruteForce) {
    for (const auto& [name, scene] : degenerate_scenes()) {
        std::mt19937 rng(7);
        std::vector<Rayf> rays;
        const Box3f box = scene.primitive_count() ? grown(scene_bounds(scene), 0.5f) : Box3f{{-1, -1, -1}, {1, 1, 1}};
        for (int i = 0; i < 300; ++i) {
            Rayf r;
            r.org = random_point(rng, box);
            r.dir = i % 3 ? random_direction(rng) : Vec3f{signed_zero(rng), signed_zero(rng), i % 2 ? 1.0f : -1.0f};
            rays.push_back(r);
        }
        const BruteForce brute(scene, KernelChoice{});
        std::vector<Hitf> want(rays.size());
        brute.intersect(rays, want);
        for (const std::string& builder : builders())
            for (const char* layout : {"bvh2", "bvh4", "bvh8"}) {
                if (!layout_compiled(layout)) continue;
                AccelConfig config;
                config.kind = layout;
                config.builder = builder;
                const auto accel = build_accel(scene, config);
                std::vector<Hitf> got(rays.size());
                accel->intersect(rays, got);
                for (std::size_t i = 0; i < rays.size(); ++i)
                    ASSERT_TRUE(same_hit(want[i], got[i]) || (want[i].found() && outside_own_box(scene, rays[i], want[i].prim, want[i].t)))
                        << name << ", " << builder << ", " << layout << ", ray " << i << ": " << describe(rays[i])
                        << "\n  oracle " << describe(want[i]) << ", got " << describe(got[i]);
            }
    }
}

TEST(BvhBuilders, UnknownBuilderIsAClearError) {
    const Scene& scene = scene_for("gen:tetra:3");
    AccelConfig config;
    config.builder = "fastest";
    try {
        build_accel(scene, config);
        FAIL() << "no exception";
    } catch (const std::invalid_argument& e) {
        EXPECT_NE(std::string(e.what()).find("binned|sweep|morton|sbvh"), std::string::npos) << e.what();
    }
}

/// Runs the CLI; returns its exit status, with stdout and stderr in `output`.
int cli(const std::string& args, std::string& output) {
    const auto log = std::filesystem::temp_directory_path() / "raypack_test_bvh_builders.log";
    const int status = std::system((std::string(RAYPACK_CLI) + " " + args + " >" + log.string() + " 2>&1").c_str());
    std::ifstream in(log);
    output.assign(std::istreambuf_iterator<char>(in), {});
    return status;
}

TEST(BvhBuilders, CliBuilderOption) {
    const auto rays = std::filesystem::temp_directory_path() / "raypack_test_bvh_builders.rays";
    std::string out;
    ASSERT_EQ(cli("rays gen:tetra:2 --kind camera --res 8 8 -o " + rays.string(), out), 0) << out;
    const std::string trace = "trace gen:tetra:2 --rays " + rays.string() + " --repeat 1 ";
    EXPECT_EQ(cli(trace + "--accel bvh2 --builder morton --json", out), 0) << out;
    EXPECT_NE(out.find("\"builder\":\"morton\""), std::string::npos) << out;
    EXPECT_NE(cli(trace + "--builder fastest", out), 0);
    EXPECT_NE(out.find("binned|sweep|morton|sbvh"), std::string::npos) << out;
    EXPECT_NE(cli(trace + "--accel grid --builder sweep", out), 0);
    EXPECT_NE(out.find("--builder"), std::string::npos) << out;
}

}  // namespace
}  // namespace raypack::bvh_builders_test
