// One suite over the cell structures (uniform grid, two-level grid, octree,
// k-d tree): each must answer every ray as brute force does (exactly, ties at
// shared edges aside) on the hand-made scenes that break cell walks, with the
// rays built from its own planes, and its packets of every width must answer
// as its single rays (bit for bit for the k-d tree). What is particular to one
// structure (its build, its walk's parts, its counts) stays in its own file.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/grid/grid2_accel.h"
#include "accel/grid/grid_accel.h"
#include "accel/kdtree/kdtree_accel.h"
#include "accel/octree/octree_accel.h"
#include "accel/prims/triangle_edges.h"
#include "tests/cell_test_cases.h"
#include "tests/grid_test_rays.h"
#include "tests/oracle_harness.h"

namespace raypack::cell_structures_test {

using namespace raypack::oracle_harness;
using namespace raypack::cell_test_cases;
namespace {

/// A structure of the suite: its kind for build_accel, the rays that make
/// its walk stumble, and how its packets must answer.
struct GridCase {
    static constexpr const char* kind = "grid";
    /// Leaves read Moeller's triangle records (accel/prims/triangle_edges.h)
    /// rather than the vertices: measured faster for the grids and the
    /// octree, not for the k-d tree (docs/structures.md).
    static constexpr bool triangle_records = true;
    static constexpr PacketAnswers packets = PacketAnswers::UpToTies;
    static std::vector<Rayf> adversarial_rays(const Accel& accel, const Scene& scene, std::mt19937& rng) {
        return grid_test_rays::grid_adversarial_rays(dynamic_cast<const GridAccel&>(accel).grid().geometry, scene, rng);
    }
};

struct Grid2Case {
    static constexpr const char* kind = "grid2";
    static constexpr bool triangle_records = true;
    static constexpr PacketAnswers packets = PacketAnswers::UpToTies;
    /// The top grid's planes, and those of its largest cell grid.
    static std::vector<Rayf> adversarial_rays(const Accel& accel, const Scene& scene, std::mt19937& rng) {
        const TwoLevelGrid& g = dynamic_cast<const Grid2Accel&>(accel).grid();
        std::vector<Rayf> rays = grid_test_rays::grid_adversarial_rays(g.top.geometry, scene, rng);
        const auto largest = std::max_element(g.cells.begin(), g.cells.end(), [](const Grid& a, const Grid& b) {
            return a.geometry.cells() < b.geometry.cells();
        });
        if (largest != g.cells.end()) {
            const std::vector<Rayf> cell = grid_test_rays::grid_adversarial_rays(largest->geometry, scene, rng);
            rays.insert(rays.end(), cell.begin(), cell.end());
        }
        return rays;
    }
};

struct OctreeCase {
    static constexpr const char* kind = "octree";
    static constexpr bool triangle_records = true;
    static constexpr PacketAnswers packets = PacketAnswers::UpToTies;
    static std::vector<Rayf> adversarial_rays(const Accel& accel, const Scene& scene, std::mt19937& rng) {
        return octree_adversarial_rays(dynamic_cast<const OctreeAccel&>(accel).octree(), scene, rng);
    }
};

struct KdTreeCase {
    static constexpr const char* kind = "kdtree";
    static constexpr bool triangle_records = false;
    static constexpr PacketAnswers packets = PacketAnswers::BitForBit;  // the same kernels, lane by lane
    static std::vector<Rayf> adversarial_rays(const Accel& accel, const Scene& scene, std::mt19937& rng) {
        return kdtree_adversarial_rays(dynamic_cast<const KdTreeAccel&>(accel).tree(), scene, rng);
    }
};

template <class Case>
class CellStructures : public ::testing::Test {
protected:
    static std::unique_ptr<Accel> build(const Scene& scene) { return build_accel(scene, accel_config(Case::kind)); }
    /// `n` random rays (some from outside the scene box), then the adversarial ones.
    static std::vector<Rayf> rays_for(const Accel& accel, const Scene& scene, std::mt19937& rng, int n) {
        std::vector<Rayf> rays = random_rays(scene, rng, n, kOriginGrowth);
        const std::vector<Rayf> adv = Case::adversarial_rays(accel, scene, rng);
        rays.insert(rays.end(), adv.begin(), adv.end());
        return rays;
    }
    static void expect_agreement(const Scene& scene, const Accel& accel, const std::vector<Rayf>& rays,
                                 const std::string& what) {
        expect_oracle_agreement(scene, accel, rays, std::string(Case::kind) + " " + what, Case::packets);
    }
};

struct CaseNames {
    template <class Case>
    static std::string GetName(int) {
        return Case::kind;
    }
};

using Cases = ::testing::Types<GridCase, Grid2Case, OctreeCase, KdTreeCase>;
TYPED_TEST_SUITE(CellStructures, Cases, CaseNames);

TYPED_TEST(CellStructures, RegisteredAsAnAccelKind) {
    const auto kinds = accel_kinds();
    EXPECT_NE(std::find(kinds.begin(), kinds.end(), std::string(TypeParam::kind)), kinds.end());
    EXPECT_NE(accel_kinds_list().find(TypeParam::kind), std::string::npos);
    const Scene scene = scene_with([](Scene& s) { s.add_sphere({0, 0, 0}, 1, 0); });
    EXPECT_EQ(this->build(scene)->stats().name, TypeParam::kind);
}

TYPED_TEST(CellStructures, TriangleRecordsOnlyWhereRead) {
    // 48 bytes a triangle with Moeller's test in float (the default), where
    // the structure reads them; none with another triangle test, nor in double.
    std::mt19937 rng(11);
    const Scene scene = scene_with([&](Scene& s) {
        for (int i = 0; i < 40; ++i) {
            const Vec3f c{float(i % 7), float(i / 7), float(i % 3)};
            s.add_triangle(c, c + Vec3f{1, 0, 0}, c + Vec3f{0, 1, 0.5f}, 0);
        }
        s.add_sphere({3, 3, 3}, 1, 0);
    });
    const auto with = this->build(scene);
    KernelChoice watertight;
    watertight.triangle = TriangleMethod::Watertight;
    KernelChoice in_double;
    in_double.precision = Precision::Double;
    const auto without = build_accel(scene, accel_config(TypeParam::kind, watertight));
    const auto double_precision = build_accel(scene, accel_config(TypeParam::kind, in_double));
    EXPECT_EQ(with->stats().bytes - without->stats().bytes,
              TypeParam::triangle_records ? 40 * sizeof(TriangleEdgeRecord) : 0u);
    EXPECT_EQ(double_precision->stats().bytes, without->stats().bytes);
    EXPECT_EQ(sizeof(TriangleEdgeRecord), 48u);
    // Brute force's answers (read from the vertices).
    this->expect_agreement(scene, *with, this->rays_for(*with, scene, rng, 2000), "records");
}

TYPED_TEST(CellStructures, OnePrimitiveOfEachKind) {
    std::mt19937 rng(7);
    for (const Scene& scene : one_primitive_scenes()) {
        const auto accel = this->build(scene);
        this->expect_agreement(scene, *accel, this->rays_for(*accel, scene, rng, 500),
                               "one " + std::to_string(int(scene.prims[0].kind)));
    }
}

TYPED_TEST(CellStructures, EmptySceneMissesEverything) {
    const Scene scene;
    const auto accel = this->build(scene);
    std::vector<Rayf> rays(37);
    for (std::size_t i = 0; i < rays.size(); ++i) rays[i].dir = {1, float(i) - 18, 0.5f};
    for (int width : {1, 4, 8, 16}) {
        if (!accel->supports_packet(width)) continue;
        for (const Hitf& h : trace_hits(*accel, rays, width)) EXPECT_FALSE(h.found()) << width;
        for (std::uint8_t o : trace_occlusion(*accel, rays, width)) EXPECT_EQ(o, 0) << width;
    }
}

TYPED_TEST(CellStructures, FlatScenes) {
    std::mt19937 rng(11);
    for (int axis = 0; axis < 3; ++axis) {
        const Scene scene = flat_scene(axis, 24, rng);
        const auto accel = this->build(scene);
        std::vector<Rayf> rays = this->rays_for(*accel, scene, rng, 1000);
        const std::vector<Rayf> flat = flat_scene_rays(axis, rng, 1500);
        rays.insert(rays.end(), flat.begin(), flat.end());
        this->expect_agreement(scene, *accel, rays, "flat " + std::to_string(axis));
    }
}

TYPED_TEST(CellStructures, PrimitivesSpanningManyCells) {
    std::mt19937 rng(13);
    const Scene scene = spanning_scene(rng);
    const auto accel = this->build(scene);
    this->expect_agreement(scene, *accel, this->rays_for(*accel, scene, rng, 3000), "spanning");
}

}  // namespace
}  // namespace raypack::cell_structures_test
