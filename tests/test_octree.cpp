// The octree (accel/octree/) against the brute-force oracle. It runs the very
// same primitive kernels as the oracle, so it must agree exactly: the same
// hit or miss on every ray, bit-identical t for the same primitive, another
// primitive only at a shared edge or vertex (t within 1e-5), the same
// occlusion answers; and its packets of every width must give what its
// single rays give. Adversarial rays are built from the octree's own planes:
// along the cube's midplanes at several depths, through node corners, from
// inside leaves and on node boundaries, axis-parallel with +-0 components.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <tbb/parallel_for.h>

#include <algorithm>
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
#include "accel/grid/triangle_box_overlap.h"
#include "accel/octree/octree_accel.h"
#include "accel/octree/octree_build.h"
#include "accel/octree/revelles.h"
#include "render/camera_rays.h"
#include "scene/load.h"

namespace raypack::octree_test {

using namespace raypack::oracle_harness;
using namespace raypack::cell_test_cases;
namespace {

// ---- Tracing and comparing --------------------------------------------------------

/// Both cores; packets of `width` (1 = single rays), in chunks that are
/// multiples of 16 so that packets are the same whatever the schedule.
std::vector<Hitf> trace(const Accel& accel, const std::vector<Rayf>& rays, int width = 1) {
    std::vector<Hitf> hits(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, (rays.size() + 63) / 64), [&](const auto& r) {
        const std::size_t first = r.begin() * 64, last = std::min(rays.size(), r.end() * 64);
        const auto in = std::span<const Rayf>(rays).subspan(first, last - first);
        const auto out = std::span<Hitf>(hits).subspan(first, last - first);
        if (width == 1) accel.intersect(in, out);
        else accel.intersect_packets(width, in, out);
    });
    return hits;
}

std::vector<std::uint8_t> trace_occluded(const Accel& accel, const std::vector<Rayf>& rays, int width = 1) {
    std::vector<std::uint8_t> occ(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, (rays.size() + 63) / 64), [&](const auto& r) {
        const std::size_t first = r.begin() * 64, last = std::min(rays.size(), r.end() * 64);
        const auto in = std::span<const Rayf>(rays).subspan(first, last - first);
        const auto out = std::span<std::uint8_t>(occ).subspan(first, last - first);
        if (width == 1) accel.occluded(in, out);
        else accel.occluded_packets(width, in, out);
    });
    return occ;
}

std::vector<int> packet_widths() {
    std::vector<int> w;
    if constexpr (kWidthCompiled<4>) w.push_back(4);
    if constexpr (kWidthCompiled<8>) w.push_back(8);
    if constexpr (kWidthCompiled<16>) w.push_back(16);
    return w;
}

/// Closest hit and occlusion of every ray against brute force, then packets
/// of every width against single rays (ties at shared edges aside).
void expect_agreement(const Scene& scene, const Accel& octree, const std::vector<Rayf>& rays, const std::string& what) {
    expect_oracle_agreement(scene, octree, rays, what);
}

// ---- Ray sets -----------------------------------------------------------------------

/// As camera_rays() (tests/oracle_harness.h), in another order: 4x4 pixel
/// tiles one after the other.
std::vector<Rayf> tiled_camera_rays(const Scene& scene, int size) {
    const CameraFrame f = make_camera_frame(scene.camera, size, size);
    std::vector<Rayf> rays;
    // 4x4 tiles, so that packets of 16 are square.
    for (int ty = 0; ty < size; ty += 4)
        for (int tx = 0; tx < size; tx += 4)
            for (int y = ty; y < std::min(size, ty + 4); ++y)
                for (int x = tx; x < std::min(size, tx + 4); ++x)
                    rays.push_back(camera_ray(f, float(x) + 0.5f, float(y) + 0.5f));
    return rays;
}

std::unique_ptr<OctreeAccel> make_octree(const Scene& scene, const OctreeConfig& oc = {}) {
    return std::make_unique<OctreeAccel>(scene, AccelConfig{}, oc);
}

/// The references in the leaves under node i, ascending, once each.
std::vector<std::uint32_t> subtree_refs(const Octree& t, std::uint32_t i) {
    std::vector<std::uint32_t> out;
    std::vector<std::uint32_t> pending = {i};
    while (!pending.empty()) {
        const OctreeNode& n = t.nodes[pending.back()];
        pending.pop_back();
        if (n.is_leaf()) out.insert(out.end(), t.refs.begin() + n.first, t.refs.begin() + n.first + n.count);
        else
            for (std::uint32_t c = 0; c < 8; ++c) pending.push_back(n.first + c);
    }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return out;
}

/// The groups' leaves are the highest inner nodes whose leaves hold at most
/// group_leaf_size primitives, and hold exactly those, ascending, with
/// boxes that hold them.
void expect_group_leaves(const Octree& t, const Scene& scene, const OctreeConfig& oc) {
    // (node, inside a group leaf already)
    std::vector<std::pair<std::uint32_t, bool>> pending = {{0, false}};
    std::size_t found = 0;
    while (!pending.empty()) {
        const auto [i, inside] = pending.back();
        pending.pop_back();
        const OctreeNode& node = t.nodes[i];
        const OctreeNode& whole = t.group_leaves[i];
        if (node.is_leaf()) {
            EXPECT_FALSE(whole.is_leaf()) << "a leaf of the tree is not also a group leaf";
            continue;
        }
        EXPECT_EQ(node.group_leaf(), whole.is_leaf()) << "node " << i << ": its flag";
        const std::vector<std::uint32_t> under = subtree_refs(t, i);
        const bool small = under.size() <= std::size_t(oc.group_leaf_size);
        EXPECT_EQ(whole.is_leaf(), small && !inside) << "node " << i << " over " << under.size() << " primitives";
        if (whole.is_leaf()) {
            ++found;
            ASSERT_LE(std::size_t(whole.first) + whole.count, t.group_refs.size());
            const std::vector<std::uint32_t> held(t.group_refs.begin() + whole.first,
                                                  t.group_refs.begin() + whole.first + whole.count);
            EXPECT_EQ(held, under) << "node " << i;
            for (std::uint32_t k = whole.first; k < whole.first + whole.count; ++k) {
                const Box3f want = primitive_bounds(scene, t.group_refs[k]);
                for (int a = 0; a < 3; ++a) {
                    EXPECT_LE(t.group_ref_boxes[k].lo[a], want.lo[a]);
                    EXPECT_GE(t.group_ref_boxes[k].hi[a], want.hi[a]);
                }
            }
        }
        for (std::uint32_t c = 0; c < 8; ++c) pending.push_back({node.first + c, inside || whole.is_leaf()});
    }
    std::size_t total = 0;
    for (const OctreeNode& g : t.group_leaves) total += g.is_leaf() ? g.count : 0;
    EXPECT_EQ(total, t.group_refs.size());
    if (oc.group_leaf_size == 0) {
        EXPECT_EQ(found, 0u);
    }
}

/// Structural invariants: leaves obey leaf_size unless at max depth or
/// unsplittable, references ascend within leaves and are in range, inner
/// nodes mark exactly their empty children, and the statistics count what
/// is there.
void expect_well_formed(const OctreeAccel& accel, const Scene& scene, const OctreeConfig& oc) {
    const Octree& t = accel.octree();
    if (t.empty()) return;
    const Vec3f e = t.cube.extent();
    EXPECT_EQ(e.x, e.y);
    EXPECT_EQ(e.y, e.z);
    std::size_t leaves = 0, empty = 0, refs = 0;
    int depth = 0;
    // Depth of each node by a walk from the root.
    std::vector<std::pair<std::uint32_t, int>> pending = {{0, 0}};
    std::vector<bool> seen(t.nodes.size(), false);
    while (!pending.empty()) {
        const auto [i, d] = pending.back();
        pending.pop_back();
        ASSERT_LT(i, t.nodes.size());
        ASSERT_FALSE(seen[i]);
        seen[i] = true;
        const OctreeNode& node = t.nodes[i];
        if (node.is_leaf()) {
            ++leaves;
            empty += node.count == 0;
            refs += node.count;
            depth = std::max(depth, d);
            EXPECT_LE(d, oc.max_depth);
            ASSERT_LE(std::size_t(node.first) + node.count, t.refs.size());
            for (std::uint32_t k = node.first; k < node.first + node.count; ++k) {
                EXPECT_LT(t.refs[k], scene.primitive_count());
                // The box the groups cull by holds the primitive.
                const Box3f want = primitive_bounds(scene, t.refs[k]);
                for (int a = 0; a < 3; ++a) {
                    EXPECT_LE(t.ref_boxes[k].lo[a], want.lo[a]);
                    EXPECT_GE(t.ref_boxes[k].hi[a], want.hi[a]);
                }
                if (k > node.first) {
                    EXPECT_LT(t.refs[k - 1], t.refs[k]);
                }
            }
        } else {
            EXPECT_LT(d, oc.max_depth);
            for (std::uint32_t c = 0; c < 8; ++c) {
                pending.push_back({node.first + c, d + 1});
                // The packet walk skips the children the node marks empty.
                ASSERT_LT(std::size_t(node.first) + c, t.nodes.size());
                const OctreeNode& kid = t.nodes[node.first + c];
                EXPECT_EQ((node.occupied() >> c) & 1u, kid.is_leaf() && kid.count == 0 ? 0u : 1u) << "child " << c;
            }
        }
    }
    EXPECT_EQ(std::count(seen.begin(), seen.end(), false), 0);
    EXPECT_EQ(refs, t.refs.size());
    const AccelStats& s = accel.stats();
    EXPECT_EQ(s.name, "octree");
    EXPECT_EQ(s.builder, "adaptive");
    EXPECT_EQ(s.nodes, t.nodes.size());
    EXPECT_EQ(s.leaves, leaves);
    EXPECT_EQ(s.depth, depth);
    EXPECT_EQ(accel.empty_leaves(), empty);
    // Nodes, references, the references' boxes (24 bytes), the groups'
    // leaves (a node each, their references and boxes), triangle records.
    EXPECT_EQ(t.ref_boxes.size(), t.refs.size());
    EXPECT_EQ(t.group_ref_boxes.size(), t.group_refs.size());
    EXPECT_EQ(t.group_leaves.size(), t.nodes.size());
    EXPECT_EQ(s.bytes, t.nodes.size() * 16 + (t.refs.size() + t.group_refs.size() + t.outside.size()) * 4 +
                           (t.refs.size() + t.group_refs.size()) * 24 + accel.triangle_edge_bytes());
    expect_group_leaves(t, scene, oc);
    EXPECT_GE(s.build_ms, 0.0);
    if (scene.primitive_count()) {
        EXPECT_GE(accel.references_per_primitive(), 1.0);
    }
}

// ---- Every shared scene -------------------------------------------------------------


// One fixture for the whole suite, so that every test is called Octree.*.
class Octree : public ::testing::TestWithParam<std::string> {};

TEST_P(Octree, MatchesBruteForce) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    AccelConfig config;
    config.kind = "octree";
    const std::unique_ptr<Accel> accel = build_accel(scene, config);
    const auto& octree = dynamic_cast<const OctreeAccel&>(*accel);
    std::mt19937 rng(20240605);
    const BruteForce brute(scene, KernelChoice{});

    const std::vector<Rayf> camera = tiled_camera_rays(scene, 64);
    expect_agreement(scene, octree, camera, GetParam() + " camera");
    expect_agreement(scene, octree, random_rays(scene, rng, 2000, kOriginGrowth), GetParam() + " random");
    expect_agreement(scene, octree, octree_adversarial_rays(octree.octree(), scene, rng), GetParam() + " adversarial");
    const std::vector<Rayf> shadows = shadow_rays(scene, camera, trace(brute, camera));
    const std::vector<std::uint8_t> want = trace_occluded(brute, shadows);
    std::size_t n = 0;
    std::string occ = occlusion_mismatches(shadows, want, trace_occluded(octree, shadows), n);
    EXPECT_EQ(n, 0u) << GetParam() << " shadow: " << n << " of " << shadows.size() << " occlusion answers differ" << occ;
    for (int w : packet_widths()) {
        occ = occlusion_mismatches(shadows, want, trace_occluded(octree, shadows, w), n);
        EXPECT_EQ(n, 0u) << GetParam() << " shadow K=" << w << ": " << n << " occlusion answers differ" << occ;
    }
    expect_well_formed(octree, scene, OctreeConfig{});
    RecordProperty("nodes", std::to_string(octree.stats().nodes));
    RecordProperty("refs_per_prim", std::to_string(octree.references_per_primitive()));
}

// Packets of one direction octant walk in groups (octree_packet.cpp,
// trace_group): the same answers, bit for bit, as every packet alone and as
// single rays (the tie rule makes them independent of the leaves' order),
// for camera rays, for rays from a point inside the scene in each octant and
// in mixed octants, and, for occlusion, for rays from the first light to the
// camera rays' hits, at every compiled width.
TEST_P(Octree, PacketGroupsGiveThePacketsAnswers) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    OctreeConfig alone_config;
    alone_config.packet_groups = false;
    const auto grouped = make_octree(scene), alone = make_octree(scene, alone_config);
    const BruteForce brute(scene, KernelChoice{});
    const std::vector<Rayf> camera = tiled_camera_rays(scene, 64);
    const std::vector<Rayf> rays = packet_group_rays(scene, camera, trace(brute, camera), 43);
    for (int width : packet_widths()) {
        const GroupDifferences d = group_differences(*grouped, *alone, rays, width);
        EXPECT_EQ(d.against_alone, 0u) << GetParam() << " width " << width << ": grouped against alone";
        EXPECT_EQ(d.against_single, 0u) << GetParam() << " width " << width << ": grouped against single rays";
    }
}

INSTANTIATE_TEST_SUITE_P(, Octree, ::testing::ValuesIn(shared_scene_files()), param_name);

// ---- Hand-made scenes -----------------------------------------------------------------

TEST_F(Octree, TheGroundStaysOutsideTheTree) {
    // SPD balls: the ground (its two triangles, 24 units across) is tested
    // by every ray, and the cube fits the sphereflake (under 2 units).
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/balls.nff");
    const auto octree = make_octree(scene);
    EXPECT_EQ(octree->octree().outside, (std::vector<std::uint32_t>{0, 1}));
    EXPECT_LT(octree->octree().cube.extent().x, 2.0f);
}

TEST_F(Octree, StateTableIsThePapers) {
    // new_node: from child c, leaving through axis k's plane, moves to c | bit
    // if that bit was clear, else out of the parent (8).
    for (int c = 0; c < 8; ++c) {
        for (int k = 0; k < 3; ++k) {
            const int bit = 4 >> k;
            EXPECT_EQ(revelles::kNext[c][k], (c & bit) ? 8 : (c | bit)) << c << " " << k;
        }
    }
    EXPECT_EQ(revelles::new_node(0, 1, 2, 3), 4);
    EXPECT_EQ(revelles::new_node(0, 2, 1, 3), 2);
    EXPECT_EQ(revelles::new_node(0, 3, 2, 1), 1);
    EXPECT_EQ(revelles::new_node(3, 1, 2, 3), 7);
    EXPECT_EQ(revelles::first_node(1, 1, 1, 0), 0);
    EXPECT_EQ(revelles::first_node(-1, 1, -1, 0), 5);
}

// Rays against brute force on these scenes: tests/test_cell_structures.cpp.
TEST_F(Octree, OnePrimitiveIsOneLeaf) {
    for (const Scene& scene : one_primitive_scenes()) EXPECT_EQ(make_octree(scene)->stats().nodes, 1u);
    EXPECT_EQ(make_octree(Scene{})->stats().nodes, 0u);
}

TEST_F(Octree, FlatScenesAreSplit) {
    std::mt19937 rng(11);
    for (int axis = 0; axis < 3; ++axis) {
        SCOPED_TRACE(axis);
        const Scene scene = flat_scene(axis, 24, rng);
        const auto octree = make_octree(scene);
        expect_well_formed(*octree, scene, OctreeConfig{});
        // The plane lies in the cube's midplane along `axis`: it is split
        // anyway, and both halves hold the whole plane only where it matters.
        EXPECT_GT(octree->stats().depth, 2);
    }
}

TEST_F(Octree, BigPrimitivesAreInManyLeaves) {
    std::mt19937 rng(13);
    const Scene scene = spanning_scene(rng);
    const auto octree = make_octree(scene);
    expect_well_formed(*octree, scene, OctreeConfig{});
    std::vector<std::size_t> leaves_of(scene.primitive_count(), 0);
    for (std::uint32_t p : octree->octree().refs) ++leaves_of[p];
    for (std::uint32_t p = 2000; p < 2004; ++p) EXPECT_GT(leaves_of[p], 20u) << p;
}

TEST_F(Octree, UnsplittableNodesStayLeaves) {
    // 40 triangles meeting at the centre of the cube (the scene is point
    // symmetric): every octant touches the centre, so gets all of them.
    const Scene scene = scene_with([](Scene& s) {
        for (int i = 0; i < 20; ++i) {
            const float a = float(i) * 0.314f, b = a + 0.1f;
            const Vec3f p{std::cos(a), std::sin(a), 0.3f * float(i % 3) - 0.3f};
            const Vec3f q{std::cos(b), std::sin(b), 0.5f - 0.05f * float(i % 5)};
            s.add_triangle({0, 0, 0}, p, q, 0);
            s.add_triangle({0, 0, 0}, Vec3f{0, 0, 0} - p, Vec3f{0, 0, 0} - q, 0);
        }
    });
    OctreeConfig oc;
    oc.leaf_size = 2;
    const auto octree = make_octree(scene, oc);
    expect_well_formed(*octree, scene, oc);
    EXPECT_EQ(octree->stats().nodes, 1u);
    std::mt19937 rng(5);
    expect_agreement(scene, *octree, random_rays(scene, rng, 1000, kOriginGrowth), "fan");
}

TEST_F(Octree, ConfigurationsAgree) {
    // Leaf size, depth and placement change the tree, never the answers.
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/tetra.nff");
    std::mt19937 rng(3);
    const std::vector<Rayf> rays = random_rays(scene, rng, 2000, kOriginGrowth);
    for (int leaf : {1, 4, 32}) {
        for (int depth : {0, 3, 16}) {
            for (bool exact : {true, false}) {
                OctreeConfig oc;
                oc.leaf_size = leaf;
                oc.max_depth = depth;
                oc.exact_overlap = exact;
                const auto octree = make_octree(scene, oc);
                expect_well_formed(*octree, scene, oc);
                expect_agreement(scene, *octree, rays,
                                 "leaf " + std::to_string(leaf) + " depth " + std::to_string(depth) +
                                     (exact ? " exact" : " boxes"));
            }
        }
    }
}

TEST_F(Octree, BuildIsDeterministic) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/tetra.nff");
    const auto a = make_octree(scene), b = make_octree(scene);
    ASSERT_EQ(a->octree().nodes.size(), b->octree().nodes.size());
    for (std::size_t i = 0; i < a->octree().nodes.size(); ++i) {
        EXPECT_EQ(a->octree().nodes[i].first, b->octree().nodes[i].first);
        EXPECT_EQ(a->octree().nodes[i].count, b->octree().nodes[i].count);
    }
    EXPECT_EQ(a->octree().refs, b->octree().refs);
}

TEST_F(Octree, LeavesHoldTheTrianglesThatMeetThem) {
    // Every triangle meeting a leaf's box (shrunk by a hair) is in that leaf;
    // every reference meets the leaf's box widened by the margin.
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/teapot.nff");
    const auto octree = make_octree(scene);
    const raypack::Octree& t = octree->octree();
    ASSERT_TRUE(scene.features.triangles && !scene.features.spheres && !scene.features.cones);
    auto tri = [&](std::uint32_t p, const Vec3d& lo, const Vec3d& hi) {
        const std::uint32_t i = scene.prims[p].index;
        return triangle_box_overlap((lo + hi) * 0.5, (hi - lo) * 0.5, Vec3d(scene.triangles.p0[i]),
                                    Vec3d(scene.triangles.p1[i]), Vec3d(scene.triangles.p2[i]));
    };
    std::size_t checked = 0;
    std::function<void(std::uint32_t, Vec3d, Vec3d)> visit = [&](std::uint32_t n, Vec3d lo, Vec3d hi) {
        const OctreeNode& node = t.nodes[n];
        if (!node.is_leaf()) {
            const Vec3d mid = (lo + hi) * 0.5;
            for (int c = 0; c < 8; ++c) {
                Vec3d clo, chi;
                for (int a = 0; a < 3; ++a) {
                    const bool upper = (c >> (2 - a)) & 1;
                    clo[a] = upper ? mid[a] : lo[a];
                    chi[a] = upper ? hi[a] : mid[a];
                }
                visit(node.first + c, clo, chi);
            }
            return;
        }
        const auto first = t.refs.begin() + node.first, last = first + node.count;
        const Vec3d m{t.margin, t.margin, t.margin}, hair = (hi - lo) * 1e-6;
        if (checked < 4000) {  // the full check on the first leaves
            for (std::uint32_t p = 0; p < scene.primitive_count(); ++p) {
                if (tri(p, lo + hair, hi - hair)) {
                    EXPECT_TRUE(std::binary_search(first, last, p)) << p << " leaf " << n;
                }
            }
        }
        for (auto it = first; it != last; ++it) EXPECT_TRUE(tri(*it, lo - m, hi + m)) << *it << " leaf " << n;
        ++checked;
    };
    visit(0, Vec3d(t.cube.lo), Vec3d(t.cube.hi));
    EXPECT_GT(checked, 100u);
}

TEST_F(Octree, CountingModeAgreesAndCounts) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/teapot.nff");
    const auto octree = make_octree(scene);
    const std::vector<Rayf> rays = tiled_camera_rays(scene, 32);
    OctreeRayCounters c;
    for (const Rayf& r : rays) {
        const Hitf want = octree->intersect1(r);
        const Hitf got = octree->intersect_counting(r, c);
        EXPECT_EQ(want.prim, got.prim);
        EXPECT_EQ(want.t, got.t);
        EXPECT_EQ(octree->occluded1(r), octree->occluded_counting(r, c));
    }
    EXPECT_EQ(c.rays, 2 * rays.size());
    EXPECT_GT(c.nodes_visited, c.rays);
    EXPECT_GT(c.leaves_visited, 0u);
    EXPECT_GT(c.prim_tests, 0u);

    // Two tiny spheres in opposite corners: a ray along the cube's x axis
    // through the centre row of depth-1 nodes visits the root and the two
    // children it crosses (both empty leaves or inner nodes it walks).
    const Scene corners = scene_with([](Scene& s) {
        s.add_sphere({0, 0, 0}, 0.01f, 0);
        s.add_sphere({1, 1, 1}, 0.01f, 0);
    });
    OctreeConfig oc;
    oc.leaf_size = 0;
    const auto sparse = make_octree(corners, oc);
    const Box3f cube = sparse->octree().cube;
    Rayf r;
    r.org = {cube.lo.x - 1, cube.lo.y + 0.3f * (cube.hi.y - cube.lo.y), cube.lo.z + 0.7f * (cube.hi.z - cube.lo.z)};
    r.dir = {1, 0, 0};
    OctreeRayCounters row;
    EXPECT_FALSE(sparse->intersect_counting(r, row).found());
    EXPECT_EQ(row.prim_tests, 0u);
    EXPECT_EQ(row.nodes_visited, 3u);  // root, then children (lower y, upper z): lower x, upper x
    EXPECT_EQ(row.empty_leaves_visited, 2u);  // neither holds a sphere
    TraversalCounts havran;
    row.add_to(havran);
    EXPECT_EQ(havran.nodes, 3u);  // N_TS
    EXPECT_EQ(havran.leaves, 2u);  // N_ETS
    EXPECT_EQ(havran.empty_leaves, 2u);  // N_EETS
    EXPECT_EQ(havran.prims, 0u);  // N_IT
    // A ray that misses the cube visits nothing.
    r.org = {-1, 5, 5};
    OctreeRayCounters none;
    EXPECT_FALSE(sparse->intersect_counting(r, none).found());
    EXPECT_EQ(none.nodes_visited, 0u);
    EXPECT_EQ(none.rays, 1u);
}

TEST_F(Octree, MixedSignPacketsMatchSingleRays) {
    // Rays in every octant mixed within packets, from one point inside the
    // scene: every packet splits into several octant groups.
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/tetra.nff");
    const auto octree = make_octree(scene);
    std::mt19937 rng(29);
    std::vector<Rayf> rays;
    const Vec3f c = scene_bounds(scene).center();
    for (int i = 0; i < 4000; ++i) {
        Rayf r;
        r.org = c;
        r.dir = random_direction(rng);
        if (i % 5 == 0) r.dir[i % 3] = signed_zero(rng);
        rays.push_back(r);
    }
    expect_agreement(scene, *octree, rays, "mixed signs");
}

}  // namespace
}  // namespace raypack::octree_test
