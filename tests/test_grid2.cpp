// The two-level grid (accel/grid/two_level_grid.h, grid2_accel.h) against
// the brute-force oracle, single rays and packets, and its build against
// its definition: every top cell's grid holds exactly the top cell's
// primitives and covers them wherever they are inside the top cell.
#include <gtest/gtest.h>
#include "tests/test_paths.h"

#include <algorithm>
#include <filesystem>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "accel/grid/grid2_accel.h"
#include "accel/grid/grid_accel.h"
#include "scene/load.h"
#include "tests/grid_test_rays.h"
#include "tests/oracle_harness.h"

namespace raypack::grid2_test {

using namespace raypack::oracle_harness;
using namespace raypack::grid_test_rays;
namespace {


Scene load(const std::string& file) { return load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + file); }

/// Rays of the middle 64 x 64 pixels of a 512 x 512 camera image: packets of
/// them are coherent, as a render's are.
std::vector<Rayf> camera_window(const Scene& scene) {
    const std::vector<Rayf> full = camera_rays(scene, 512);
    std::vector<Rayf> rays;
    for (int y = 224; y < 288; ++y) rays.insert(rays.end(), full.begin() + y * 512 + 224, full.begin() + y * 512 + 288);
    return rays;
}

/// Packets of every compiled width against brute force: closest hits
/// (ties at shared edges aside) and occlusion.
void expect_packets_agree(const Scene& scene, const Accel& grid, const std::vector<Rayf>& rays,
                          const std::string& what) {
    const BruteForce brute(scene, KernelChoice{});
    const std::vector<Hitf> truth = trace(brute, rays);
    std::vector<std::uint8_t> want(rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) want[i] = truth[i].found();
    for (int width : {4, 8, 16}) {
        if (!grid.supports_packet(width)) continue;
        std::vector<Hitf> got(rays.size());
        grid.intersect_packets(width, rays, got);
        std::size_t n = 0;
        const std::string hits = hit_mismatches(rays, truth, got, n);
        EXPECT_EQ(n, 0u) << what << " K=" << width << ": " << n << " of " << rays.size() << " closest hits differ"
                         << hits;
        std::vector<std::uint8_t> occ(rays.size());
        grid.occluded_packets(width, rays, occ);
        const std::string o = occlusion_mismatches(rays, want, occ, n);
        EXPECT_EQ(n, 0u) << what << " K=" << width << ": " << n << " occlusion answers differ" << o;
    }
}

class Grid2 : public ::testing::TestWithParam<std::string> {};

TEST_P(Grid2, MatchesBruteForce) {
    const Scene scene = load(GetParam());
    AccelConfig config;
    config.kind = "grid2";
    const std::unique_ptr<Accel> accel = build_accel(scene, config);
    const auto& grid = dynamic_cast<const Grid2Accel&>(*accel);
    std::mt19937 rng(20261127);
    const GridGeometry& top = grid.grid().top.geometry;
    // Single rays: camera, random, rays along the top grid's planes and
    // along the planes of its largest cell grid.
    expect_agreement(scene, grid, camera_rays(scene, 64), GetParam() + " camera");
    expect_agreement(scene, grid, random_rays(scene, rng, 2000, kOriginGrowth), GetParam() + " random");
    expect_agreement(scene, grid, grid_adversarial_rays(top, scene, rng), GetParam() + " top adversarial");
    const auto largest = std::max_element(grid.grid().cells.begin(), grid.grid().cells.end(),
                                          [](const Grid& a, const Grid& b) { return a.refs.size() < b.refs.size(); });
    ASSERT_NE(largest, grid.grid().cells.end());
    const std::vector<Rayf> cell_rays = grid_adversarial_rays(largest->geometry, scene, rng);
    expect_agreement(scene, grid, cell_rays, GetParam() + " cell adversarial");
    // Packets: coherent camera windows and bundles, and the rest.
    const std::vector<Rayf> few(cell_rays.begin(), cell_rays.begin() + std::ptrdiff_t(cell_rays.size() / 16));
    expect_packets_agree(scene, grid, camera_window(scene), GetParam() + " camera window");
    expect_packets_agree(scene, grid, bundles(few, rng, 0.25f * largest->geometry.cell_size.x, 1e-3f),
                         GetParam() + " cell bundles");
    expect_packets_agree(scene, grid, random_rays(scene, rng, 1000, kOriginGrowth), GetParam() + " random");
    EXPECT_EQ(grid.stats().name, "grid2");
    EXPECT_EQ(grid.stats().depth, 2);
    EXPECT_EQ(grid.stats().bytes, grid.grid().bytes() + grid.triangle_edge_bytes());
}

INSTANTIATE_TEST_SUITE_P(, Grid2, ::testing::ValuesIn(shared_scene_files()), param_name);

TEST_F(Grid2, EachCellGridHoldsAndCoversTheCellsPrimitives) {
    for (const char* file : {"tree.nff", "teapot.nff"}) {
        const Scene scene = load(file);
        const Grid2Accel accel(scene, AccelConfig{});
        const TwoLevelGrid& g = accel.grid();
        const GridGeometry& top = g.top.geometry;
        ASSERT_EQ(g.cell_grid.size(), top.cells());
        std::size_t non_empty = 0;
        for (std::size_t c = 0; c < top.cells(); ++c) {
            const std::uint32_t first = g.top.cell_begin[c], last = g.top.cell_begin[c + 1];
            if (first == last) {
                EXPECT_EQ(g.cell_grid[c], TwoLevelGrid::kNoGrid);
                continue;
            }
            ++non_empty;
            ASSERT_LT(g.cell_grid[c], g.cells.size());
            const Grid& sub = g.cells[g.cell_grid[c]];
            const std::set<std::uint32_t> in_top(g.top.refs.begin() + first, g.top.refs.begin() + last);
            const std::set<std::uint32_t> in_sub(sub.refs.begin(), sub.refs.end());
            // Every primitive of the top cell is somewhere in its grid, and nothing else.
            EXPECT_EQ(in_sub, in_top) << file << " top cell " << c;
            // The cell's grid covers every part of its primitives inside the top cell.
            const int x = int(c % std::size_t(top.res[0])), y = int((c / std::size_t(top.res[0])) % std::size_t(top.res[1])),
                      z = int(c / (std::size_t(top.res[0]) * std::size_t(top.res[1])));
            const int index[3] = {x, y, z};
            for (const std::uint32_t p : in_top) {
                const Box3f b = primitive_bounds(scene, p);
                for (int a = 0; a < 3; ++a) {
                    EXPECT_LE(sub.geometry.bounds.lo[a], std::max(b.lo[a], top.plane(a, index[a]))) << file << " " << c;
                    EXPECT_GE(sub.geometry.bounds.hi[a], std::min(b.hi[a], top.plane(a, index[a] + 1))) << file << " " << c;
                }
            }
        }
        EXPECT_EQ(non_empty, g.cells.size());
    }
}

TEST_F(Grid2, TheTreeNoLongerCrowdsIntoAFewCells) {
    // SPD's tree, the uniform grid's failure (docs/structures.md): a dense
    // tree on a ground 16 times wider. The two-level grid spends its cells
    // on the tree, so a camera ray tests a tenth of the primitives or fewer
    // than in the classic uniform grid (with the ground in its cells).
    const Scene scene = load("tree.nff");
    GridConfig classic;
    classic.large_primitives_outside = false;
    const GridAccel grid(scene, AccelConfig{}, classic);
    const Grid2Accel grid2(scene, AccelConfig{});
    // Its ground and trunk stay outside the cells, as in the uniform grid.
    EXPECT_EQ(grid2.grid().top.outside, (std::vector<std::uint32_t>{0, 1, 2}));
    GridRayCounters one, two;
    const std::vector<Rayf> rays = camera_rays(scene, 48);
    for (const Rayf& r : rays) {
        const Hitf a = grid.intersect_counting(r, one), b = grid2.intersect_counting(r, two);
        EXPECT_EQ(a.found(), b.found());
    }
    EXPECT_GT(one.prim_tests, 0u);
    EXPECT_LT(two.prim_tests * 10, one.prim_tests) << "grid " << one.prim_tests << ", grid2 " << two.prim_tests;
    EXPECT_LT(grid2.stats().bytes, 2 * grid.stats().bytes);
}

}  // namespace
}  // namespace raypack::grid2_test
