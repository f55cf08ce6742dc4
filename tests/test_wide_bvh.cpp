// BVH4 and BVH8 against the brute-force oracle on every shared scene, and
// the structure itself. The wide trees run the oracle's primitive kernels
// (triangle blocks hold the Moeller-Trumbore edges computed exactly as the
// kernel does), so they must agree exactly: the same hit or miss on every
// ray, the same t for the same primitive, another primitive only at (nearly)
// the same t (a shared edge or vertex, t within relative 1e-5), and the same
// occlusion answer. Rays: camera rays, random rays, and adversarial ones
// (axis-parallel with +-0 components, origins on the faces of the tree's own
// boxes with directions parallel to them, rays aimed exactly at mesh
// vertices and at points of edges, rays grazing spheres), plus shadow rays.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cstdio>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "tests/oracle_harness.h"
#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "accel/bvh/build_from_scene.h"
#include "accel/bvh/collapse.h"
#include "accel/bvh/wide_bvh_accel.h"
#include "render/camera_rays.h"
#include "scene/load.h"

namespace raypack::wide_bvh_test {

using namespace raypack::oracle_harness;
namespace {


std::vector<Hitf> trace(const Accel& accel, const std::vector<Rayf>& rays) {
    std::vector<Hitf> hits(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 64), [&](const auto& r) {
        accel.intersect(std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                        std::span<Hitf>(hits).subspan(r.begin(), r.size()));
    });
    return hits;
}

std::vector<std::uint8_t> trace_occluded(const Accel& accel, const std::vector<Rayf>& rays) {
    std::vector<std::uint8_t> occ(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 64), [&](const auto& r) {
        accel.occluded(std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                       std::span<std::uint8_t>(occ).subspan(r.begin(), r.size()));
    });
    return occ;
}

// ---- Ray sets ------------------------------------------------------------------

/// A point of primitive p on its bounding box: a vertex, the top of a
/// sphere, the centre of a cone end.
Vec3f extreme_point(const Scene& s, std::uint32_t p, std::mt19937& rng) {
    const PrimRef ref = s.prims[p];
    const std::uint32_t i = ref.index;
    switch (ref.kind) {
        case PrimKind::Triangle: {
            const int k = int(rng() % 3);
            return k == 0 ? s.triangles.p0[i] : k == 1 ? s.triangles.p1[i] : s.triangles.p2[i];
        }
        case PrimKind::Sphere: {
            Vec3f c = s.spheres.center[i];
            c[int(rng() % 3)] += (rng() % 2 ? 1.0f : -1.0f) * s.spheres.radius[i];
            return c;
        }
        case PrimKind::Cone: return rng() % 2 ? s.cones.base[i] : s.cones.apex[i];
        case PrimKind::HeightField: return s.height_fields[i].peak();
        case PrimKind::Instance: return s.instances[i].bounds.center();
    }
    return {};
}

/// Every child box of a wide tree, for rays that start on their faces.
template <int N, int M>
std::vector<Box3f> child_boxes(const raypack::WideBvh<N, M>& bvh) {
    std::vector<Box3f> boxes;
    for (const WideNode<N>& node : bvh.nodes)
        for (int i = 0; i < N; ++i)
            if (node.child[i] != wide_child::kEmpty) boxes.push_back(node.box(i));
    return boxes;
}

std::vector<Rayf> adversarial_rays(const Scene& scene, const std::vector<Box3f>& tree_boxes, std::mt19937& rng) {
    std::vector<Rayf> rays;
    const Box3f box = scene_bounds(scene);
    const auto nprims = std::uint32_t(scene.primitive_count());
    std::uniform_real_distribution<float> u(0, 1);
    auto axis_dir = [&](int axis, float sign) {
        Vec3f d{signed_zero(rng), signed_zero(rng), signed_zero(rng)};
        d[axis] = sign;
        return d;
    };
    // 1. Axis-parallel rays with +-0 in the other components, through random
    //    points and through extreme points of primitives (on leaf box faces).
    for (int i = 0; i < 600; ++i) {
        const int axis = i % 3;
        const float sign = (i / 3) % 2 ? 1.0f : -1.0f;
        Rayf r;
        r.org = i < 200 ? random_point(rng, box) : extreme_point(scene, std::uint32_t(rng() % nprims), rng);
        r.org[axis] = sign > 0 ? box.lo[axis] - 1.0f : box.hi[axis] + 1.0f;
        r.dir = axis_dir(axis, sign);
        rays.push_back(r);
    }
    // 2. Origins exactly on a face of the tree's own boxes (and of the scene
    //    box): directions parallel to that face (component +-0), and into or
    //    out of the box.
    for (int i = 0; i < 1200; ++i) {
        const Box3f b = i % 4 == 0 || tree_boxes.empty() ? box : tree_boxes[rng() % tree_boxes.size()];
        const int axis = int(rng() % 3);
        const bool hi = rng() % 2;
        Rayf r;
        r.org = random_point(rng, b);
        r.org[axis] = hi ? b.hi[axis] : b.lo[axis];
        r.dir = random_direction(rng);
        if (i % 3 == 0) {
            r.dir[axis] = signed_zero(rng);
        } else if (i % 3 == 1) {
            r.dir = axis_dir(int(rng() % 3), rng() % 2 ? 1.0f : -1.0f);
            r.dir[axis] = signed_zero(rng);
            if (!(dot(r.dir, r.dir) > 0)) r.dir[(axis + 1) % 3] = 1.0f;
        }
        rays.push_back(r);
    }
    // 3. Rays aimed exactly at vertices (and extreme points of spheres and
    //    cones), at points on triangle edges, and grazing sphere silhouettes.
    for (int i = 0; i < 1500; ++i) {
        const std::uint32_t p = std::uint32_t(rng() % nprims);
        const PrimRef ref = scene.prims[p];
        Rayf r;
        if (ref.kind == PrimKind::Sphere && i % 2) {
            const Vec3f c = scene.spheres.center[ref.index];
            const float rad = scene.spheres.radius[ref.index];
            const Vec3f d = random_direction(rng);
            const Vec3f e = normalize(cross(d, random_direction(rng)));
            const float f = i % 3 == 0 ? 1.0f - 1e-6f : i % 3 == 1 ? 1.0f : 1.0f + 1e-6f;
            r.org = c + e * (rad * f) - d * (rad * (2.0f + 4.0f * u(rng)));
            r.dir = d;
        } else {
            Vec3f target = extreme_point(scene, p, rng);
            if (ref.kind == PrimKind::Triangle && i % 3 == 0) {
                const std::uint32_t t = ref.index;
                const Vec3f a = scene.triangles.p0[t], b = scene.triangles.p1[t];
                target = a + (b - a) * u(rng);
            }
            r.org = i % 5 == 0 ? target + axis_dir(int(rng() % 3), rng() % 2 ? 3.0f : -3.0f) : random_point(rng, box);
            r.dir = target - r.org;
            if (!(dot(r.dir, r.dir) > 0)) r.dir = {1, 0, 0};
        }
        rays.push_back(r);
    }
    return rays;
}

// ---- Structure ---------------------------------------------------------------------

bool contains(const Box3f& outer, const Box3f& inner) {
    return outer.lo.x <= inner.lo.x && outer.lo.y <= inner.lo.y && outer.lo.z <= inner.lo.z &&
           outer.hi.x >= inner.hi.x && outer.hi.y >= inner.hi.y && outer.hi.z >= inner.hi.z;
}

/// Every primitive in exactly one leaf lane, boxes containing their
/// subtrees, padding lanes empty, triangle edges as the kernel computes
/// them, and the counts the stats report.
template <int N, int M>
void check_structure(const raypack::WideBvh<N, M>& bvh, const Scene& scene, const AccelStats& stats) {
    const std::size_t n = scene.primitive_count();
    std::vector<int> seen(n, 0);
    std::vector<int> visits(bvh.nodes.size(), 0);
    std::size_t leaves = 0, problems = 0;
    int depth = 0;
    auto fail = [&](const std::string& what) {
        if (++problems <= 5) ADD_FAILURE() << what;
    };
    // Checks one run of blocks of a leaf with box `box`.
    auto check_run = [&](std::uint32_t kind, std::uint32_t first, std::uint32_t count, const Box3f& box) {
        for (std::uint32_t b = first; b < first + count; ++b) {
            std::uint32_t used = 0;
            for (int j = 0; j < M; ++j) {
                const std::uint32_t p = PrimKinds::dispatch(PrimKind(kind), [&]<class Kind>() {
                    return bvh.template blocks<Kind>().at(b).prim[j];
                });
                if (p == kNoPrim) continue;
                ++used;
                if (p >= n) { fail("bad primitive number"); continue; }
                ++seen[p];
                if (int(scene.prims[p].kind) != int(kind)) fail("primitive in a block of another kind");
                if (!contains(box, primitive_bounds(scene, p))) fail("leaf box does not contain primitive " + std::to_string(p));
                if (PrimKind(kind) == PrimKind::Triangle && bvh.triangle_layout == TriangleLayout::Edges) {
                    const std::uint32_t t = scene.prims[p].index;
                    const TriangleBlock<M>& tb = bvh.template blocks<TrianglePrims>()[b];
                    const Vec3f p0 = scene.triangles.p0[t], e1n = p0 - scene.triangles.p1[t],
                                e2 = scene.triangles.p2[t] - p0;
                    const Vec3f ng = fused_cross(e1n, e2);
                    for (int a = 0; a < 3; ++a)
                        if (tb.p0[a][j] != p0[a] || tb.a[a][j] != e1n[a] || tb.b[a][j] != e2[a] || tb.ng[a][j] != ng[a])
                            fail("triangle block data differs from the kernel's");
                }
            }
            if (used == 0) fail("empty block");
        }
    };
    // Returns the union of the boxes below.
    auto walk = [&](auto&& self, std::uint32_t index, int level) -> void {
        depth = std::max(depth, level);
        if (index >= bvh.nodes.size()) return fail("child index out of range");
        if (++visits[index] > 1) return fail("node reached twice");
        const WideNode<N>& node = bvh.nodes[index];
        bool empty_seen = false;
        for (int i = 0; i < N; ++i) {
            const std::uint32_t c = node.child[i];
            const Box3f box = node.box(i);
            if (c == wide_child::kEmpty) {
                empty_seen = true;
                if (!(box.lo.x == INFINITY && box.hi.x == -INFINITY)) fail("empty slot with a non-empty box");
                continue;
            }
            if (empty_seen) fail("used slot after an empty one");
            if (box.empty()) fail("used slot with an empty box");
            if (!wide_child::is_leaf(c)) {
                if (c >= bvh.nodes.size()) { fail("child index out of range"); continue; }
                const WideNode<N>& child = bvh.nodes[c];
                for (int k = 0; k < N; ++k)
                    if (child.child[k] != wide_child::kEmpty && !contains(box, child.box(k)))
                        fail("child box does not contain its subtree");
                self(self, c, level + 1);
                continue;
            }
            ++leaves;
            const std::uint32_t kind = wide_child::kind(c);
            if (kind == wide_child::kMixed) {
                const MixedLeaf& m = bvh.mixed.at(wide_child::first(c));
                for (int k = 0; k < kPrimKinds; ++k) check_run(std::uint32_t(k), m.first[k], m.count[k], box);
            } else {
                check_run(kind, wide_child::first(c), wide_child::blocks(c), box);
            }
        }
    };
    if (n == 0) {
        EXPECT_TRUE(bvh.nodes.empty());
        return;
    }
    ASSERT_FALSE(bvh.nodes.empty());
    walk(walk, 0, 1);
    for (std::size_t p = 0; p < n; ++p)
        if (seen[p] != 1) fail("primitive " + std::to_string(p) + " in " + std::to_string(seen[p]) + " leaves");
    for (std::size_t i = 0; i < visits.size(); ++i)
        if (visits[i] != 1) fail("node " + std::to_string(i) + " unreachable");
    EXPECT_EQ(problems, 0u);
    EXPECT_EQ(stats.nodes, bvh.nodes.size());
    EXPECT_EQ(stats.leaves, leaves);
    EXPECT_EQ(stats.depth, depth);
    EXPECT_EQ(stats.bytes, bvh.bytes());
    EXPECT_GT(stats.sah_cost, 0.0);
}

// ---- Against the oracle ---------------------------------------------------------------

/// One wide configuration under test: how to build it, and its tree for the
/// structural checks.
struct Variant {
    std::string name;
    std::function<std::unique_ptr<Accel>(const Scene&, const AccelConfig&)> build;
};

template <int N, int M, NodeTest Test>
Variant variant(const std::string& name) {
    return {name, [](const Scene& s, const AccelConfig& c) { return std::make_unique<WideBvhAccel<N, M, Test>>(s, c); }};
}

std::vector<Variant> variants() {
    std::vector<Variant> v;
    v.push_back({"bvh4", [](const Scene& s, AccelConfig c) { c.kind = "bvh4"; return build_accel(s, c); }});
    v.push_back({"bvh8", [](const Scene& s, AccelConfig c) { c.kind = "bvh8"; return build_accel(s, c); }});
    v.push_back(variant<4, 4, NodeTest::Ordered>("bvh4 M=4"));
    v.push_back(variant<8, 4, NodeTest::Ordered>("bvh8 M=4"));
    v.push_back(variant<4, 8, NodeTest::Robust>("bvh4 robust slabs"));
    v.push_back(variant<8, 8, NodeTest::Robust>("bvh8 robust slabs"));
    v.push_back({"bvh8 greedy collapse", [](const Scene& s, const AccelConfig& c) {
                     CollapseConfig cc = WideBvhAccel<8, 8>::collapse_config(c);
                     cc.method = CollapseMethod::Greedy;
                     return std::make_unique<WideBvhAccel<8, 8>>(s, c, cc);
                 }});
    return v;
}

/// The tree of a built wide accel, for the structural checks.
template <int N, int M, NodeTest Test>
const raypack::WideBvh<N, M>* tree_of(const Accel& a) {
    const auto* w = dynamic_cast<const WideBvhAccel<N, M, Test>*>(&a);
    return w ? &w->bvh() : nullptr;
}

void check_any_structure(const Accel& a, const Scene& scene) {
    if (const auto* t = tree_of<4, 4, NodeTest::Ordered>(a)) return check_structure(*t, scene, a.stats());
    if (const auto* t = tree_of<8, 4, NodeTest::Ordered>(a)) return check_structure(*t, scene, a.stats());
    if (const auto* t = tree_of<4, 8, NodeTest::Ordered>(a)) return check_structure(*t, scene, a.stats());
    if (const auto* t = tree_of<8, 8, NodeTest::Ordered>(a)) return check_structure(*t, scene, a.stats());
    if (const auto* t = tree_of<4, 8, NodeTest::Robust>(a)) return check_structure(*t, scene, a.stats());
    if (const auto* t = tree_of<8, 8, NodeTest::Robust>(a)) return check_structure(*t, scene, a.stats());
    ADD_FAILURE() << "not a wide BVH: " << a.stats().name;
}

/// Every variant on the same rays against the oracle's answers.
void check_against_oracle(const Scene& scene, const KernelChoice& kernels, int camera_res, int random_count,
                          const std::string& label) {
    AccelConfig config;
    config.kernels = kernels;
    const BruteForce brute(scene, kernels);
    std::mt19937 rng(20240607);
    const std::vector<Variant> vs = variants();
    std::vector<std::unique_ptr<Accel>> accels;
    for (const Variant& v : vs) accels.push_back(v.build(scene, config));
    // Box faces of both trees' nodes (bvh4 and bvh8 differ above the leaves).
    std::vector<Box3f> boxes;
    for (int k = 0; k < 2; ++k) {
        std::vector<Box3f> b = k == 0 ? child_boxes(*tree_of<4, 8, NodeTest::Ordered>(*accels[0]))
                                      : child_boxes(*tree_of<8, 8, NodeTest::Ordered>(*accels[1]));
        boxes.insert(boxes.end(), b.begin(), b.end());
    }
    struct Set {
        const char* name;
        std::vector<Rayf> rays;
    };
    std::vector<Set> sets;
    sets.push_back({"camera", camera_rays(scene, camera_res)});
    sets.push_back({"random", random_rays(scene, rng, random_count)});
    sets.push_back({"adversarial", adversarial_rays(scene, boxes, rng)});
    std::vector<std::vector<Hitf>> truth;
    for (const Set& s : sets) truth.push_back(trace(brute, s.rays));
    std::vector<Rayf> occlusion = shadow_rays(scene, sets[0].rays, truth[0]);
    // Occlusion on the closest-hit sets too: those have no light to aim at.
    for (std::size_t k = 1; k < sets.size(); ++k) occlusion.insert(occlusion.end(), sets[k].rays.begin(), sets[k].rays.end());
    const std::vector<std::uint8_t> occlusion_truth = trace_occluded(brute, occlusion);

    for (std::size_t v = 0; v < vs.size(); ++v) {
        SCOPED_TRACE(vs[v].name + " on " + label);
        const Accel& accel = *accels[v];
        check_any_structure(accel, scene);
        std::size_t excused = 0;
        for (std::size_t k = 0; k < sets.size(); ++k) {
            const Mismatches m = compare_hits(scene, sets[k].rays, truth[k], trace(accel, sets[k].rays), 5);
            EXPECT_EQ(m.count, 0u) << sets[k].name << ": " << m.count << " of " << sets[k].rays.size()
                                   << " rays differ from brute force" << m.first;
            excused += m.excused;
        }
        const Mismatches m =
            compare_occluded(scene, kernels, occlusion, occlusion_truth, trace_occluded(accel, occlusion), 5);
        EXPECT_EQ(m.count, 0u) << "occlusion: " << m.count << " of " << occlusion.size() << " answers differ"
                               << m.first;
        excused += m.excused;
        if (excused != 0 && v == 0)
            std::printf("[   NOTE   ] %s: %zu rays excused, their oracle hits lie outside the primitive's box\n",
                        label.c_str(), excused);
    }
}

// The fixture hides the raypack::WideBvh template here, hence the qualified
// names above; it gives the tests their WideBvh. prefix.
class WideBvh : public ::testing::TestWithParam<std::string> {};

TEST_P(WideBvh, MatchesBruteForce) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    ASSERT_GT(scene.primitive_count(), 0u);
    // The bunny's 69k triangles make the oracle the slow part: fewer rays.
    const bool big = scene.primitive_count() > 20000;
    check_against_oracle(scene, KernelChoice{}, big ? 40 : 64, big ? 1000 : 2000, GetParam());
}

INSTANTIATE_TEST_SUITE_P(, WideBvh, ::testing::ValuesIn(shared_scene_files()), param_name);

// The other kernels change the leaf layout (vertices instead of edges) and
// the sphere test: checked on the scenes with every primitive kind.
TEST_F(WideBvh, OtherKernelsMatchBruteForce) {
    for (const char* file : {"tree.nff", "tetra.nff"}) {
        const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + file);
        check_against_oracle(scene, {SphereMethod::Precise, TriangleMethod::Watertight}, 32, 500,
                             std::string(file) + " (precise, watertight)");
        check_against_oracle(scene, {SphereMethod::Algebraic, TriangleMethod::Plane}, 32, 500,
                             std::string(file) + " (algebraic, plane)");
    }
}

// ---- The node test alone ------------------------------------------------------------------

/// Entry and exit of the float ray through a box in long double: the
/// reference the node test must never be less generous than.
bool box_hit_reference(const Rayf& r, const Box3f& b) {
    if (b.empty()) return false;
    long double t0 = r.tnear, t1 = r.tfar;
    for (int a = 0; a < 3; ++a) {
        const long double o = r.org[a], d = r.dir[a], lo = b.lo[a], hi = b.hi[a];
        if (d == 0) {
            if (o < lo || o > hi) return false;
            continue;
        }
        long double n = (lo - o) / d, f = (hi - o) / d;
        if (n > f) std::swap(n, f);
        t0 = std::max(t0, n);
        t1 = std::min(t1, f);
    }
    return t0 <= t1;
}

template <int N>
void check_node_test(int rays_per_node) {
    std::mt19937 rng(99);
    std::uniform_real_distribution<float> u(-1, 1);
    std::uniform_int_distribution<int> e(-6, 6);
    std::size_t reference_hits = 0, missed = 0, extra = 0;
    std::string first;
    for (int trial = 0; trial < 400; ++trial) {
        // Boxes at scales 2^-6 .. 2^6, away from the origin by up to 2^7.
        const float scale = std::ldexp(1.0f, e(rng)), offset = std::ldexp(1.0f, e(rng) + 1);
        WideNode<N> node;
        std::vector<Box3f> boxes(N);
        for (int i = 0; i < N; ++i) {
            Box3f b;
            const Vec3f c{u(rng) * offset, u(rng) * offset, u(rng) * offset};
            b.extend(c);
            b.extend(c + Vec3f{u(rng), u(rng), u(rng)} * scale);
            if (i == N - 1 && trial % 2) b = Box3f{};  // an unused slot
            boxes[i] = b;
            node.set_box(i, b);
            node.child[i] = 0;
        }
        for (int k = 0; k < rays_per_node; ++k) {
            // Aim at a corner, an edge point or a face point of one box.
            const Box3f& b = boxes[rng() % (N - 1)];
            Vec3f target;
            for (int a = 0; a < 3; ++a) {
                const float t = (rng() % 3 == 0) ? 0.5f * (u(rng) + 1) : float(rng() % 2);
                target[a] = b.lo[a] + t * (b.hi[a] - b.lo[a]);
                if (t == 1.0f) target[a] = b.hi[a];
            }
            Rayf r;
            r.org = Vec3f{u(rng), u(rng), u(rng)} * (offset * 4);
            r.dir = target - r.org;
            if (k % 7 == 0) r.dir[rng() % 3] = 0.0f;  // parallel to one slab
            if (k % 11 == 0) r.org = target - r.dir;   // ends exactly ...
            if (!(dot(r.dir, r.dir) > 0)) continue;
            const NodeRay<N> nr = make_node_ray<NodeTest::Ordered, N>(r);
            vfloat<N> entry;
            const std::uint32_t bits = node_hits<NodeTest::Ordered>(node, nr, vfloat<N>(r.tfar), entry);
            for (int i = 0; i < N; ++i) {
                const bool want = box_hit_reference(r, boxes[i]), got = (bits >> i) & 1u;
                reference_hits += want;
                if (got && !want) {
                    // Only a graze: the box grown by a relative 1e-5 is met.
                    Box3f grown = boxes[i];
                    const float delta = 1e-5f * (length(r.org) + length(grown.lo) + length(grown.hi));
                    grown.extend(grown.lo - Vec3f{delta, delta, delta});
                    grown.extend(grown.hi + Vec3f{delta, delta, delta});
                    extra += !box_hit_reference(r, grown);
                }
                if (want && !got && ++missed <= 3) first += "\n  " + describe(r) + " box " + std::to_string(i);
            }
        }
    }
    EXPECT_EQ(missed, 0u) << "boxes the exact ray meets were culled" << first;
    EXPECT_GT(reference_hits, 1000u);
    EXPECT_EQ(extra, 0u) << "boxes the ray misses by far were entered";
}

TEST_F(WideBvh, NodeTestNeverCullsABoxTheExactRayMeets) {
    check_node_test<4>(400);
#if defined(__AVX2__)
    check_node_test<8>(400);
#endif
}

// ---- Hand-made cases -------------------------------------------------------------------

Scene one_sphere() {
    Scene s;
    s.materials.push_back({});
    s.add_sphere({0, 0, 0}, 1, 0);
    s.update_features();
    return s;
}

TEST_F(WideBvh, RayInBoxPlaneWithSignedZeroDirection) {
    // The ray y = +-1 touches the unit sphere, whose box has a face in that
    // plane; the geometric kernel calls it a hit at t = 5 (see
    // AccelOracle.RayInBoxPlaneWithNegativeZeroDirection). The ordered slab
    // test sees 0 * inf there and must not cull the box for either sign of 0.
    const Scene scene = one_sphere();
    const BruteForce brute(scene, KernelChoice{});
    for (const Variant& v : variants()) {
        const std::unique_ptr<Accel> accel = v.build(scene, AccelConfig{});
        for (float y : {1.0f, -1.0f}) {
            for (float zero : {0.0f, -0.0f}) {
                for (float sign : {1.0f, -1.0f}) {
                    Rayf r;
                    r.org = {-5 * sign, y, 0};
                    r.dir = {sign, zero, zero};
                    const Hitf want = brute.intersect1(r);
                    ASSERT_TRUE(want.found());
                    const Hitf got = accel->intersect1(r);
                    EXPECT_TRUE(got.found()) << v.name << ": " << describe(r);
                    EXPECT_EQ(got.t, want.t) << v.name << ": " << describe(r);
                    EXPECT_TRUE(accel->occluded1(r)) << v.name << ": " << describe(r);
                }
            }
        }
    }
}

TEST_F(WideBvh, EmptySceneMissesEverything) {
    const Scene scene;
    for (const Variant& v : variants()) {
        const std::unique_ptr<Accel> accel = v.build(scene, AccelConfig{});
        Rayf r;
        r.dir = {1, 1, 1};
        EXPECT_FALSE(accel->intersect1(r).found()) << v.name;
        EXPECT_FALSE(accel->occluded1(r)) << v.name;
        EXPECT_EQ(accel->stats().nodes, 0u) << v.name;
    }
}

TEST_F(WideBvh, StatsNameTheStructure) {
    const Scene scene = one_sphere();
    for (const char* kind : {"bvh4", "bvh8"}) {
        AccelConfig config;
        config.kind = kind;
        const auto accel = build_accel(scene, config);
        EXPECT_EQ(accel->stats().name, kind);
        EXPECT_EQ(accel->stats().builder, "binned");
        EXPECT_GE(accel->stats().build_ms, 0.0);
        EXPECT_EQ(accel->stats().nodes, 1u);  // a one-leaf tree: the root holds the leaf
        EXPECT_EQ(accel->stats().leaves, 1u);
    }
}

/// A binary tree whose root is one leaf of every primitive: more blocks than
/// a child slot can name, of three kinds, so the run table is used.
TEST_F(WideBvh, BigMixedLeafUsesRunTable) {
    Scene scene;
    scene.materials.push_back({});
    std::mt19937 rng(5);
    std::uniform_real_distribution<float> u(-1, 1);
    for (int i = 0; i < 45; ++i) {
        const Vec3f c{u(rng), u(rng), u(rng)};
        scene.add_triangle(c, c + Vec3f{0.3f, 0, 0}, c + Vec3f{0, 0.3f, 0.1f}, 0);
        if (i % 3 == 0) scene.add_sphere(c, 0.1f, 0);
        if (i % 5 == 0) scene.add_cone(c, 0.1f, c + Vec3f{0, 0.2f, 0}, 0.05f, 0);
    }
    scene.update_features();
    Bvh2 binary;
    Bvh2Node root;
    for (std::uint32_t p = 0; p < scene.primitive_count(); ++p) {
        root.box.extend(primitive_bounds(scene, p));
        binary.prim_index.push_back(p);
    }
    root.first = 0;
    root.count = std::uint32_t(scene.primitive_count());
    binary.nodes.push_back(root);
    binary.leaves = 1;
    const raypack::WideBvh<8, 4> bvh = collapse_bvh<8, 4>(binary, scene, CollapseConfig{});
    ASSERT_EQ(bvh.nodes.size(), 1u);
    ASSERT_TRUE(wide_child::is_leaf(bvh.nodes[0].child[0]));
    EXPECT_EQ(wide_child::kind(bvh.nodes[0].child[0]), wide_child::kMixed);
    EXPECT_EQ(bvh.blocks<TrianglePrims>().size(), 12u);  // 45 in blocks of 4
    AccelStats stats;
    stats.nodes = 1;
    stats.leaves = 1;
    stats.depth = 1;
    stats.bytes = bvh.bytes();
    stats.sah_cost = sah_cost(bvh, 1.0f, 1.0f);
    check_structure(bvh, scene, stats);

    const BruteForce brute(scene, KernelChoice{});
    const std::vector<Rayf> rays = random_rays(scene, rng, 3000);
    for (const Rayf& r : rays) {
        Hitf got;
        trace_wide<8, 4, TriangleMethod::Moeller, NodeTest::Ordered, false>(bvh, SphereMethod::Geometric, r, got);
        const Hitf want = brute.intersect1(r);
        ASSERT_EQ(got.found(), want.found()) << describe(r);
        if (want.found() && want.prim == got.prim) {
            EXPECT_EQ(got.t, want.t) << describe(r);
        }
        Hitf ignored;
        EXPECT_EQ((trace_wide<8, 4, TriangleMethod::Moeller, NodeTest::Ordered, true>(bvh, SphereMethod::Geometric,
                                                                                       r, ignored)),
                  brute.occluded1(r))
            << describe(r);
    }
}

}  // namespace
}  // namespace raypack::wide_bvh_test

TEST(WideBvhCollapse, SameTreeForAnyThreadCount) {
    // The collapse writes the root's subtrees in parallel, each at offsets
    // counted beforehand (accel/bvh/collapse.cpp): the arrays must come out
    // byte for byte those of one thread. gen:mount:7 (32k triangles, four
    // spheres) is past the parallel threshold (1024 wide nodes).
    const raypack::Scene scene = raypack::load_scene("gen:mount:7");
    const raypack::Bvh2 binary = raypack::build_scene_bvh2(scene, raypack::AccelConfig{});
    auto collapse_with = [&](int threads) {
        tbb::task_arena arena(threads);
        raypack::WideBvh<4, 4> bvh;
        arena.execute([&] { bvh = raypack::collapse_bvh<4, 4>(binary, scene, raypack::CollapseConfig{}); });
        return bvh;
    };
    const raypack::WideBvh<4, 4> one = collapse_with(1), two = collapse_with(2);
    ASSERT_GE(one.nodes.size(), 1024u);  // the parallel path runs
    auto same_bytes = [](const auto& a, const auto& b) {
        // Empty arrays have no data() to compare (memcmp of null is undefined).
        return a.size() == b.size() &&
               (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(a[0])) == 0);
    };
    EXPECT_TRUE(same_bytes(one.nodes, two.nodes));
    raypack::PrimKinds::until([&]<class Kind>() {
        EXPECT_TRUE(same_bytes(one.blocks<Kind>(), two.blocks<Kind>())) << int(Kind::kind);
        return false;
    });
    EXPECT_EQ(one.mixed.size(), two.mixed.size());
    EXPECT_EQ(one.depth, two.depth);
    EXPECT_EQ(one.leaves, two.leaves);
    EXPECT_FALSE(one.blocks<raypack::SpherePrims>().empty());
}
