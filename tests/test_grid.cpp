// The uniform grid (accel/grid/) against the brute-force oracle, and its
// parts against brute-force references: the triangle-box overlap test
// against clipping, the placement of primitives against clipping per cell,
// the 3D-DDA against slab tests of every cell, the resolution heuristic.
// The grid runs the very same primitive kernels as the oracle, so it must
// agree exactly: the same hit or miss on every ray, bit-identical t for the
// same primitive, another primitive only at a shared edge or vertex, and the
// same occlusion answers.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <filesystem>
#include <functional>
#include <iomanip>
#include <limits>
#include <optional>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "tests/oracle_harness.h"
#include "tests/cell_test_cases.h"
#include "tests/grid_test_rays.h"
#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "accel/grid/coherent_grid.h"
#include "accel/grid/coherent_grid_group.h"
#include "accel/grid/dda.h"
#include "accel/grid/dda_packet.h"
#include "accel/grid/grid_accel.h"
#include "accel/grid/grid_build.h"
#include "accel/outside_prims.h"
#include "accel/grid/grid_packet.h"
#include "accel/grid/triangle_box_overlap.h"
#include "render/camera_rays.h"
#include "scene/load.h"

namespace raypack::grid_test {

using namespace raypack::oracle_harness;
using namespace raypack::grid_test_rays;
using namespace raypack::cell_test_cases;
namespace {

std::unique_ptr<GridAccel> make_grid(const Scene& scene, const GridConfig& gc = {}) {
    return std::make_unique<GridAccel>(scene, AccelConfig{}, gc);
}

// ---- Every shared scene -------------------------------------------------------------


// One fixture for the whole suite, so that every test is called Grid.*.
class Grid : public ::testing::TestWithParam<std::string> {};

TEST_P(Grid, MatchesBruteForce) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    AccelConfig config;
    config.kind = "grid";
    const std::unique_ptr<Accel> accel = build_accel(scene, config);
    const auto& grid = dynamic_cast<const GridAccel&>(*accel);
    std::mt19937 rng(20240605);
    const BruteForce brute(scene, KernelChoice{});

    const std::vector<Rayf> camera = camera_rays(scene, 64);
    expect_agreement(scene, grid, camera, GetParam() + " camera");
    expect_agreement(scene, grid, random_rays(scene, rng, 2000, kOriginGrowth), GetParam() + " random");
    expect_agreement(scene, grid, grid_adversarial_rays(grid.grid().geometry, scene, rng), GetParam() + " adversarial");
    const std::vector<Rayf> shadows = shadow_rays(scene, camera, trace(brute, camera));
    std::size_t n = 0;
    const std::string occ = occlusion_mismatches(shadows, trace_occluded(brute, shadows), trace_occluded(grid, shadows), n);
    EXPECT_EQ(n, 0u) << GetParam() << " shadow: " << n << " of " << shadows.size() << " occlusion answers differ" << occ;

    // The statistics describe what was built.
    const AccelStats& s = grid.stats();
    EXPECT_EQ(s.name, "grid");
    EXPECT_EQ(s.builder, "uniform");
    EXPECT_EQ(s.nodes, grid.cell_count());
    std::size_t nonempty = 0;
    for (std::size_t c = 0; c < grid.cell_count(); ++c)
        nonempty += grid.grid().cell_begin[c + 1] > grid.grid().cell_begin[c];
    EXPECT_EQ(s.leaves, nonempty);
    EXPECT_DOUBLE_EQ(grid.empty_cell_fraction(), 1.0 - double(nonempty) / double(grid.cell_count()));
    EXPECT_EQ(s.bytes, (grid.cell_count() + 1 + grid.reference_count() + grid.grid().outside.size()) *
                               sizeof(std::uint32_t) +
                           grid.grid().macro.full.size() + grid.triangle_edge_bytes());
    EXPECT_GE(grid.references_per_primitive(), 1.0);
    const double cells_per_prim = double(grid.cell_count()) / double(scene.primitive_count());
    const double lambda = GridConfig{}.lambda;
    EXPECT_GT(cells_per_prim, lambda / 3.0);
    EXPECT_LT(cells_per_prim, lambda * 3.0);
    RecordProperty("cells", std::to_string(grid.cell_count()));
    RecordProperty("refs_per_prim", std::to_string(grid.references_per_primitive()));
}

INSTANTIATE_TEST_SUITE_P(, Grid, ::testing::ValuesIn(shared_scene_files()), param_name);

// ---- Hand-made scenes -----------------------------------------------------------------

// Rays against brute force on these scenes: tests/test_cell_structures.cpp.
TEST_F(Grid, OnePrimitiveGivesAtLeastOneCell) {
    for (const Scene& scene : one_primitive_scenes()) {
        const auto grid = make_grid(scene);
        EXPECT_GE(grid->cell_count(), 1u);
        for (int r : grid->resolution()) EXPECT_GE(r, 1);
    }
    EXPECT_EQ(make_grid(Scene{})->cell_count(), 0u);
}

TEST_F(Grid, FlatScenesGetOneLayerOfCells) {
    std::mt19937 rng(11);
    for (int axis = 0; axis < 3; ++axis) {
        SCOPED_TRACE(axis);
        const Scene scene = flat_scene(axis, 24, rng);
        const auto grid = make_grid(scene);
        // One layer of cells across the plane, about lambda * N over its area.
        EXPECT_EQ(grid->resolution()[axis], 1);
        const GridGeometry& g = grid->grid().geometry;
        EXPECT_GT(g.bounds.hi[axis] - g.bounds.lo[axis], 0.1f * g.cell_size[(axis + 1) % 3]);
        const double per_prim = double(grid->cell_count()) / double(scene.primitive_count());
        EXPECT_GT(per_prim, 0.5 * GridConfig{}.lambda);
        EXPECT_LT(per_prim, 2.0 * GridConfig{}.lambda);
    }
}

TEST_F(Grid, BigPrimitivesAreInManyCells) {
    std::mt19937 rng(13);
    const Scene scene = spanning_scene(rng);
    const auto grid = make_grid(scene);
    std::vector<std::size_t> cells_of(scene.primitive_count(), 0);
    for (std::uint32_t p : grid->grid().refs) ++cells_of[p];
    for (std::uint32_t p = 2000; p < 2004; ++p) EXPECT_GT(cells_of[p], 50u) << p;
}

TEST_F(Grid, ReferenceCapCoarsensTheGrid) {
    // Big overlapping spheres: every sphere is in most cells.
    std::mt19937 rng(17);
    std::uniform_real_distribution<float> u(0, 1);
    const Scene scene = scene_with([&](Scene& s) {
        for (int i = 0; i < 300; ++i) s.add_sphere({u(rng), u(rng), u(rng)}, 0.8f, 0);
    });
    GridConfig gc;
    gc.max_references = 20000;
    const auto grid = make_grid(scene, gc);
    EXPECT_LE(grid->reference_count(), gc.max_references);
    EXPECT_LT(grid->lambda(), gc.lambda);
    expect_agreement(scene, *grid, random_rays(scene, rng, 1000, kOriginGrowth), "capped");
    // An absurd density is held at max_cells.
    gc = {};
    gc.lambda = 1e9f;
    gc.max_cells = 5000;
    const auto dense = make_grid(scene, gc);
    EXPECT_LE(dense->cell_count(), 5000u);
    EXPECT_GT(dense->cell_count(), 2500u);
}

TEST_F(Grid, BuildIsDeterministic) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/tetra.nff");
    const auto a = make_grid(scene), b = make_grid(scene);
    EXPECT_EQ(a->grid().cell_begin, b->grid().cell_begin);
    EXPECT_EQ(a->grid().refs, b->grid().refs);
}

TEST_F(Grid, CountingModeAgreesAndCounts) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/teapot.nff");
    const auto grid = make_grid(scene);
    const std::vector<Rayf> rays = camera_rays(scene, 32);
    GridRayCounters c;
    for (const Rayf& r : rays) {
        const Hitf want = grid->intersect1(r);
        const Hitf got = grid->intersect_counting(r, c);
        EXPECT_EQ(want.prim, got.prim);
        EXPECT_EQ(want.t, got.t);
        EXPECT_EQ(grid->occluded1(r), grid->occluded_counting(r, c));
    }
    EXPECT_EQ(c.rays, 2 * rays.size());
    EXPECT_GT(c.cells_visited, c.rays);
    EXPECT_GT(c.prim_tests, 0u);

    // A ray straight through an empty row of cells visits exactly res.x of them.
    const Scene corners = scene_with([](Scene& s) {
        s.add_sphere({0, 0, 0}, 0.01f, 0);
        s.add_sphere({1, 1, 1}, 0.01f, 0);
    });
    GridConfig gc;
    gc.lambda = 1000;
    const auto sparse = make_grid(corners, gc);
    const GridGeometry& g = sparse->grid().geometry;
    ASSERT_GT(g.res[0], 5);
    Rayf r;
    r.org = {-1, 0.5f * (g.plane(1, 2) + g.plane(1, 3)), 0.5f * (g.plane(2, 2) + g.plane(2, 3))};
    r.dir = {1, 0, 0};
    GridRayCounters row;
    EXPECT_FALSE(sparse->intersect_counting(r, row).found());
    EXPECT_EQ(row.cells_visited, std::uint64_t(g.res[0]));
    EXPECT_EQ(row.empty_cells_visited, std::uint64_t(g.res[0]));
    EXPECT_EQ(row.prim_tests, 0u);
    // The teapot's rays crossed empty cells and others.
    EXPECT_GT(c.empty_cells_visited, 0u);
    EXPECT_LT(c.empty_cells_visited, c.cells_visited);
    // A ray that misses the grid visits none.
    r.org = {-1, 5, 5};
    GridRayCounters none;
    EXPECT_FALSE(sparse->intersect_counting(r, none).found());
    EXPECT_EQ(none.cells_visited, 0u);
}

// ---- The 3D-DDA against slab tests of every cell ---------------------------------------

/// Double-precision slab test of a ray against a box: the parametric
/// interval, empty when lo > hi.
std::pair<double, double> slab_interval(const Rayf& r, const Vec3d& lo, const Vec3d& hi) {
    double t0 = r.tnear, t1 = r.tfar;
    for (int a = 0; a < 3; ++a) {
        const double o = r.org[a], d = r.dir[a];
        if (d == 0) {
            if (o < lo[a] || o > hi[a]) return {1, 0};
            continue;
        }
        double n = (lo[a] - o) / d, f = (hi[a] - o) / d;
        if (n > f) std::swap(n, f);
        t0 = std::max(t0, n);
        t1 = std::min(t1, f);
    }
    return {t0, t1};
}

TEST_F(Grid, DdaVisitsEveryCellTheRayCrossesInOrder) {
    GridGeometry g;
    g.res = {7, 5, 9};
    g.bounds.lo = {-1.5f, 0.25f, 2.0f};
    g.bounds.hi = {2.0f, 3.0f, 6.5f};
    for (int a = 0; a < 3; ++a) {
        g.cell_size[a] = (g.bounds.hi[a] - g.bounds.lo[a]) / float(g.res[a]);
        g.inv_cell_size[a] = float(g.res[a]) / (g.bounds.hi[a] - g.bounds.lo[a]);
    }
    std::mt19937 rng(19);
    std::vector<Rayf> rays = grid_adversarial_rays(g, scene_with([](Scene& s) { s.add_sphere({0, 1, 3}, 0.1f, 0); }), rng);
    for (int i = 0; i < 2000; ++i) {
        Rayf r;
        r.org = random_point(rng, grown(g.bounds, 0.3f));
        r.dir = random_direction(rng);
        rays.push_back(r);
    }
    std::size_t checked = 0;
    for (const Rayf& r : rays) {
        float entry;
        if (!intersect_aabb(r.org, reciprocal(r.dir), g.bounds, r.tnear, r.tfar, entry)) continue;
        std::vector<std::uint32_t> walk;
        std::vector<DdaSegment> segs;
        GridDda dda(g, r.org, r.dir, reciprocal(r.dir), entry);
        while (const auto s = dda.next()) {
            segs.push_back(*s);
            walk.push_back(s->cell);
            ASSERT_LT(walk.size(), 100u) << describe(r);
        }
        ASSERT_FALSE(segs.empty()) << describe(r);
        // Consecutive segments join up, and t does not run backwards (up to rounding).
        for (std::size_t k = 1; k < segs.size(); ++k) {
            EXPECT_EQ(segs[k].t_enter, segs[k - 1].t_exit) << describe(r);
            EXPECT_GE(segs[k].t_exit, segs[k].t_enter - 1e-5f * std::fabs(segs[k].t_enter)) << describe(r);
        }
        // Every cell the ray crosses by more than rounding is walked, and
        // every walked cell is within rounding of the ray.
        const double eps = 1e-3 * double(g.cell_size.x);
        Rayf unbounded = r;
        unbounded.tfar = std::numeric_limits<float>::infinity();  // the walk goes on past tfar
        for (int z = 0; z < g.res[2]; ++z) {
            for (int y = 0; y < g.res[1]; ++y) {
                for (int x = 0; x < g.res[0]; ++x) {
                    const Vec3d lo{g.plane(0, x), g.plane(1, y), g.plane(2, z)};
                    const Vec3d hi{g.plane(0, x + 1), g.plane(1, y + 1), g.plane(2, z + 1)};
                    const Vec3d e{eps, eps, eps};
                    const auto inner = slab_interval(r, lo + e, hi - e);
                    const auto outer = slab_interval(unbounded, lo - e, hi + e);
                    const bool walked = std::find(walk.begin(), walk.end(), g.cell_index(x, y, z)) != walk.end();
                    if (inner.first < inner.second) {
                        EXPECT_TRUE(walked) << x << " " << y << " " << z << " " << describe(r);
                    }
                    if (walked) {
                        EXPECT_LE(outer.first, outer.second) << x << " " << y << " " << z << " " << describe(r);
                    }
                }
            }
        }
        ++checked;
    }
    EXPECT_GT(checked, 2000u);
}

// ---- Resolution heuristic -----------------------------------------------------------------

TEST_F(Grid, ResolutionFollowsDensityAndShape) {
    auto total = [](const std::array<int, 3>& r) { return std::size_t(r[0]) * r[1] * r[2]; };
    // A cube: about lambda * N cubic cells.
    std::array<int, 3> r = grid_resolution({2, 2, 2}, 1000, 4, 1 << 26);
    EXPECT_EQ(r[0], r[1]);
    EXPECT_EQ(r[1], r[2]);
    EXPECT_NEAR(double(total(r)), 4000.0, 4000.0 * 0.2);
    // A box 4:2:1: cells near-cubic, so resolution in the same ratio.
    r = grid_resolution({4, 2, 1}, 1000, 4, 1 << 26);
    EXPECT_NEAR(double(r[0]) / r[2], 4.0, 0.6);
    EXPECT_NEAR(double(r[1]) / r[2], 2.0, 0.4);
    // Flat: one layer, lambda * N cells over the area.
    r = grid_resolution({3, 3, 0}, 1000, 4, 1 << 26);
    EXPECT_EQ(r[2], 1);
    EXPECT_NEAR(double(total(r)), 4000.0, 4000.0 * 0.2);
    // Nearly flat: the thin axis has one cell, the others still share the density.
    r = grid_resolution({3, 1e-4f, 3}, 1000, 4, 1 << 26);
    EXPECT_EQ(r[1], 1);
    EXPECT_NEAR(double(total(r)), 4000.0, 4000.0 * 0.2);
    // A line, a point, nothing.
    r = grid_resolution({0, 0, 5}, 100, 4, 1 << 26);
    EXPECT_EQ(r, (std::array<int, 3>{1, 1, 400}));
    EXPECT_EQ(grid_resolution({0, 0, 0}, 100, 4, 1 << 26), (std::array<int, 3>{1, 1, 1}));
    EXPECT_EQ(grid_resolution({1, 1, 1}, 0, 4, 1 << 26), (std::array<int, 3>{1, 1, 1}));
    // Absurd inputs stay within the cap and give every axis a cell.
    for (const Vec3f& e : {Vec3f{1e30f, 1, 1e-30f}, Vec3f{1e-30f, 1e-30f, 1e-30f}, Vec3f{1e20f, 1e20f, 1e20f},
                           Vec3f{1, 1e6f, 1}}) {
        for (std::size_t n : {std::size_t(1), std::size_t(1000), std::size_t(1) << 40}) {
            r = grid_resolution(e, n, 4, 1 << 20);
            EXPECT_LE(total(r), std::size_t(1) << 20);
            for (int k : r) EXPECT_GE(k, 1);
        }
    }
    r = grid_resolution({1, 1, 1}, std::size_t(1) << 40, 1e30f, 1000);
    EXPECT_LE(total(r), 1000u);
    EXPECT_GE(total(r), 500u);
}

// ---- Triangle-box overlap against clipping ----------------------------------------------

/// Reference: clip the triangle against the six planes of the box
/// (Sutherland-Hodgman) in long double; it overlaps iff something is left.
bool clip_overlap(const Vec3d& lo, const Vec3d& hi, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    using P = std::array<long double, 3>;
    std::vector<P> poly = {{a.x, a.y, a.z}, {b.x, b.y, b.z}, {c.x, c.y, c.z}};
    for (int axis = 0; axis < 3; ++axis) {
        for (int side = 0; side < 2; ++side) {
            const long double bound = side ? hi[axis] : lo[axis];
            auto inside = [&](const P& p) { return side ? p[axis] <= bound : p[axis] >= bound; };
            std::vector<P> out;
            for (std::size_t i = 0; i < poly.size(); ++i) {
                const P& p = poly[i];
                const P& q = poly[(i + 1) % poly.size()];
                if (inside(p)) out.push_back(p);
                if (inside(p) != inside(q)) {
                    const long double t = (bound - p[axis]) / (q[axis] - p[axis]);
                    P m;
                    for (int k = 0; k < 3; ++k) m[k] = p[k] + (q[k] - p[k]) * t;
                    m[axis] = bound;
                    out.push_back(m);
                }
            }
            poly = std::move(out);
            if (poly.empty()) return false;
        }
    }
    return true;
}

bool sat(const Vec3d& lo, const Vec3d& hi, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    return triangle_box_overlap((lo + hi) * 0.5, (hi - lo) * 0.5, a, b, c);
}

TEST_F(Grid, TriangleBoxOverlapMatchesClipping) {
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(-1, 1);
    int decided_in = 0, decided_out = 0, bbox_only_wrong = 0;
    for (int i = 0; i < 40000; ++i) {
        const Vec3d center{u(rng) * 0.3, u(rng) * 0.3, u(rng) * 0.3};
        const Vec3d half{0.05 + 0.3 * std::fabs(u(rng)), 0.05 + 0.3 * std::fabs(u(rng)), 0.05 + 0.3 * std::fabs(u(rng))};
        const double scale = i % 2 ? 0.2 : 1.0;  // small triangles near the box, and large ones
        const Vec3d a = Vec3d{u(rng), u(rng), u(rng)} * 0.6;
        const Vec3d b = a + Vec3d{u(rng), u(rng), u(rng)} * scale, c = a + Vec3d{u(rng), u(rng), u(rng)} * scale;
        const Vec3d lo = center - half, hi = center + half;
        const bool got = sat(lo, hi, a, b, c);
        const Vec3d d{1e-9, 1e-9, 1e-9};
        if (clip_overlap(lo + d, hi - d, a, b, c)) {
            ++decided_in;
            EXPECT_TRUE(got) << i;
        } else if (!clip_overlap(lo - d, hi + d, a, b, c)) {
            ++decided_out;
            EXPECT_FALSE(got) << i;
            Box3<double> tb;
            tb.extend(a), tb.extend(b), tb.extend(c);
            const bool boxes_meet = !(tb.lo.x > hi.x || tb.hi.x < lo.x || tb.lo.y > hi.y || tb.hi.y < lo.y ||
                                      tb.lo.z > hi.z || tb.hi.z < lo.z);
            bbox_only_wrong += boxes_meet;
        }
        // Sampled points of the triangle inside the box imply overlap.
        for (int k = 0; k < 8; ++k) {
            double s = std::fabs(u(rng)), t = std::fabs(u(rng));
            if (s + t > 1) s = 1 - s, t = 1 - t;
            const Vec3d p = a + (b - a) * s + (c - a) * t;
            if (p.x >= lo.x && p.x <= hi.x && p.y >= lo.y && p.y <= hi.y && p.z >= lo.z && p.z <= hi.z) {
                EXPECT_TRUE(got) << i;
            }
        }
    }
    EXPECT_GT(decided_in, 5000);
    EXPECT_GT(decided_out, 5000);
    EXPECT_GT(bbox_only_wrong, 1000) << "cases where the bounding boxes meet but the triangle does not";
}

TEST_F(Grid, TriangleBoxOverlapTouchingCases) {
    const Vec3d lo{0, 0, 0}, hi{1, 1, 1};
    const double e = 1e-9;
    struct Case {
        const char* what;
        Vec3d a, b, c;
        bool overlap;
    };
    const Case cases[] = {
        // Along a box edge, otherwise outside; then moved off it.
        {"edge on box edge", {0, 0, 0}, {1, 0, 0}, {0.5, -1, -1}, true},
        {"edge off box edge", {0, -e, -e}, {1, -e, -e}, {0.5, -1, -1}, false},
        // A vertex on a box corner, the rest outside.
        {"vertex on corner", {1, 1, 1}, {2, 1.5, 1}, {1.5, 2, 3}, true},
        {"vertex off corner", {1 + e, 1 + e, 1 + e}, {2, 1.5, 1 + e}, {1.5, 2, 3}, false},
        // A triangle edge crossing a box edge at one point.
        {"edge crosses box edge", {2, 0, 0.5}, {0, 2, 0.5}, {2, 2, 0.5}, true},
        {"edge misses box edge", {2 + e, 0, 0.5}, {0, 2 + e, 0.5}, {2, 2, 0.5}, false},
        // The plane through one box corner, the corner inside the triangle.
        {"plane on corner", {3, 0, 0}, {0, 3, 0}, {0, 0, 3}, true},
        {"plane past corner", {3 + 1e-6, 0, 0}, {0, 3 + 1e-6, 0}, {0, 0, 3 + 1e-6}, false},
        // In a face's plane, overlapping the face, and next to it.
        {"in face plane", {0.2, 0.2, 1}, {2, 0.5, 1}, {0.5, 2, 1}, true},
        {"above face plane", {0.2, 0.2, 1 + e}, {2, 0.5, 1 + e}, {0.5, 2, 1 + e}, false},
        // Bounding boxes meet, triangles do not (the edge axes separate).
        {"edge axis separates", {1.5, 0.9, 0.5}, {0.9, 1.5, 0.5}, {1.5, 1.5, 0.5}, false},
        {"plane separates", {2, 0, 0}, {0, 2, 0}, {0, 0, 2}, false},  // against the half box below
        // Through the middle with every vertex outside.
        {"big through middle", {-5, -5, 0.5}, {5, -5, 0.5}, {0, 5, 0.6}, true},
        // Degenerate: a segment through the box, a segment beside it, a point inside.
        {"segment through", {-1, 0.5, 0.5}, {2, 0.5, 0.5}, {0.5, 0.5, 0.5}, true},
        {"segment beside", {1.5, 0.9, 0.5}, {0.9, 1.5, 0.5}, {1.2, 1.2, 0.5}, false},
        {"point inside", {0.5, 0.5, 0.5}, {0.5, 0.5, 0.5}, {0.5, 0.5, 0.5}, true},
    };
    for (const Case& k : cases) {
        const Vec3d h = std::string(k.what) == "plane separates" ? Vec3d{0.5, 0.5, 0.5} : hi;
        EXPECT_EQ(sat(lo, h, k.a, k.b, k.c), k.overlap) << k.what;
        if (k.a == k.b) continue;  // clipping needs a proper polygon
        if (std::string(k.what).find("plane") == std::string::npos || k.overlap) {
            EXPECT_EQ(clip_overlap(lo, h, k.a, k.b, k.c), k.overlap) << "reference: " << k.what;
        }
    }
}

// ---- Placement: exactly the cells a triangle meets ------------------------------------------

TEST_F(Grid, TrianglesAreInExactlyTheCellsTheyMeet) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/teapot.nff");
    const auto grid = make_grid(scene);
    const raypack::Grid& gr = grid->grid();
    const GridGeometry& g = gr.geometry;
    const double margin = grid_placement_margin(scene_bounds(scene));
    std::size_t checked_in = 0, checked_out = 0, margin_only = 0;
    ASSERT_TRUE(scene.features.triangles && !scene.features.spheres && !scene.features.cones);
    for (std::uint32_t p = 0; p < scene.primitive_count(); ++p) {
        const std::uint32_t i = scene.prims[p].index;
        const Vec3d a(scene.triangles.p0[i]), b(scene.triangles.p1[i]), c(scene.triangles.p2[i]);
        const Box3f box = primitive_bounds(scene, p);
        int i0[3], i1[3];
        for (int k = 0; k < 3; ++k) {
            i0[k] = std::max(0, int(std::floor((box.lo[k] - g.bounds.lo[k]) * g.inv_cell_size[k])) - 1);
            i1[k] = std::min(g.res[k] - 1, int(std::floor((box.hi[k] - g.bounds.lo[k]) * g.inv_cell_size[k])) + 1);
        }
        for (int z = i0[2]; z <= i1[2]; ++z) {
            for (int y = i0[1]; y <= i1[1]; ++y) {
                for (int x = i0[0]; x <= i1[0]; ++x) {
                    const std::uint32_t cell = g.cell_index(x, y, z);
                    const auto first = gr.refs.begin() + gr.cell_begin[cell], last = gr.refs.begin() + gr.cell_begin[cell + 1];
                    const bool present = std::binary_search(first, last, p);
                    const Vec3d lo{g.plane(0, x), g.plane(1, y), g.plane(2, z)};
                    const Vec3d hi{g.plane(0, x + 1), g.plane(1, y + 1), g.plane(2, z + 1)};
                    const Vec3d m{2 * margin, 2 * margin, 2 * margin};
                    if (clip_overlap(lo, hi, a, b, c)) {
                        ++checked_in;
                        EXPECT_TRUE(present) << "triangle " << p << " cell " << x << " " << y << " " << z;
                    } else if (!clip_overlap(lo - m, hi + m, a, b, c)) {
                        ++checked_out;
                        EXPECT_FALSE(present) << "triangle " << p << " cell " << x << " " << y << " " << z;
                    } else {
                        margin_only += present;  // within the margin: either way is right
                    }
                }
            }
        }
    }
    // Every reference is a real overlap or within the margin. Those within
    // the margin alone are mostly vertices on the teapot's plane of symmetry,
    // which is also a cell plane up to the rounding of its float position.
    EXPECT_EQ(checked_in + margin_only, grid->reference_count());
    EXPECT_LT(double(margin_only), 0.1 * double(grid->reference_count()));
    EXPECT_GT(checked_out, 1000u);
    // Exact placement stores fewer references than bounding boxes would.
    GridConfig boxes_only;
    boxes_only.exact_overlap = false;
    EXPECT_LT(grid->reference_count(), make_grid(scene, boxes_only)->reference_count());
}

// ---- Packets: every lane stepping its own DDA ------------------------------------------------

/// The packet DDA of width K against K single-ray DDAs, in lockstep.
template <int K>
void expect_packet_walks_equal(const GridGeometry& g, const std::vector<Rayf>& rays) {
    using F = vfloat<K>;
    for (std::size_t first = 0; first + K <= rays.size(); first += K) {
        vmask<K> valid;
        const RayPacket<K> packet = load_packet<K>(std::span<const Rayf>(rays).subspan(first, K), valid);
        alignas(64) float start[K];
        std::vector<GridDda> single;
        std::uint32_t walking = 0;
        for (int l = 0; l < K; ++l) {
            const Rayf& r = rays[first + l];
            float entry = 0;
            if (intersect_aabb(r.org, reciprocal(r.dir), g.bounds, r.tnear, r.tfar, entry)) walking |= 1u << l;
            start[l] = entry;
            single.emplace_back(g, r.org, r.dir, reciprocal(r.dir), entry);
        }
        GridDdaPacket<K> dda(g, packet, load_lanes<F>(start));
        alignas(64) std::int32_t cells[K];
        alignas(64) float t_exit[K];
        for (int round = 0; walking && round < 1000; ++round) {
            dda.cells(cells);
            const auto x = dda.crossing();
            store_lanes(t_exit, x.t);
            std::uint32_t out = 0;
            for (std::uint32_t bits = walking; bits; bits &= bits - 1) {
                const int l = std::countr_zero(bits);
                const std::optional<DdaSegment> seg = single[l].next();
                ASSERT_TRUE(seg.has_value());
                ASSERT_EQ(std::uint32_t(cells[l]), seg->cell) << describe(rays[first + l]) << " round " << round;
                ASSERT_EQ(std::bit_cast<std::uint32_t>(t_exit[l]), std::bit_cast<std::uint32_t>(seg->t_exit))
                    << describe(rays[first + l]) << " round " << round;
            }
            alignas(64) float lanes_on[K];
            for (int l = 0; l < K; ++l) lanes_on[l] = (walking >> l) & 1u ? 1.0f : 0.0f;
            const vmask<K> on = load_lanes<F>(lanes_on) > F(0.0f);
            out = mask_bits(dda.advance(x, on));
            for (std::uint32_t bits = out; bits; bits &= bits - 1)
                EXPECT_FALSE(single[std::countr_zero(bits)].next().has_value());
            walking &= ~out;
        }
        EXPECT_EQ(walking, 0u);
    }
}

TEST_F(Grid, PacketDdaWalksLikeSingleRays) {
    std::mt19937 rng(31);
    for (const char* file : {"teapot.nff", "balls.nff"}) {
        const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + file);
        const auto grid = make_grid(scene);
        const GridGeometry& g = grid->grid().geometry;
        std::vector<Rayf> rays = grid_adversarial_rays(g, scene, rng);
        const std::vector<Rayf> random = random_rays(scene, rng, 1000, kOriginGrowth);
        rays.insert(rays.end(), random.begin(), random.end());
        if constexpr (kWidthCompiled<4>) expect_packet_walks_equal<4>(g, rays);
        if constexpr (kWidthCompiled<8>) expect_packet_walks_equal<8>(g, rays);
        if constexpr (kWidthCompiled<16>) expect_packet_walks_equal<16>(g, rays);
    }
}

TEST_F(Grid, PacketsEqualSingleRays) {
    // Packets stepping their lanes' own DDAs have no mailbox, so they must
    // equal the single-ray walk without one bit for bit: the same cells in
    // the same order per lane, the same kernels. Against the default walk
    // (with mailbox), and for the coherent walk, only ties may differ.
    const KernelChoice variants[] = {
        {SphereMethod::Geometric, TriangleMethod::Moeller},
        {SphereMethod::Algebraic, TriangleMethod::Watertight},
        {SphereMethod::Precise, TriangleMethod::Plane},
    };
    std::mt19937 rng(29);
    for (const char* file : {"balls.nff", "mount.nff", "rings.nff", "teapot.nff", "tetra.nff", "tree.nff"}) {
        const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + file);
        for (const KernelChoice& kc : variants) {
            AccelConfig config;
            config.kernels = kc;
            GridConfig no_mailbox;
            no_mailbox.mailbox = false;
            no_mailbox.coherent_packets = false;
            const GridAccel grid(scene, config, no_mailbox);
            std::vector<Rayf> rays = camera_rays(scene, 40);
            const std::vector<Rayf> random = random_rays(scene, rng, 800, kOriginGrowth);
            const std::vector<Rayf> adv = grid_adversarial_rays(grid.grid().geometry, scene, rng);
            rays.insert(rays.end(), random.begin(), random.end());
            rays.insert(rays.end(), adv.begin(), adv.end());
            rays.resize(rays.size() - 3);  // a ragged last packet
            std::vector<Hitf> want(rays.size());
            grid.intersect(rays, want);
            const std::vector<Rayf> shadows = shadow_rays(scene, rays, want);
            std::vector<std::uint8_t> want_occ(shadows.size());
            grid.occluded(shadows, want_occ);
            const GridAccel with_mailbox(scene, config);
            for (int width : {4, 8, 16}) {
                if (!grid.supports_packet(width)) continue;
                SCOPED_TRACE(::testing::Message() << file << " width " << width << " sphere " << int(kc.sphere)
                                                  << " triangle " << int(kc.triangle));
                std::vector<Hitf> got(rays.size());
                grid.intersect_packets(width, rays, got);
                int differ = 0;
                for (std::size_t i = 0; i < rays.size(); ++i) {
                    const bool same = got[i].prim == want[i].prim &&
                                      std::bit_cast<std::uint32_t>(got[i].t) == std::bit_cast<std::uint32_t>(want[i].t) &&
                                      std::bit_cast<std::uint32_t>(got[i].u) == std::bit_cast<std::uint32_t>(want[i].u) &&
                                      std::bit_cast<std::uint32_t>(got[i].v) == std::bit_cast<std::uint32_t>(want[i].v);
                    if (!same && ++differ <= 3)
                        ADD_FAILURE() << describe(rays[i]) << "\n  single " << describe(want[i]) << ", packet "
                                      << describe(got[i]);
                }
                EXPECT_EQ(differ, 0);
                std::vector<std::uint8_t> occ(shadows.size());
                grid.occluded_packets(width, shadows, occ);
                EXPECT_EQ(occ, want_occ);
                std::vector<Hitf> mailboxed(rays.size());
                with_mailbox.intersect(rays, mailboxed);
                std::size_t n = 0;
                const std::string first = hit_mismatches(rays, mailboxed, got, n);
                EXPECT_EQ(n, 0u) << first;
                // The default grid: coherent packets walk slice by slice.
                std::vector<Hitf> coherent(rays.size());
                with_mailbox.intersect_packets(width, rays, coherent);
                const std::string differ_coherent = hit_mismatches(rays, want, coherent, n);
                EXPECT_EQ(n, 0u) << differ_coherent;
                with_mailbox.occluded_packets(width, shadows, occ);
                EXPECT_EQ(occ, want_occ);
            }
        }
    }
}

// ---- Packets: the coherent walk (coherent_grid.h) ----------------------------------------

TEST_F(Grid, MacrocellsMarkExactlyTheOccupiedBlocks) {
    for (const char* file : {"tetra.nff", "tree.nff"}) {
        const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + file);
        const auto grid = make_grid(scene);
        const raypack::Grid& g = grid->grid();
        const MacroCells& m = g.macro;
        std::size_t blocks_full = 0;
        for (int z = 0; z < m.res[2]; ++z)
            for (int y = 0; y < m.res[1]; ++y)
                for (int x = 0; x < m.res[0]; ++x) {
                    bool any_refs = false;
                    for (int cz = z << m.shift; cz < std::min(g.geometry.res[2], (z + 1) << m.shift); ++cz)
                        for (int cy = y << m.shift; cy < std::min(g.geometry.res[1], (y + 1) << m.shift); ++cy)
                            for (int cx = x << m.shift; cx < std::min(g.geometry.res[0], (x + 1) << m.shift); ++cx) {
                                const std::uint32_t c = g.geometry.cell_index(cx, cy, cz);
                                any_refs = any_refs || g.cell_begin[c + 1] > g.cell_begin[c];
                            }
                    ASSERT_EQ(m.any(x, y, z), any_refs) << file << " block " << x << " " << y << " " << z;
                    blocks_full += any_refs;
                }
        for (int a = 0; a < 3; ++a) EXPECT_EQ(m.res[a], (g.geometry.res[a] + (1 << m.shift) - 1) >> m.shift);
        // Both scenes leave blocks empty: the walk has something to skip.
        EXPECT_LT(blocks_full, m.full.size()) << file;
    }
}

/// Packets of width K through the coherent walk directly, against brute
/// force: G = 1, each packet alone (coherent_grid.h); G > 1, groups of G
/// consecutive packets (coherent_grid_group.h), as grid_packet.cpp forms
/// them. The grid's primitives outside its cells are tested first, as there.
/// Where the walk leaves off (its rays diverged, or a group does not share
/// one major direction), brute force over what is left of each remaining
/// lane (up to its closest hit so far) finishes it. Returns how many
/// closest-hit packets the walk finished.
template <int K, int G = 1>
int expect_coherent_walk_matches(const GridAccel& grid, const Scene& scene, const std::vector<Rayf>& rays,
                                 const std::string& what) {
    using F = vfloat<K>;
    const BruteForce brute(scene, KernelChoice{});
    const std::vector<Hitf> truth = trace(brute, rays);
    const PacketRecordIntersector<F> isect{&scene, KernelChoice{}};
    const GridGeometry& g = grid.grid().geometry;
    std::vector<Hitf> got(rays.size());
    std::vector<std::uint8_t> occluded(rays.size()), want_occluded(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) want_occluded[i] = truth[i].found();
    int finished = 0;
    for (std::size_t first = 0; first + G * K <= rays.size(); first += G * K) {
        for (const bool any_hit : {false, true}) {
            LoadedPacket<K> p[G];
            coherent_grid::GroupLanes<K, G> lanes;
            std::uint32_t left[G] = {};
            for (int q = 0; q < G; ++q) {
                load_fresh_packet<K>(rays, first + std::size_t(q) * K, RcpMethod::Exact, p[q]);
                for (const std::uint32_t prim : grid.grid().outside) {
                    const vmask<K> m = isect.intersect(p[q].valid, p[q].ray, p[q].hit, prim);
                    if (any_hit) p[q].occluded = p[q].occluded | m, p[q].valid = p[q].valid & !m;
                }
                const SlabRay<F> slab = make_slab_ray(p[q].ray.org, p[q].ray.rdir, p[q].ray.tnear, p[q].ray.tfar);
                F entry;
                const vmask<K> active = intersect_box<SlabMethod::Robust, F>(
                    p[q].valid, slab, splat<F>(g.bounds.lo), splat<F>(g.bounds.hi), entry);
                if (none(active)) continue;
                left[q] = mask_bits(active);  // until the walk takes them
                lanes.packet[lanes.count] = &p[q];
                lanes.active[lanes.count] = active;
                lanes.entry[lanes.count++] = entry;
            }
            const int k = coherent_grid::group_major_axis<K, G>(lanes);
            if (k >= 0) {
                bool done;
                if constexpr (G == 1) {
                    LoadedPacket<K>& one = *lanes.packet[0];
                    done = any_hit ? coherent_grid::trace<K, true>(grid.grid(), isect, k, one.ray, one.hit,
                                                                   lanes.active[0], lanes.entry[0], one.occluded)
                                   : coherent_grid::trace<K, false>(grid.grid(), isect, k, one.ray, one.hit,
                                                                    lanes.active[0], lanes.entry[0], one.occluded);
                } else {
                    done = any_hit ? coherent_grid::trace_group<K, G, true>(grid.grid(), isect, k, lanes)
                                   : coherent_grid::trace_group<K, G, false>(grid.grid(), isect, k, lanes);
                }
                for (int q = 0; q < lanes.count; ++q) {
                    const auto at = std::size_t(lanes.packet[q] - p);
                    left[at] = done ? 0u : mask_bits(lanes.active[q]);
                }
                finished += done && !any_hit ? lanes.count : 0;
            }
            for (int q = 0; q < G; ++q) {
                alignas(64) float t[K], u[K], v[K], tfar[K];
                store_lanes(t, p[q].hit.t), store_lanes(u, p[q].hit.u), store_lanes(v, p[q].hit.v);
                store_lanes(tfar, p[q].ray.tfar);
                const std::uint32_t o = mask_bits(p[q].occluded);
                for (int l = 0; l < K; ++l) {
                    const std::size_t i = first + std::size_t(q) * K + std::size_t(l);
                    Hitf h{t[l], p[q].hit.prim[l], u[l], v[l]};
                    if ((left[q] >> l) & 1u) {
                        Rayf rest = rays[i];
                        rest.tfar = any_hit ? rest.tfar : tfar[l];
                        const Hitf b = brute.intersect1(rest);
                        if (b.found()) h = b;
                        if (any_hit) occluded[i] = b.found();
                    }
                    if (any_hit) occluded[i] |= (o >> l) & 1u;
                    else got[i] = h;
                }
            }
        }
    }
    std::size_t n = 0;
    const std::string hits = hit_mismatches(rays, truth, got, n);
    EXPECT_EQ(n, 0u) << what << " K=" << K << " G=" << G << ": " << n << " of " << rays.size()
                     << " closest hits differ" << hits;
    const std::string occ = occlusion_mismatches(rays, want_occluded, occluded, n);
    EXPECT_EQ(n, 0u) << what << " K=" << K << " G=" << G << ": " << n << " of " << rays.size()
                     << " occlusion answers differ" << occ;
    return finished;
}

template <int K>
void expect_coherent_walks(const std::string& file, std::mt19937& rng, int bundle_count = 200) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + file);
    const auto grid = make_grid(scene);
    const GridGeometry& g = grid->grid().geometry;
    const float cell = std::min({g.cell_size.x, g.cell_size.y, g.cell_size.z});
    // Camera rays of the middle 64 x 64 pixels of a 512 x 512 image: the
    // walk finishes most packets.
    const std::vector<Rayf> full = camera_rays(scene, 512);
    std::vector<Rayf> camera;
    for (int y = 224; y < 288; ++y)
        camera.insert(camera.end(), full.begin() + y * 512 + 224, full.begin() + y * 512 + 288);
    const int finished = expect_coherent_walk_matches<K>(*grid, scene, camera, file + " camera");
    EXPECT_GE(finished, int(camera.size() / K) * 3 / 4) << file << " K=" << K;
    // The same in groups of 128 rays (two rows of the window's 64 pixels).
    constexpr int G = 128 / K;
    const int group_finished = expect_coherent_walk_matches<K, G>(*grid, scene, camera, file + " camera");
    EXPECT_GE(group_finished, int(camera.size() / K) * 3 / 4) << file << " K=" << K << " G=" << G;
    // Tight bundles around rays that make a DDA stumble (cell edges, planes,
    // corners, axis-parallel, far origins, tnear and tfar inside the grid):
    // every bundle keeps its base ray exactly.
    const std::vector<Rayf> adversarial = grid_adversarial_rays(g, scene, rng);
    const std::vector<Rayf> few(adversarial.begin(),
                                adversarial.begin() + std::ptrdiff_t(adversarial.size() * std::size_t(bundle_count) / 1600));
    expect_coherent_walk_matches<K>(*grid, scene, bundles(few, rng, 0.25f * cell, 1e-3f), file + " edge bundles");
    // Groups: 128 rays around each of every eighth base ray, a group of
    // packets to each (as many rays as above).
    auto every_eighth = [](const std::vector<Rayf>& base) {
        std::vector<Rayf> some;
        for (std::size_t i = 0; i < base.size(); i += 8) some.push_back(base[i]);
        return some;
    };
    expect_coherent_walk_matches<K, G>(*grid, scene, bundles(every_eighth(few), rng, 0.25f * cell, 1e-3f, G * K),
                                       file + " edge bundles");
    // Random bundles, tight and loose; loose ones leave the walk on the way.
    const std::vector<Rayf> random = random_rays(scene, rng, bundle_count, kOriginGrowth);
    expect_coherent_walk_matches<K>(*grid, scene, bundles(random, rng, 2.0f * cell, 0.01f), file + " bundles");
    expect_coherent_walk_matches<K>(*grid, scene, bundles(random, rng, 0.0f, 0.6f), file + " fans");
    expect_coherent_walk_matches<K, G>(*grid, scene, bundles(every_eighth(random), rng, 2.0f * cell, 0.01f, G * K),
                                       file + " bundles");
}

TEST_F(Grid, LargePrimitivesStayOutsideTheCells) {
    // A ground polygon under a small object (SPD balls and tree: the ground
    // comes first in their files): its triangles are tested by every ray and
    // the cells fit the rest; the tree's trunk goes too (it reaches down to
    // the ground). Scenes without one keep everything in cells.
    const std::pair<const char*, std::vector<std::uint32_t>> cases[] = {
        {"balls.nff", {0, 1}}, {"tree.nff", {0, 1, 2}}, {"rings.nff", {}}, {"tetra.nff", {}},
        {"mount.nff", {}},     {"teapot.nff", {}},      {"gears.nff", {}}};
    for (const auto& [file, want] : cases) {
        const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + file);
        const auto grid = make_grid(scene);
        EXPECT_EQ(grid->grid().outside, want) << file;
        if (want.empty()) continue;
        // The grid's box is the rest's, and shrank at least kMinShrink-fold.
        Box3f rest, all;
        for (std::uint32_t p = 0; p < scene.primitive_count(); ++p) {
            all.extend(primitive_bounds(scene, p));
            if (std::find(want.begin(), want.end(), p) == want.end()) rest.extend(primitive_bounds(scene, p));
        }
        const Box3f& box = grid->grid().geometry.bounds;
        for (int a = 0; a < 3; ++a) {
            EXPECT_LE(box.lo[a], rest.lo[a]) << file;
            EXPECT_GE(box.hi[a], rest.hi[a]) << file;
        }
        EXPECT_GE(all.half_area(), kMinShrink * box.half_area()) << file;
        // Camera rays: the same hits as the classic grid (the ground in its
        // cells) with several times fewer primitive tests.
        GridConfig classic_config;
        classic_config.large_primitives_outside = false;
        const auto classic = make_grid(scene, classic_config);
        EXPECT_TRUE(classic->grid().outside.empty());
        GridRayCounters fitted_counts, classic_counts;
        for (const Rayf& r : camera_rays(scene, 64)) {
            const Hitf a = grid->intersect_counting(r, fitted_counts);
            const Hitf b = classic->intersect_counting(r, classic_counts);
            EXPECT_EQ(a.prim, b.prim) << file;
            EXPECT_EQ(a.t, b.t) << file;
        }
        EXPECT_LT(fitted_counts.prim_tests * 3, classic_counts.prim_tests)
            << file << ": " << fitted_counts.prim_tests << " tests against " << classic_counts.prim_tests;
    }
}

TEST_F(Grid, CoherentWalkMatchesBruteForce) {
    std::mt19937 rng(37);
    for (const char* file : {"balls.nff", "mount.nff", "rings.nff", "teapot.nff", "tetra.nff", "tree.nff"}) {
        if constexpr (kWidthCompiled<4>) expect_coherent_walks<4>(file, rng);
        if constexpr (kWidthCompiled<8>) expect_coherent_walks<8>(file, rng);
        if constexpr (kWidthCompiled<16>) expect_coherent_walks<16>(file, rng);
    }
}

TEST_F(Grid, CoherentWalkOnASmallScene) {
    // The test above on one small scene, fewer rays: the sanitizer stage runs this one.
    std::mt19937 rng(41);
    if constexpr (kWidthCompiled<4>) expect_coherent_walks<4>("teapot.nff", rng, 20);
    if constexpr (kWidthCompiled<16>) expect_coherent_walks<16>("teapot.nff", rng, 20);
}

TEST_F(Grid, DivergingPacketsLeaveTheCoherentWalk) {
    // 16 rays from the middle of tetra fanning out over a wide cone about
    // +x: the rectangle outgrows the lanes within a few slices, the walk
    // hands them over to their own DDAs, and the answers stay brute force's.
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/tetra.nff");
    const auto grid = make_grid(scene);
    const Box3f box = grid->grid().geometry.bounds;
    std::vector<Rayf> rays;
    for (int p = 0; p < 64; ++p)
        for (int l = 0; l < 16; ++l) {
            Rayf r;
            r.org = box.lo + box.extent() * Vec3f{0.05f, 0.3f + 0.01f * float(p % 8), 0.3f + 0.01f * float(p / 8)};
            const float a = 1.2f * (float(l % 4) / 3.0f - 0.5f), b = 1.2f * (float(l / 4) / 3.0f - 0.5f);
            r.dir = {1.0f, std::tan(a), std::tan(b)};
            rays.push_back(r);
        }
    if constexpr (kWidthCompiled<16>) {
        const int finished = expect_coherent_walk_matches<16>(*grid, scene, rays, "fan");
        EXPECT_LT(finished, 64 / 2);  // most packets left the walk
    }
    std::vector<Hitf> got(rays.size());
    grid->intersect_packets(kWidthCompiled<16> ? 16 : 4, rays, got);
    const BruteForce brute(scene, KernelChoice{});
    std::size_t n = 0;
    const std::string first = hit_mismatches(rays, trace(brute, rays), got, n);
    EXPECT_EQ(n, 0u) << first;
}

}  // namespace
}  // namespace raypack::grid_test
