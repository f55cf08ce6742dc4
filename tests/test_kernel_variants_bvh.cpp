// The kernel variants (--slabs, --rcp, --precision) in bvh2, bvh4 and bvh8,
// single rays, packets of every compiled width and count_traversal:
// (a) robust slabs with exact or approximate reciprocals, float or double,
//     agree with the brute-force oracle run with the same primitive kernels
//     and precision (the oracle has no boxes, so slabs and rcp do not apply);
// (b) packets give the single ray's answers, bit for bit, for every variant
//     (but which of two tied primitives, see count_unlike_single);
// (c) plain slabs never report a hit the oracle does not have, and lose at
//     most a stated few on random rays (the count is printed);
// (d) adversarial rays (aimed exactly at mesh vertices and edge points,
//     axis-parallel with +-0 components, from box faces parallel to them):
//     robust slabs, watertight triangles and exact reciprocals lose no hit
//     (Ize, "Robust BVH Ray Traversal", JCGT 2013);
// (e) far from the origin, --precision double gives t closer to the double
//     oracle than float does (max error in float ulps).
#include <gtest/gtest.h>
#include "tests/test_paths.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/brute/brute_force.h"
#include "measure/ray_sets.h"
#include "scene/load.h"
#include "tests/oracle_harness.h"

namespace raypack {
namespace {

using namespace oracle_harness;

Scene load(const std::string& spec) {
    return load_scene(spec.rfind("gen:", 0) == 0 ? spec : std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + spec);
}

std::vector<std::string> bvh_kinds() {
    std::vector<std::string> kinds;
    for (const char* k : accel_kinds())
        if (std::string(k).rfind("bvh", 0) == 0) kinds.push_back(k);
    return kinds;
}

struct Variant {
    const char* name;
    SlabMethod slabs;
    RcpMethod rcp;
    Precision precision;
};

constexpr Variant kRobustExactFloat{"robust+exact+float", SlabMethod::Robust, RcpMethod::Exact, Precision::Float};
constexpr Variant kRobustExactDouble{"robust+exact+double", SlabMethod::Robust, RcpMethod::Exact, Precision::Double};
constexpr Variant kRobustApproxFloat{"robust+approx+float", SlabMethod::Robust, RcpMethod::Approx, Precision::Float};
constexpr Variant kRobustApproxDouble{"robust+approx+double", SlabMethod::Robust, RcpMethod::Approx,
                                      Precision::Double};
constexpr Variant kPlainExactFloat{"plain+exact+float", SlabMethod::Plain, RcpMethod::Exact, Precision::Float};
constexpr Variant kPlainApproxDouble{"plain+approx+double", SlabMethod::Plain, RcpMethod::Approx, Precision::Double};

KernelChoice kernels_of(const Variant& v, TriangleMethod triangle = TriangleMethod::Moeller) {
    KernelChoice k;
    k.triangle = triangle;
    k.slabs = v.slabs;
    k.rcp = v.rcp;
    k.precision = v.precision;
    return k;
}

/// Random origins in the grown scene box, random directions, a third with a
/// finite tfar, a seventh with a +-0 component.
std::vector<Rayf> random_rays_with_zeros(const Scene& scene, std::mt19937& rng, int n) {
    const Box3f box = grown(scene_bounds(scene), 0.1f);
    std::uniform_real_distribution<float> u(0, 1);
    std::vector<Rayf> rays(static_cast<std::size_t>(n));
    for (int i = 0; i < n; ++i) {
        rays[i].org = random_point(rng, box);
        rays[i].dir = random_direction(rng);
        if (i % 7 == 0) rays[i].dir[i % 3] = signed_zero(rng);
        if (i % 3 == 0) rays[i].tfar = u(rng) * length(box.extent());
    }
    return rays;
}

/// Rays aimed exactly at triangle vertices and edge points from random
/// origins, axis-parallel rays (+-0 in the other components) through
/// vertices, and rays from a face of a primitive's box (a plane of the BVH's
/// boxes) with the direction component along its normal +-0.
std::vector<Rayf> adversarial_rays(const Scene& scene, std::mt19937& rng, int n) {
    std::vector<Rayf> rays;
    const std::size_t prims = scene.primitive_count();
    if (prims == 0) return rays;
    const Box3f box = grown(scene_bounds(scene), 0.5f);
    std::uniform_real_distribution<float> u(0, 1);
    const float reach = 2.0f * length(box.extent());
    while (int(rays.size()) < n) {
        const std::uint32_t p = std::uint32_t(rng() % prims);
        const Box3f pb = primitive_bounds(scene, p);
        const PrimRef ref = scene.prims[p];
        if (ref.kind == PrimKind::Triangle) {
            const Vec3f v[3] = {scene.triangles.p0[ref.index], scene.triangles.p1[ref.index],
                                scene.triangles.p2[ref.index]};
            const Vec3f& a = v[rng() % 3];
            const Vec3f& b = v[rng() % 3];
            const float s = float(rng() % 5) / 4.0f;  // vertex or an edge point
            const Vec3f target = a + (b - a) * s;
            Rayf r;
            r.org = random_point(rng, box);
            r.dir = target - r.org;
            rays.push_back(r);
            Rayf q;  // along an axis, through the vertex
            const int axis = int(rng() % 3);
            q.dir = {signed_zero(rng), signed_zero(rng), signed_zero(rng)};
            q.dir[axis] = rng() % 2 ? 1.0f : -1.0f;
            q.org = a;
            q.org[axis] = a[axis] - q.dir[axis] * reach;
            rays.push_back(q);
        }
        Rayf f;  // on a face of the primitive's box, parallel to it
        const int axis = int(rng() % 3);
        f.org = random_point(rng, grown(pb, 0.2f));
        f.org[axis] = rng() % 2 ? pb.hi[axis] : pb.lo[axis];
        f.dir = random_direction(rng);
        f.dir[axis] = signed_zero(rng);
        rays.push_back(f);
    }
    return rays;
}

std::vector<Hitf> closest(const Accel& accel, int width, const std::vector<Rayf>& rays) {
    std::vector<Hitf> hits(rays.size());
    accel.intersect_packets(width, rays, hits);
    return hits;
}

std::vector<std::uint8_t> occluded(const Accel& accel, int width, const std::vector<Rayf>& rays) {
    std::vector<std::uint8_t> occ(rays.size());
    accel.occluded_packets(width, rays, occ);
    return occ;
}

bool bits_equal(const Hitf& a, const Hitf& b) {
    auto bits = [](float f) { return std::bit_cast<std::uint32_t>(f); };
    if (a.prim != b.prim || bits(a.t) != bits(b.t)) return false;
    return !a.found() || (bits(a.u) == bits(b.u) && bits(a.v) == bits(b.v));
}

/// Packets against single rays: the same hit or miss, and the same
/// primitive with the same t, u, v bits. Another primitive is a tie the
/// visiting order decides (packets order children by their first lane): for
/// bvh2 only at bit-identical t (a ray aimed at a shared vertex or edge); for
/// the wide trees at t within relative 1e-5 (nearly coincident hits, see
/// accel/bvh/wide_packet_traversal.h).
std::size_t count_unlike_single(bool exact, const std::vector<Hitf>& single, const std::vector<Hitf>& packet,
                                std::string& first) {
    std::size_t bad = 0;
    for (std::size_t i = 0; i < single.size(); ++i) {
        const Hitf &s = single[i], &p = packet[i];
        bool ok = bits_equal(s, p);
        if (!ok && s.found() && p.found() && s.prim != p.prim)
            ok = exact ? std::bit_cast<std::uint32_t>(s.t) == std::bit_cast<std::uint32_t>(p.t)
                       : std::fabs(s.t - p.t) <= 1e-5f * std::max(std::fabs(s.t), std::fabs(p.t));
        if (!ok && ++bad <= 3)
            first += "\n  ray " + std::to_string(i) + ": single " + describe(s) + ", packet " + describe(p);
    }
    return bad;
}

// Scenes: small enough that the oracle keeps the file under its time budget,
// with triangles, spheres and cones between them.
const char* const kScenes[] = {"tetra.nff", "rings.nff", "gen:balls:1", "gen:tetra:3", "gen:mount:3"};

class KernelVariantsBvh : public ::testing::TestWithParam<std::string> {};

// (a) and (b), and count_traversal's answers, for the variants that must
// match the oracle; (b) and (c) for plain slabs.
TEST_P(KernelVariantsBvh, AgreeWithOracleAndPacketsEqualSingleRays) {
    const Scene scene = load(GetParam());
    ASSERT_GT(scene.primitive_count(), 0u);
    std::mt19937 rng(777);
    const std::vector<Rayf> camera = camera_ray_set(scene, 24, 24);
    const std::vector<Rayf> random = random_rays_with_zeros(scene, rng, 700);
    const std::vector<Rayf> hard = adversarial_rays(scene, rng, 300);
    const Variant variants[] = {kRobustExactFloat, kRobustExactDouble, kRobustApproxFloat,
                                kRobustApproxDouble, kPlainExactFloat, kPlainApproxDouble};
    for (const Variant& v : variants) {
        const KernelChoice kc = kernels_of(v);
        const bool plain = v.slabs == SlabMethod::Plain;
        const BruteForce brute(scene, kc);
        std::vector<Rayf> rays = camera;
        rays.insert(rays.end(), random.begin(), random.end());
        const std::vector<Hitf> truth = closest(brute, 1, rays);
        std::vector<Rayf> occ_rays =
            shadow_rays(scene, camera, std::vector<Hitf>(truth.begin(), truth.begin() + camera.size()));
        occ_rays.insert(occ_rays.end(), random.begin(), random.end());
        const std::vector<std::uint8_t> occ_truth = occluded(brute, 1, occ_rays);
        for (const std::string& kind : bvh_kinds()) {
            const auto accel = build_accel(scene, accel_config(kind, kc));
            SCOPED_TRACE(GetParam() + " " + kind + " " + v.name);
            const std::vector<Hitf> single = closest(*accel, 1, rays);
            const std::vector<std::uint8_t> single_occ = occluded(*accel, 1, occ_rays);
            if (!plain) {
                const Mismatches m = compare_hits(scene, rays, truth, single, 3);
                EXPECT_EQ(m.count, 0u) << "of " << rays.size() << " rays differ from brute force" << m.first;
                const Mismatches o = compare_occluded(scene, kc, occ_rays, occ_truth, single_occ, 3);
                EXPECT_EQ(o.count, 0u) << "of " << occ_rays.size() << " occlusion answers differ" << o.first;
            } else {
                // (c) Plain slabs may lose a box (and so a hit), never invent
                // one: a hit it reports is the oracle's or a farther one.
                std::size_t lost = 0;
                for (std::size_t i = 0; i < rays.size(); ++i) {
                    if (same_closest_hit(truth[i], single[i])) continue;
                    ++lost;
                    EXPECT_TRUE(truth[i].found() && (!single[i].found() || single[i].t >= truth[i].t))
                        << "ray " << i << ": " << describe(rays[i]) << "\n  brute " << describe(truth[i])
                        << ", plain " << describe(single[i]);
                }
                std::size_t lost_occ = 0;
                for (std::size_t i = 0; i < occ_rays.size(); ++i) {
                    if (occ_truth[i] == single_occ[i]) continue;
                    ++lost_occ;
                    EXPECT_TRUE(occ_truth[i]) << "plain slabs occluded a ray the oracle does not: "
                                              << describe(occ_rays[i]);
                }
                // The stated allowance: 1 in 200 (none seen in practice).
                EXPECT_LE(lost, rays.size() / 200) << "plain slabs lost too many closest hits";
                EXPECT_LE(lost_occ, occ_rays.size() / 200) << "plain slabs lost too many occlusions";
                if (lost + lost_occ != 0)
                    std::printf("[   NOTE   ] %s %s %s: plain slabs lost %zu of %zu closest hits, %zu of %zu "
                                "occlusions\n", GetParam().c_str(), kind.c_str(), v.name, lost, rays.size(), lost_occ,
                                occ_rays.size());
            }
            // count_traversal walks the single-ray traversal: the same answers.
            std::vector<Hitf> counted(rays.size());
            TraversalCounts counts;
            ASSERT_TRUE(accel->count_traversal(rays, false, counted, counts));
            for (std::size_t i = 0; i < rays.size(); ++i)
                if (!bits_equal(counted[i], single[i])) {
                    ADD_FAILURE() << "count_traversal differs on ray " << i << ": " << describe(counted[i]) << " vs "
                                  << describe(single[i]);
                    break;
                }
            std::vector<Hitf> counted_occ(occ_rays.size());
            ASSERT_TRUE(accel->count_traversal(occ_rays, true, counted_occ, counts));
            for (std::size_t i = 0; i < occ_rays.size(); ++i)
                ASSERT_EQ(counted_occ[i].found(), single_occ[i] != 0) << "count_traversal occlusion, ray " << i;
            // (b) Every packet width, on the oracle's rays and the adversarial ones.
            std::vector<Rayf> all = rays;
            all.insert(all.end(), hard.begin(), hard.end());
            all.resize(all.size() - 5);  // ragged last packets
            const std::vector<Hitf> single_all = closest(*accel, 1, all);
            const std::vector<std::uint8_t> single_all_occ = occluded(*accel, 1, all);
            for (int width : {4, 8, 16}) {
                const bool compiled = (width == 4 && kWidthCompiled<4>) || (width == 8 && kWidthCompiled<8>) ||
                                      (width == 16 && kWidthCompiled<16>);
                ASSERT_EQ(accel->supports_packet(width), compiled) << "width " << width;
                if (!compiled) continue;
                std::string first;
                EXPECT_EQ(count_unlike_single(kind == "bvh2", single_all, closest(*accel, width, all), first), 0u)
                    << "width " << width << ": of " << all.size() << " rays differ from single rays" << first;
                EXPECT_EQ(occluded(*accel, width, all), single_all_occ) << "width " << width << " occlusion";
            }
        }
    }
}

// (d) Robust slabs + watertight triangles + exact reciprocals lose no hit on
// rays aimed at vertices and edges, axis-parallel, or lying in box planes;
// the other slab/rcp combinations are measured on the same rays and printed.
TEST_P(KernelVariantsBvh, AdversarialRaysRobustLosesNoHit) {
    const Scene scene = load(GetParam());
    std::mt19937 rng(99);
    const std::vector<Rayf> rays = adversarial_rays(scene, rng, 1500);
    const Variant variants[] = {kRobustExactFloat, kRobustApproxFloat, kPlainExactFloat};
    for (const Variant& v : variants) {
        const KernelChoice kc = kernels_of(v, TriangleMethod::Watertight);
        const BruteForce brute(scene, kc);
        const std::vector<Hitf> truth = closest(brute, 1, rays);
        const std::vector<std::uint8_t> occ_truth = occluded(brute, 1, rays);
        for (const std::string& kind : bvh_kinds()) {
            const auto accel = build_accel(scene, accel_config(kind, kc));
            SCOPED_TRACE(GetParam() + " " + kind + " " + v.name + " watertight");
            const bool must_agree = v.slabs == SlabMethod::Robust && v.rcp == RcpMethod::Exact;
            std::size_t lost = 0;
            std::string first;
            for (int width : {1, 4, 8, 16}) {
                if (!accel->supports_packet(width)) continue;
                const std::vector<Hitf> got = closest(*accel, width, rays);
                const std::vector<std::uint8_t> occ = occluded(*accel, width, rays);
                std::size_t lost_here = 0;
                for (std::size_t i = 0; i < rays.size(); ++i) {
                    if (same_closest_hit(truth[i], got[i]) && occ[i] == occ_truth[i]) continue;
                    if (++lost_here <= 2 && must_agree)
                        first += "\n  width " + std::to_string(width) + " ray " + std::to_string(i) + ": " +
                                 describe(rays[i]) + "\n    brute " + describe(truth[i]) +
                                 (occ_truth[i] ? " occluded" : " clear") + ", got " + describe(got[i]) +
                                 (occ[i] ? " occluded" : " clear");
                }
                lost = std::max(lost, lost_here);
            }
            if (must_agree)
                EXPECT_EQ(lost, 0u) << "of " << rays.size() << " adversarial rays" << first;
            else if (lost != 0)
                std::printf("[   NOTE   ] %s %s %s: %zu of %zu adversarial rays lose their hit or occlusion\n",
                            GetParam().c_str(), kind.c_str(), v.name, lost, rays.size());
        }
    }
}

std::string spec_name(const ::testing::TestParamInfo<std::string>& info) {
    std::string s = info.param;
    std::replace_if(s.begin(), s.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
    return s;
}

INSTANTIATE_TEST_SUITE_P(, KernelVariantsBvh,
                         ::testing::ValuesIn(std::vector<std::string>(std::begin(kScenes), std::end(kScenes))),
                         spec_name);

// (e) Far from the origin (mount moved by 3e4 along each axis), float
// Moeller-Trumbore loses digits to cancellation; --precision double runs the
// same test in double and rounds t once, so its error against the double
// oracle is at most half an ulp plus the float ray's own rounding.
TEST(KernelVariantsBvhPrecision, DoubleIsCloserToTheDoubleOracleFarFromOrigin) {
    const Scene near = load("gen:mount:3");
    Scene far;
    const Vec3f offset{3e4f, 3e4f, 3e4f};
    far.materials = near.materials;
    for (std::size_t i = 0; i < near.triangles.p0.size(); ++i)
        far.add_triangle(near.triangles.p0[i] + offset, near.triangles.p1[i] + offset, near.triangles.p2[i] + offset, 0);
    far.update_features();
    ASSERT_GT(far.primitive_count(), 100u);
    // Rays from around the scene at random primitives' centroids.
    std::mt19937 rng(5);
    const Box3f box = grown(scene_bounds(far), 0.5f);
    std::vector<Rayf> rays;
    for (int i = 0; i < 400; ++i) {
        Rayf r;
        r.org = random_point(rng, box);
        r.dir = primitive_bounds(far, std::uint32_t(rng() % far.primitive_count())).center() - r.org;
        rays.push_back(r);
    }
    const BruteForce oracle(far, KernelChoice{});
    std::vector<Hit<double>> ref;
    for (const Rayf& r : rays)
        ref.push_back(oracle.intersect_double(Ray<double>{Vec3<double>(r.org), Vec3<double>(r.dir), double(r.tnear),
                                                          double(r.tfar)}));
    for (const std::string& kind : bvh_kinds()) {
        double max_ulps[2] = {0, 0};
        std::size_t compared[2] = {0, 0};
        for (int d = 0; d < 2; ++d) {
            const Variant& v = d ? kRobustExactDouble : kRobustExactFloat;
            const auto accel = build_accel(far, accel_config(kind, kernels_of(v)));
            for (int width : {1, 8}) {
                if (!accel->supports_packet(width)) continue;
                const std::vector<Hitf> got = closest(*accel, width, rays);
                for (std::size_t i = 0; i < rays.size(); ++i) {
                    if (!got[i].found() || got[i].prim != ref[i].prim) continue;
                    const float rt = float(ref[i].t);
                    const double ulp = double(std::nextafter(rt, INFINITY)) - double(rt);
                    max_ulps[d] = std::max(max_ulps[d], std::fabs(double(got[i].t) - ref[i].t) / ulp);
                    ++compared[d];
                }
            }
        }
        std::printf("[   NOTE   ] far mount %s: max |t - t_double| %.3g ulps in float, %.3g with --precision double "
                    "(%zu, %zu hits)\n", kind.c_str(), max_ulps[0], max_ulps[1], compared[0], compared[1]);
        EXPECT_GT(compared[1], 200u) << kind;
        EXPECT_LE(max_ulps[1], 1.0) << kind;
        EXPECT_GT(max_ulps[0], 2.0 * max_ulps[1]) << kind << ": float should be measurably worse far from the origin";
    }
}

}  // namespace
}  // namespace raypack
