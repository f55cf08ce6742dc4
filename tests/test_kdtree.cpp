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
#include "tests/cell_test_cases.h"
#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "accel/kdtree/kdtree_accel.h"
#include "accel/kdtree/kdtree_build.h"
#include "accel/kdtree/primitive_clipper.h"
#include "render/camera_rays.h"
#include "scene/load.h"

namespace raypack::kdtree_test {

using namespace raypack::oracle_harness;
using namespace raypack::cell_test_cases;
namespace {

// ---- Tracing and comparing --------------------------------------------------------

/// Closest hit and occlusion of every ray against brute force, then packets
/// against single rays bit for bit (the same kernels per lane).
void expect_agreement(const Scene& scene, const Accel& tree, const std::vector<Rayf>& rays, const std::string& what) {
    expect_oracle_agreement(scene, tree, rays, what, PacketAnswers::BitForBit);
}

// ---- Building -----------------------------------------------------------------------

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
    std::size_t empty_spaces = 0;
    std::function<void(std::uint32_t, const Box3f&, int)> walk = [&](std::uint32_t n, const Box3f& voxel, int d) {
        depth = std::max(depth, d);
        if (n == 0 && d > 0) {  // empty space: an empty leaf without a node
            ++leaves, ++empty, ++empty_spaces;
            return;
        }
        ASSERT_LT(n, t.nodes.size());
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
        // The above child comes after the below subtree (or right after its
        // parent when the below side is empty); never both sides empty.
        EXPECT_TRUE(node.above_child() == 0 || node.above_child() > n) << n;
        EXPECT_TRUE(node.below_child(n) != 0 || node.above_child() != 0) << n;
        Box3f below = voxel, above = voxel;
        below.hi[a] = node.split();
        above.lo[a] = node.split();
        walk(node.below_child(n), below, d + 1);
        walk(node.above_child(), above, d + 1);
    };
    if (!t.empty()) walk(0, t.bounds, 0);
    // Empty space has no node: the tree's nodes are its inner nodes and
    // leaves but the empty ones it stands for.
    EXPECT_EQ(t.nodes.size() + empty_spaces, 2 * t.leaves - 1);
    EXPECT_EQ(leaves, t.leaves);
    EXPECT_EQ(empty, accel.empty_leaves());
    EXPECT_EQ(refs, t.references);
    EXPECT_EQ(depth, accel.stats().depth);
    EXPECT_EQ(accel.stats().nodes, t.nodes.size());
    EXPECT_EQ(accel.stats().leaves, leaves);
    EXPECT_EQ(accel.stats().bytes, t.nodes.size() * 8 + (t.prim_index.size() + t.outside.size()) * 4);
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
    expect_agreement(scene, tree, kdtree_adversarial_rays(tree.tree(), scene, rng), GetParam() + " adversarial");
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

// Packets of rays from one point walk in groups (kdtree_packet.cpp,
// trace_group): the same answers, bit for bit, as every packet alone and as
// single rays, for camera rays, for rays from one point inside the scene in
// every direction (a group of one octant, or packets of mixed octants that
// walk alone) and, for occlusion, for rays from the first light to the
// camera rays' hits (one origin, many ends), at every compiled width.
TEST_P(KdTree, PacketGroupsGiveThePacketsAnswers) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    KdTreeConfig alone_config;
    alone_config.packet_groups = false;
    const auto grouped = make_tree(scene), alone = make_tree(scene, alone_config);
    const BruteForce brute(scene, KernelChoice{});
    const std::vector<Rayf> camera = camera_rays(scene, 64);
    const std::vector<Rayf> rays = packet_group_rays(scene, camera, trace_hits(brute, camera), 41);
    int checked = 0;
    for (int width : {4, 8, 16}) {
        if (!grouped->supports_packet(width)) continue;
        ++checked;
        const GroupDifferences d = group_differences(*grouped, *alone, rays, width);
        EXPECT_EQ(d.against_alone, 0u) << GetParam() << " width " << width << ": grouped against alone";
        EXPECT_EQ(d.against_single, 0u) << GetParam() << " width " << width << ": grouped against single rays";
    }
    EXPECT_GE(checked, 1);
}

INSTANTIATE_TEST_SUITE_P(, KdTree, ::testing::ValuesIn(shared_scene_files()), param_name);

// ---- Hand-made scenes -----------------------------------------------------------------

TEST_F(KdTree, TheGroundStaysOutsideTheTree) {
    // SPD balls: the ground (its two triangles, 24 units across) is tested
    // by every ray, and the root voxel fits the sphereflake (under 2 units).
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/balls.nff");
    const KdTreeAccel kd(scene, AccelConfig{});
    EXPECT_EQ(kd.tree().outside, (std::vector<std::uint32_t>{0, 1}));
    EXPECT_LT(kd.tree().bounds.extent().x, 2.0f);
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

static_assert(sizeof(KdNode) == 8);

// Rays against brute force on these scenes: tests/test_cell_structures.cpp.
TEST_F(KdTree, OnePrimitiveIsOneLeaf) {
    // One primitive: a leaf beats any split.
    for (const Scene& scene : one_primitive_scenes()) EXPECT_EQ(make_tree(scene)->tree().nodes.size(), 1u);
    EXPECT_TRUE(make_tree(Scene{})->tree().empty());
}

TEST_F(KdTree, FlatScenesHaveNoPlaneAlongTheFlatAxis) {
    std::mt19937 rng(11);
    for (int axis = 0; axis < 3; ++axis) {
        SCOPED_TRACE(axis);
        const Scene scene = flat_scene(axis, 24, rng);
        const auto tree = make_tree(scene);
        EXPECT_GT(tree->tree().nodes.size(), 100u);
        expect_well_formed(*tree, scene);
        // The root voxel has no thickness there.
        for (const SplitPlane& p : split_planes(tree->tree())) EXPECT_NE(p.axis, axis);
    }
}

TEST_F(KdTree, BigPrimitivesAreInManyLeaves) {
    std::mt19937 rng(13);
    const Scene scene = spanning_scene(rng);
    const auto tree = make_tree(scene);
    expect_well_formed(*tree, scene);
    std::vector<std::size_t> leaves_of(scene.primitive_count(), 0);
    const raypack::KdTree& t = tree->tree();
    for (const KdNode& n : t.nodes) {
        if (!n.is_leaf()) continue;
        const std::uint32_t* p = t.leaf_prims(n);
        for (std::uint32_t k = 0; k < n.prim_count(); ++k) ++leaves_of[p[k]];
    }
    for (std::uint32_t p = 2000; p < 2004; ++p) EXPECT_GT(leaves_of[p], 20u) << p;
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
