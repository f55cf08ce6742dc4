// The traversal variants --slabs, --rcp and --precision (KernelChoice) in
// the cell structures: grid, octree, k-d tree, single rays, packets of every
// compiled width and the counting walk.
// - Robust slabs with exact or approximate reciprocals, float or double
//   primitive tests, agree exactly with the brute-force oracle (same
//   kernels) on camera and random rays.
// - Packets equal single rays bit for bit, and the counting walk gives the
//   single rays' answers, for every variant.
// - Plain slabs agree with the oracle on random rays, never report a hit the
//   oracle lacks, and lose a stated number of hits on adversarial rays (rays
//   in and along the structures' own planes, +-0 components, origins on the
//   root box's faces), so that a change of behaviour shows.
// - Robust slabs with the watertight triangle test lose no hit on them.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <tbb/parallel_for.h>

#include <array>
#include <bit>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "tests/oracle_harness.h"
#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "accel/cell_kernel_variants.h"
#include "kernels/ray_packet.h"
#include "accel/grid/grid_accel.h"
#include "accel/kdtree/kdtree_accel.h"
#include "accel/octree/octree_accel.h"
#include "render/camera_rays.h"
#include "scene/load.h"

namespace raypack::kernel_variants_cells_test {

using namespace raypack::oracle_harness;
namespace {

const char* const kStructures[] = {"grid", "octree", "kdtree"};

std::uint32_t bits(float f) { return std::bit_cast<std::uint32_t>(f); }

/// What a structure's answers lack against the oracle's.
struct Disagreement {
    std::size_t lost = 0;     ///< the oracle hits, the structure misses (or is not occluded)
    std::size_t farther = 0;  ///< the structure's closest hit lies beyond the oracle's
    std::size_t extra = 0;    ///< the structure hits where the oracle does not, or nearer
    std::string first;        ///< the first few, described
    std::size_t total() const { return lost + farther + extra; }
};

/// Closest hits and occlusion against the oracle's: the same primitive at the
/// bit-identical t, or another at a t within 1e-5 (a shared edge or vertex).
Disagreement compare(const std::vector<Rayf>& rays, const std::vector<Hitf>& want, const std::vector<Hitf>& got,
                     const std::vector<std::uint8_t>& got_occ) {
    Disagreement d;
    for (std::size_t i = 0; i < rays.size(); ++i) {
        std::size_t* kind = nullptr;
        if (want[i].found() != bool(got_occ[i])) kind = want[i].found() ? &d.lost : &d.extra;
        if (want[i].found() && !got[i].found()) kind = &d.lost;
        else if (!want[i].found() && got[i].found()) kind = &d.extra;
        else if (want[i].found()) {
            const bool ok = want[i].prim == got[i].prim
                                ? want[i].t == got[i].t
                                : std::fabs(want[i].t - got[i].t) <=
                                      1e-5f * std::max(std::fabs(want[i].t), std::fabs(got[i].t));
            if (!ok) kind = got[i].t > want[i].t ? &d.farther : &d.extra;
        }
        if (!kind) continue;
        ++*kind;
        if (d.total() <= 3)
            d.first += "\n  " + describe(rays[i]) + "\n    oracle " + describe(want[i]) + ", structure " +
                       describe(got[i]) + (got_occ[i] ? " (occluded)" : " (clear)");
    }
    return d;
}

/// random_rays() (tests/oracle_harness.h) draws origins in the scene box
/// grown by this fraction per side, so that some start outside the structure.
constexpr float kOriginGrowth = 0.2f;

/// The planes a structure computes distances to, per axis, and its root box.
struct Planes {
    std::vector<float> at[3];
    Box3f root;
};

Planes planes_of(const Accel& accel) {
    Planes p;
    if (const auto* g = dynamic_cast<const GridAccel*>(&accel)) {
        const GridGeometry& geo = g->grid().geometry;
        p.root = geo.bounds;
        for (int a = 0; a < 3; ++a)
            for (int i = 0; i <= geo.res[a]; ++i) p.at[a].push_back(geo.plane(a, i));
    } else if (const auto* o = dynamic_cast<const OctreeAccel*>(&accel)) {
        // Node faces down to depth 5: lo + side * k / 2^d, as the traversal's midpoints see them.
        p.root = o->octree().cube;
        for (int a = 0; a < 3; ++a)
            for (int k = 0; k <= 32; ++k)
                p.at[a].push_back(p.root.lo[a] + (p.root.hi[a] - p.root.lo[a]) * (float(k) / 32.0f));
    } else {
        const auto& kd = dynamic_cast<const KdTreeAccel&>(accel).tree();
        p.root = kd.bounds;
        for (const KdNode& n : kd.nodes)
            if (!n.is_leaf()) p.at[n.axis()].push_back(n.split());
        for (int a = 0; a < 3; ++a) p.at[a].push_back(p.root.lo[a]), p.at[a].push_back(p.root.hi[a]);
    }
    return p;
}

/// Rays that make slab distances round the wrong way, from the structure's
/// own planes: in and along them with +-0 direction components, through
/// their corners, and from the root box's faces.
std::vector<Rayf> adversarial_rays(const Planes& p, const Scene& scene, std::mt19937& rng) {
    std::vector<Rayf> rays;
    const Box3f box = p.root;
    auto plane = [&](int a) { return p.at[a][rng() % p.at[a].size()]; };
    auto corner = [&] { return Vec3f{plane(0), plane(1), plane(2)}; };
    // 1. Along plane intersections, axis-parallel, from outside the root box.
    append_edge_rays(rays, rng, box, corner, 300);
    // 2. Inside a plane (that direction component +-0), from inside the box.
    append_in_plane_rays(rays, rng, box, plane, 300);
    // 3. Through plane corners, and from them.
    append_corner_rays(rays, rng, box, corner, 300);
    // 4. Origins on the root box's faces: inwards, and along the face (+-0).
    append_face_rays(rays, rng, box, 300);
    // 5. Aimed at triangle vertices and sphere poles.
    append_vertex_rays(rays, scene, rng, grown(box, 0.2f), 200);
    return rays;
}

KernelChoice variant(SlabMethod slabs, RcpMethod rcp, Precision precision,
                     TriangleMethod triangle = TriangleMethod::Moeller) {
    KernelChoice k;
    k.triangle = triangle;
    k.slabs = slabs;
    k.rcp = rcp;
    k.precision = precision;
    return k;
}

std::string name(const KernelChoice& k) {
    return std::string(k.slabs == SlabMethod::Plain ? "plain" : "robust") + "/" +
           (k.rcp == RcpMethod::Approx ? "approx" : "exact") + "/" +
           (k.precision == Precision::Double ? "double" : "float") +
           (k.triangle == TriangleMethod::Watertight ? "/watertight" : "");
}

/// The grid without mailbox, whose single-ray walk packets reproduce bit
/// for bit (grid_accel.h); the other structures as configured.
std::unique_ptr<Accel> make(const Scene& scene, const std::string& kind, const KernelChoice& k) {
    if (kind == "grid") {
        GridConfig gc;
        gc.mailbox = false;
        return std::make_unique<GridAccel>(scene, accel_config(kind, k), gc);
    }
    return build_accel(scene, accel_config(kind, k));
}

Scene load(const std::string& file) { return load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + file); }

// The shared scenes but the two largest, gears and bunny, whose builds (up
// to fifteen per test) alone would take some 30 s (test_grid.cpp, test_octree.cpp
// and test_kdtree.cpp trace them with the default variant).
const std::vector<std::string> kScenes = {"balls.nff", "mount.nff", "rings.nff", "teapot.nff", "tetra.nff",
                                          "tree.nff"};

/// Hits plain slabs (with exact reciprocals) lose on the 1400
/// adversarial_rays() of seed 7 (missed, or a farther hit found), per scene
/// and structure {grid, octree, kdtree}, as measured. The grid and octree
/// lose none: their builders widen cells and nodes by a placement margin that
/// also covers plain rounding. The k-d tree's plain walk drops the margin of
/// its split planes, so rays in and along them miss leaves (Ize 2013's case).
/// (tree lost 24 until its ground left the tree, session 30: the rays along
/// the ground's plane meet it outside the tree now.)
const std::map<std::string, std::array<std::size_t, 3>> kPlainAdversarialLosses = {
    {"balls.nff", {0, 0, 0}},    {"mount.nff", {0, 0, 17}},  {"rings.nff", {0, 0, 15}},
    {"teapot.nff", {0, 0, 10}}, {"tetra.nff", {0, 0, 238}}, {"tree.nff", {0, 0, 0}},
};

class KernelVariantsCells : public ::testing::TestWithParam<std::string> {};

// (a) Robust slabs, exact or approximate reciprocals, float or double
// primitive tests: exactly the oracle's answers (with the same kernels).
TEST_P(KernelVariantsCells, RobustVariantsAgreeWithOracle) {
    const Scene scene = load(GetParam());
    std::mt19937 rng(3);
    std::vector<Rayf> rays = camera_rays(scene, 24);
    const std::vector<Rayf> random = random_rays(scene, rng, 600, kOriginGrowth);
    rays.insert(rays.end(), random.begin(), random.end());
    for (const KernelChoice& k : {variant(SlabMethod::Robust, RcpMethod::Exact, Precision::Float),
                                  variant(SlabMethod::Robust, RcpMethod::Exact, Precision::Double),
                                  variant(SlabMethod::Robust, RcpMethod::Approx, Precision::Float)}) {
        const BruteForce oracle(scene, k);
        const std::vector<Hitf> want = trace_hits(oracle, rays);
        for (const char* kind : kStructures) {
            const std::unique_ptr<Accel> accel = build_accel(scene, accel_config(kind, k));
            const Disagreement d = compare(rays, want, trace_hits(*accel, rays), trace_occlusion(*accel, rays));
            EXPECT_EQ(d.total(), 0u) << GetParam() << " " << kind << " " << name(k) << ": " << d.lost << " lost, "
                                     << d.farther << " farther, " << d.extra << " extra of " << rays.size()
                                     << d.first;
        }
    }
}

// (b) Packets of every compiled width equal single rays bit for bit, closest
// hit and occlusion, and the counting walk gives the single rays' answers.
TEST_P(KernelVariantsCells, PacketsAndCountingEqualSingleRays) {
    const Scene scene = load(GetParam());
    std::mt19937 rng(5);
    for (const char* kind : kStructures) {
        for (const KernelChoice& k : {variant(SlabMethod::Robust, RcpMethod::Exact, Precision::Float),
                                      variant(SlabMethod::Robust, RcpMethod::Exact, Precision::Double),
                                      variant(SlabMethod::Robust, RcpMethod::Approx, Precision::Float),
                                      variant(SlabMethod::Plain, RcpMethod::Exact, Precision::Float),
                                      variant(SlabMethod::Plain, RcpMethod::Approx, Precision::Float)}) {
            const std::unique_ptr<Accel> accel = make(scene, kind, k);
            std::vector<Rayf> rays = camera_rays(scene, 16);
            const std::vector<Rayf> random = random_rays(scene, rng, 200, kOriginGrowth);
            const std::vector<Rayf> adv = adversarial_rays(planes_of(*accel), scene, rng);
            rays.insert(rays.end(), random.begin(), random.end());
            rays.insert(rays.end(), adv.begin(), adv.end());
            rays.resize(rays.size() - 3);  // a ragged last packet
            const std::vector<Hitf> want = trace_hits(*accel, rays);
            const std::vector<std::uint8_t> want_occ = trace_occlusion(*accel, rays);
            int checked = 0;
            for (int width : {4, 8, 16}) {
                if (!accel->supports_packet(width)) continue;
                ++checked;
                const std::vector<Hitf> got = trace_hits(*accel, rays, width);
                const std::vector<std::uint8_t> got_occ = trace_occlusion(*accel, rays, width);
                std::size_t differ = 0;
                for (std::size_t i = 0; i < rays.size(); ++i) {
                    if (same_bits(want[i], got[i]) && want_occ[i] == got_occ[i]) continue;
                    if (++differ <= 3)
                        ADD_FAILURE() << GetParam() << " " << kind << " " << name(k) << " width " << width << ": "
                                      << describe(rays[i]) << "\n  single " << describe(want[i]) << ", packet "
                                      << describe(got[i]);
                }
                EXPECT_EQ(differ, 0u) << GetParam() << " " << kind << " " << name(k) << " width " << width;
            }
            EXPECT_GE(checked, 1) << "no packet width compiled in";
            for (bool any_hit : {false, true}) {
                std::vector<Hitf> counted(rays.size());
                TraversalCounts counts;
                ASSERT_TRUE(accel->count_traversal(rays, any_hit, counted, counts));
                std::size_t differ = 0;
                for (std::size_t i = 0; i < rays.size(); ++i)
                    differ += any_hit ? counted[i].found() != bool(want_occ[i]) : !same_bits(counted[i], want[i]);
                EXPECT_EQ(differ, 0u) << GetParam() << " " << kind << " " << name(k) << " counting, any hit "
                                      << any_hit;
                EXPECT_GT(counts.nodes, 0u);
            }
        }
    }
}

// (c) Plain slabs: the oracle's answers on random rays; on adversarial rays
// never a hit the oracle lacks, and exactly the stated number lost.
TEST_P(KernelVariantsCells, PlainSlabsLoseOnlyTheStatedHits) {
    const Scene scene = load(GetParam());
    std::mt19937 rng(3);
    std::vector<Rayf> rays = camera_rays(scene, 24);
    const std::vector<Rayf> random = random_rays(scene, rng, 600, kOriginGrowth);
    rays.insert(rays.end(), random.begin(), random.end());
    const KernelChoice plain = variant(SlabMethod::Plain, RcpMethod::Exact, Precision::Float);
    const KernelChoice plain_approx = variant(SlabMethod::Plain, RcpMethod::Approx, Precision::Float);
    const BruteForce oracle(scene, plain);
    const std::vector<Hitf> want = trace_hits(oracle, rays);
    for (int s = 0; s < 3; ++s) {
        const char* kind = kStructures[s];
        for (const KernelChoice& k : {plain, plain_approx}) {
            const std::unique_ptr<Accel> accel = build_accel(scene, accel_config(kind, k));
            const Disagreement d = compare(rays, want, trace_hits(*accel, rays), trace_occlusion(*accel, rays));
            EXPECT_EQ(d.total(), 0u) << GetParam() << " " << kind << " " << name(k) << " random: " << d.lost
                                     << " lost, " << d.farther << " farther, " << d.extra << " extra" << d.first;

            std::mt19937 adv_rng(7);
            const std::vector<Rayf> adv = adversarial_rays(planes_of(*accel), scene, adv_rng);
            const std::vector<Hitf> adv_want = trace_hits(oracle, adv);
            const Disagreement a = compare(adv, adv_want, trace_hits(*accel, adv), trace_occlusion(*accel, adv));
            EXPECT_EQ(a.extra, 0u) << GetParam() << " " << kind << " " << name(k) << a.first;
            const std::string key = std::string(kind) + " " + name(k);
            RecordProperty(key + " adversarial lost", std::to_string(a.lost + a.farther));
            std::printf("%s %s adversarial: %zu lost, %zu farther of %zu\n", GetParam().c_str(), key.c_str(), a.lost,
                        a.farther, adv.size());
            // Approximate reciprocals differ between rcp14 (AVX-512) and rcpss, so only
            // exact ones have a stated count.
            if (k.rcp == RcpMethod::Exact) {
                EXPECT_EQ(a.lost + a.farther, kPlainAdversarialLosses.at(GetParam())[s])
                    << GetParam() << " " << kind << " plain/exact: adversarial losses changed" << a.first;
            }
        }
    }
}

// (d) Robust slabs, exact reciprocals, watertight triangles: no hit lost on
// the adversarial rays either.
TEST_P(KernelVariantsCells, RobustWatertightLosesNoAdversarialHit) {
    const Scene scene = load(GetParam());
    const KernelChoice k =
        variant(SlabMethod::Robust, RcpMethod::Exact, Precision::Float, TriangleMethod::Watertight);
    const BruteForce oracle(scene, k);
    for (const char* kind : kStructures) {
        const std::unique_ptr<Accel> accel = build_accel(scene, accel_config(kind, k));
        std::mt19937 rng(7);
        const std::vector<Rayf> adv = adversarial_rays(planes_of(*accel), scene, rng);
        const Disagreement d = compare(adv, trace_hits(oracle, adv), trace_hits(*accel, adv), trace_occlusion(*accel, adv));
        EXPECT_EQ(d.total(), 0u) << GetParam() << " " << kind << ": " << d.lost << " lost, " << d.farther
                                 << " farther, " << d.extra << " extra of " << adv.size() << d.first;
    }
}

INSTANTIATE_TEST_SUITE_P(, KernelVariantsCells, ::testing::ValuesIn(kScenes), param_name);

// The hits above cannot tell an approximate rdir from an exact one (the
// structures' margins absorb a few ulps), so the packets' rdir is checked
// here: load_packet() gives every lane the single ray's reciprocal(dir, rcp),
// and approximate ones do differ from exact ones.
template <int K>
void check_packet_rcp(std::mt19937& rng) {
    std::vector<Rayf> rays(K);
    int approx_differs = 0;
    for (int round = 0; round < 200; ++round) {
        for (int l = 0; l < K; ++l) {
            rays[l].org = {0, 0, 0};
            rays[l].dir = random_direction(rng);
            if (l == 1) rays[l].dir.y = signed_zero(rng);
        }
        for (RcpMethod rcp : {RcpMethod::Exact, RcpMethod::Approx}) {
            vmask<K> valid;
            RayPacket<K> p = load_packet<K>(rays, valid, rcp);
            alignas(64) float r[3][K];
            for (int a = 0; a < 3; ++a) store_lanes(r[a], p.rdir[a]);
            for (int l = 0; l < K; ++l) {
                const Vec3f want = reciprocal(rays[l].dir, rcp);
                for (int a = 0; a < 3; ++a) ASSERT_EQ(bits(r[a][l]), bits(want[a])) << K << " lane " << l;
                if (rcp == RcpMethod::Approx)
                    for (int a = 0; a < 3; ++a) approx_differs += want[a] != reciprocal(rays[l].dir)[a];
            }
        }
    }
    EXPECT_GT(approx_differs, 0) << "approximate reciprocals all equal the exact ones: --rcp approx is not approximate";
}

TEST(KernelVariantsCellsRcp, PacketsGetTheSingleRaysReciprocals) {
    std::mt19937 rng(11);
#if defined(__SSE4_2__)
    check_packet_rcp<4>(rng);
#endif
#if defined(__AVX2__)
    check_packet_rcp<8>(rng);
#endif
#if defined(__AVX512BW__)
    check_packet_rcp<16>(rng);
#endif
}

}  // namespace
}  // namespace raypack::kernel_variants_cells_test
