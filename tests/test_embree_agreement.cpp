// raypack's bvh2 against Embree 3, an independent tracer with its own BVH and
// its own primitive tests, on full-resolution camera rays and shadow rays of
// every shared scene.
#include <gtest/gtest.h>
#include "tests/test_paths.h"

#ifdef RAYPACK_HAVE_EMBREE

#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "accel/embree/embree_accel.h"
#include "render/camera_rays.h"
#include "scene/load.h"
#include "tests/oracle_harness.h"

namespace raypack {
namespace {

constexpr double kRequired = 0.999;
constexpr float kRelT = 1e-4f;


std::vector<Hitf> trace(const Accel& accel, const std::vector<Rayf>& rays) {
    std::vector<Hitf> hits(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](const auto& r) {
        accel.intersect(std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                        std::span<Hitf>(hits).subspan(r.begin(), r.size()));
    });
    return hits;
}

std::vector<std::uint8_t> trace_occluded(const Accel& accel, const std::vector<Rayf>& rays) {
    std::vector<std::uint8_t> occ(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 256), [&](const auto& r) {
        accel.occluded(std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                       std::span<std::uint8_t>(occ).subspan(r.begin(), r.size()));
    });
    return occ;
}

std::string describe(const Rayf& r) {
    std::ostringstream os;
    os << std::hexfloat << "org (" << r.org.x << ", " << r.org.y << ", " << r.org.z << ") dir (" << r.dir.x << ", "
       << r.dir.y << ", " << r.dir.z << ") tnear " << r.tnear << " tfar " << r.tfar;
    return os.str();
}

const char* kind_name(const Scene& s, std::uint32_t prim) {
    if (prim == kNoPrim) return "miss";
    switch (s.prims[prim].kind) {
        case PrimKind::Sphere: return "sphere";
        case PrimKind::Triangle: return "triangle";
        case PrimKind::Cone: return "cone";
        case PrimKind::HeightField: return "height field";
        case PrimKind::Instance: return "instance";
    }
    return "?";
}

std::string describe(const Scene& s, const Hitf& h) {
    if (!h.found()) return "miss";
    std::ostringstream os;
    os << kind_name(s, h.prim) << " " << h.prim << " t " << std::setprecision(9) << h.t;
    return os.str();
}

/// Disagreements by the kind of primitive involved (either tracer's hit).
struct Tally {
    std::size_t rays = 0, disagree = 0;
    std::array<std::size_t, 3> by_kind{};
    std::string examples;
    double fraction() const { return rays ? 1.0 - double(disagree) / double(rays) : 1.0; }
    std::string kinds() const {
        return "sphere " + std::to_string(by_kind[0]) + ", triangle " + std::to_string(by_kind[1]) + ", cone " +
               std::to_string(by_kind[2]);
    }
};

class EmbreeAgreement : public ::testing::TestWithParam<std::string> {};

TEST_P(EmbreeAgreement, CameraAndShadowRays) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    AccelConfig config;
    const std::unique_ptr<Accel> bvh = build_accel(scene, config);
    const EmbreeAccel embree(scene);

    const int size = 512;
    const CameraFrame f = make_camera_frame(scene.camera, size, size);
    std::vector<Rayf> rays;
    rays.reserve(std::size_t(size) * size);
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) rays.push_back(camera_ray(f, float(x) + 0.5f, float(y) + 0.5f));
    const std::vector<Hitf> a = trace(*bvh, rays), b = trace(embree, rays);

    Tally cam;
    cam.rays = rays.size();
    for (std::size_t i = 0; i < rays.size(); ++i) {
        const bool ok = a[i].found() == b[i].found() &&
                        (!a[i].found() || std::fabs(a[i].t - b[i].t) <= kRelT * std::max(a[i].t, b[i].t));
        if (ok) continue;
        ++cam.disagree;
        for (std::uint32_t p : {a[i].prim, b[i].prim})
            if (p != kNoPrim) ++cam.by_kind[int(scene.prims[p].kind)];
        if (cam.disagree <= 5)
            cam.examples += "\n  pixel (" + std::to_string(i % size) + ", " + std::to_string(i / size) +
                            "): " + describe(rays[i]) + "\n    bvh2 " + describe(scene, a[i]) + ", embree " +
                            describe(scene, b[i]);
    }

    // Shadow rays from raypack's camera hits to the first light; the origin is
    // the hit point itself and tnear keeps the surface from shadowing itself.
    std::vector<Rayf> shadows;
    std::vector<std::uint32_t> shadow_from;
    if (!scene.lights.empty()) {
        const Vec3f light = scene.lights[0].position;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            if (!a[i].found()) continue;
            Rayf s;
            s.org = rays[i].org + rays[i].dir * a[i].t;
            s.dir = light - s.org;
            s.tnear = 1e-4f;
            s.tfar = 1.0f - 1e-4f;
            shadows.push_back(s);
            shadow_from.push_back(a[i].prim);
        }
    }
    const std::vector<std::uint8_t> sa = trace_occluded(*bvh, shadows), sb = trace_occluded(embree, shadows);
    Tally sh;
    sh.rays = shadows.size();
    for (std::size_t i = 0; i < shadows.size(); ++i) {
        if (sa[i] == sb[i]) continue;
        ++sh.disagree;
        // Which primitive blocks the ray, according to a closest-hit query of each.
        const Hitf ha = bvh->intersect1(shadows[i]), hb = embree.intersect1(shadows[i]);
        for (std::uint32_t p : {ha.prim, hb.prim})
            if (p != kNoPrim) ++sh.by_kind[int(scene.prims[p].kind)];
        if (sh.disagree <= 5)
            sh.examples += "\n  from " + std::string(kind_name(scene, shadow_from[i])) + " " +
                           std::to_string(shadow_from[i]) + ": " + describe(shadows[i]) + "\n    bvh2 " +
                           (sa[i] ? "occluded by " + describe(scene, ha) : std::string("clear")) + ", embree " +
                           (sb[i] ? "occluded by " + describe(scene, hb) : std::string("clear"));
    }

    std::cout << std::fixed << std::setprecision(6) << "[ embree   ] " << std::setw(10) << GetParam()
              << "  camera " << cam.fraction() << " (" << cam.disagree << " of " << cam.rays << ")"
              << "  shadow " << sh.fraction() << " (" << sh.disagree << " of " << sh.rays << ")" << std::defaultfloat
              << "\n";
    if (cam.disagree) std::cout << "             camera disagreements involve " << cam.kinds() << "\n";
    if (sh.disagree) std::cout << "             shadow disagreements involve " << sh.kinds() << "\n";

    EXPECT_GE(cam.fraction(), kRequired) << GetParam() << " camera rays: " << cam.kinds() << cam.examples;
    EXPECT_GE(sh.fraction(), kRequired) << GetParam() << " shadow rays: " << sh.kinds() << sh.examples;
}

std::string param_name(const ::testing::TestParamInfo<std::string>& info) {
    std::string s = info.param;
    std::replace(s.begin(), s.end(), '.', '_');
    return s;
}

INSTANTIATE_TEST_SUITE_P(, EmbreeAgreement, ::testing::ValuesIn(oracle_harness::shared_scene_files()), param_name);

// ---- Packets: rtcIntersect4/8/16 and rtcOccluded4/8/16 ------------------------------

/// In chunks of 61 rays, so that every width ends each chunk with a ragged
/// packet (inactive lanes).
std::vector<Hitf> trace_packets(const Accel& accel, int width, const std::vector<Rayf>& rays) {
    std::vector<Hitf> hits(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 61), [&](const auto& r) {
        accel.intersect_packets(width, std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                                std::span<Hitf>(hits).subspan(r.begin(), r.size()));
    });
    return hits;
}

std::vector<std::uint8_t> trace_occluded_packets(const Accel& accel, int width, const std::vector<Rayf>& rays) {
    std::vector<std::uint8_t> occ(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), 61), [&](const auto& r) {
        accel.occluded_packets(width, std::span<const Rayf>(rays).subspan(r.begin(), r.size()),
                               std::span<std::uint8_t>(occ).subspan(r.begin(), r.size()));
    });
    return occ;
}

TEST_P(EmbreeAgreement, PacketsMatchSingleRays) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    const EmbreeAccel embree(scene);
    AccelConfig config;
    const std::unique_ptr<Accel> bvh = build_accel(scene, config);
    // Camera rays, then random rays from inside the scene box.
    const int size = 128;
    const CameraFrame f = make_camera_frame(scene.camera, size, size);
    std::vector<Rayf> rays;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) rays.push_back(camera_ray(f, float(x) + 0.5f, float(y) + 0.5f));
    std::mt19937 rng(77);
    std::normal_distribution<float> g;
    std::uniform_real_distribution<float> u(0, 1);
    const Box3f box = scene_bounds(scene);
    for (int i = 0; i < 3001; ++i) {
        Rayf r;
        const Vec3f e = box.extent();
        r.org = {box.lo.x + u(rng) * e.x, box.lo.y + u(rng) * e.y, box.lo.z + u(rng) * e.z};
        r.dir = {g(rng), g(rng), g(rng)};
        rays.push_back(r);
    }
    const std::vector<Hitf> single = trace(embree, rays);
    const float scene_size = length(box.extent());
    // Shadow rays from the single-ray hits to the first light.
    std::vector<Rayf> shadows;
    for (std::size_t i = 0; i < rays.size() && !scene.lights.empty(); ++i) {
        if (!single[i].found()) continue;
        Rayf s;
        s.org = rays[i].org + rays[i].dir * single[i].t;
        s.dir = scene.lights[0].position - s.org;
        s.tnear = 1e-4f;
        s.tfar = 1.0f - 1e-4f;
        shadows.push_back(s);
    }
    shadows.insert(shadows.end(), rays.begin(), rays.end());
    const std::vector<std::uint8_t> single_occ = trace_occluded(embree, shadows);
    const std::vector<Hitf> ours = trace(*bvh, rays);

    for (int width : {4, 8, 16}) {
        SCOPED_TRACE("rtcIntersect" + std::to_string(width) + " on " + GetParam());
        ASSERT_TRUE(embree.supports_packet(width));
        const std::vector<Hitf> packet = trace_packets(embree, width, rays);
        std::size_t unlike = 0, unlike_ours = 0;
        std::string examples;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Hitf &a = single[i], &b = packet[i];
            // t within relative 1e-6, or, for hits right at the origin, the
            // hit points within 1e-6 of the scene's size: Embree's packet and
            // single-ray sphere tests round differently, e.g. on mount.nff
            // t = 0.00265879929 vs 0.00265880674 from an origin 0.005 inside
            // a sphere's surface (cancellation in either form).
            const bool ok = a.found() == b.found() &&
                            (!a.found() || std::fabs(a.t - b.t) <= 1e-6f * std::max(a.t, b.t) ||
                             std::fabs(a.t - b.t) * length(rays[i].dir) <= 1e-6f * scene_size);
            if (!ok && ++unlike <= 3)
                examples += "\n  " + describe(rays[i]) + ": single " + describe(scene, a) + ", packet " +
                            describe(scene, b);
            const Hitf& c = ours[i];
            if (c.found() != b.found() || (c.found() && std::fabs(c.t - b.t) > kRelT * std::max(c.t, b.t)))
                ++unlike_ours;
        }
        EXPECT_EQ(unlike, 0u) << "closest hits differ from rtcIntersect1" << examples;
        // Against raypack, as the single-ray comparison above.
        EXPECT_GE(1.0 - double(unlike_ours) / double(rays.size()), kRequired);
        const std::vector<std::uint8_t> occ = trace_occluded_packets(embree, width, shadows);
        std::size_t occ_unlike = 0;
        for (std::size_t i = 0; i < shadows.size(); ++i) occ_unlike += occ[i] != single_occ[i];
        EXPECT_EQ(occ_unlike, 0u) << "of " << shadows.size() << " occlusion answers differ from rtcOccluded1";
    }
}

/// A packet whose rays share one origin runs in Embree's coherent context.
/// The camera rays must get the same answers as in the incoherent context, at
/// every width, also when a ray from elsewhere makes one packet incoherent.
TEST_P(EmbreeAgreement, CoherentContextMatchesIncoherent) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + GetParam());
    const EmbreeAccel embree(scene);
    EmbreeOptions incoherent_options;
    incoherent_options.context = EmbreeContext::Incoherent;
    const EmbreeAccel incoherent(scene, incoherent_options);
    const int size = 96;
    const CameraFrame f = make_camera_frame(scene.camera, size, size);
    std::vector<Rayf> rays;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) rays.push_back(camera_ray(f, float(x) + 0.5f, float(y) + 0.5f));
    rays[size * size / 2 + 3].org = rays[0].org + Vec3f{1.0f, 1.0f, 1.0f};  // one packet loses its single origin
    for (int width : {1, 4, 8, 16}) {
        SCOPED_TRACE("width " + std::to_string(width) + " on " + GetParam());
        std::vector<Hitf> a(rays.size()), b(rays.size());
        embree.intersect_packets(width, rays, a);
        incoherent.intersect_packets(width, rays, b);
        std::vector<std::uint8_t> oa(rays.size()), ob(rays.size());
        embree.occluded_packets(width, rays, oa);
        incoherent.occluded_packets(width, rays, ob);
        std::size_t unlike = 0, hits = 0, occ_unlike = 0;
        for (std::size_t i = 0; i < rays.size(); ++i) {
            hits += a[i].found();
            unlike += a[i].found() != b[i].found() || a[i].prim != b[i].prim ||
                      std::fabs(a[i].t - b[i].t) > 1e-6f * std::max(a[i].t, b[i].t) || a[i].u != b[i].u ||
                      a[i].v != b[i].v;
            occ_unlike += oa[i] != ob[i];
        }
        EXPECT_GT(hits, 0u) << "the camera sees nothing: the test would prove nothing";
        EXPECT_EQ(unlike, 0u) << "closest hits differ between the coherent and incoherent context";
        EXPECT_EQ(occ_unlike, 0u) << "occlusion differs between the coherent and incoherent context";
    }
}

// ---- Semantics the scene comparison depends on ----------------------------------

Scene single(PrimKind kind) {
    Scene s;
    s.materials.push_back({});
    switch (kind) {
        case PrimKind::Sphere: s.add_sphere({0, 0, 0}, 2, 0); break;
        case PrimKind::Triangle: s.add_triangle({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, 0); break;
        case PrimKind::Cone: s.add_cone({0, 0, 0}, 1, {0, 0, 2}, 1, 0); break;
        case PrimKind::HeightField: ADD_FAILURE() << "the Embree backend has no height fields"; break;
        case PrimKind::Instance: ADD_FAILURE() << "the Embree backend has no instances"; break;
    }
    s.update_features();
    return s;
}

Rayf ray(Vec3f org, Vec3f dir, float tnear = 0, float tfar = std::numeric_limits<float>::infinity()) {
    Rayf r;
    r.org = org;
    r.dir = dir;
    r.tnear = tnear;
    r.tfar = tfar;
    return r;
}

TEST_F(EmbreeAgreement, ConesAreOpenLikeNff) {
    // NFF cones have no caps (Embree's own cone curves would add them): along
    // the axis of an open cylinder, no hit.
    const Scene s = single(PrimKind::Cone);
    const EmbreeAccel e(s);
    EXPECT_FALSE(e.intersect1(ray({0, 0, -5}, {0, 0, 1})).found());
    EXPECT_FALSE(e.intersect1(ray({0.5f, 0.25f, 7}, {0, 0, -1})).found());
    EXPECT_FALSE(e.occluded1(ray({0, 0, -5}, {0, 0, 1})));
    // From the side: the wall at the analytic distance, u along the axis.
    const Hitf h = e.intersect1(ray({-5, 0, 1}, {1, 0, 0}));
    ASSERT_TRUE(h.found());
    EXPECT_EQ(h.prim, 0u);
    EXPECT_NEAR(h.t, 4.0f, 1e-5f);
    EXPECT_NEAR(h.u, 0.5f, 1e-5f);
    // From inside: the far wall.
    const Hitf in = e.intersect1(ray({0, 0, 1}, {1, 0, 0}));
    ASSERT_TRUE(in.found());
    EXPECT_NEAR(in.t, 1.0f, 1e-5f);
    // Beyond the ends: nothing.
    EXPECT_FALSE(e.intersect1(ray({-5, 0, 3}, {1, 0, 0})).found());
}

TEST_F(EmbreeAgreement, ConesWithUnnormalisedDirections) {
    // Embree 3.13.5's cone curves got this wrong (see embree_accel.cpp): a
    // thin cylinder along y seen almost end-on by a camera-style ray whose
    // direction is not unit length. The ray passes > 0.85 from the axis.
    Scene s;
    s.materials.push_back({});
    s.add_cone({-6.75319f, 17.7447f, 6}, 0.07412f, {-6.75319f, 18.8391f, 6}, 0.07412f, 0);
    s.update_features();
    const EmbreeAccel e(s);
    const Rayf r = ray({-1, -2.61313009f, 0.5f}, {-0.295866817f, 1, 0.309016466f}, 1);
    EXPECT_FALSE(e.intersect1(r).found());
    EXPECT_FALSE(e.occluded1(r));
    // Scaling the direction scales t and nothing else.
    const Rayf side = ray({-6.75319f, 18.2f, 0}, {0, 0, 0.5f});
    const Hitf h = e.intersect1(side);
    ASSERT_TRUE(h.found());
    EXPECT_NEAR(h.t, (6.0f - 0.07412f) / 0.5f, 1e-4f);
}

TEST_F(EmbreeAgreement, PointedConeAndSwappedEnds) {
    Scene s;
    s.materials.push_back({});
    s.add_cone({0, 0, 0}, 1, {0, 0, 1}, 0, 0);
    s.add_cone({5, 0, 1}, 0, {5, 0, 0}, 1, 0);
    s.update_features();
    const EmbreeAccel e(s);
    const Hitf h0 = e.intersect1(ray({-5, 0, 0.5f}, {1, 0, 0}));
    ASSERT_TRUE(h0.found());
    EXPECT_EQ(h0.prim, 0u);
    EXPECT_NEAR(h0.t, 4.5f, 1e-5f);
    const Hitf h1 = e.intersect1(ray({5, -5, 0.5f}, {0, 1, 0}));
    ASSERT_TRUE(h1.found());
    EXPECT_EQ(h1.prim, 1u);
    EXPECT_NEAR(h1.t, 4.5f, 1e-5f);
    // The mirrored nappe beyond the apex is not part of the cone.
    EXPECT_FALSE(e.intersect1(ray({-5, 0, 1.5f}, {1, 0, 0})).found());
}

TEST_F(EmbreeAgreement, SpheresAndTrianglesFollowRaypackConventions) {
    const Scene sp = single(PrimKind::Sphere);
    const EmbreeAccel es(sp);
    EXPECT_NEAR(es.intersect1(ray({0, 0, -5}, {0, 0, 1})).t, 3.0f, 1e-6f);
    EXPECT_NEAR(es.intersect1(ray({0, 0, 1}, {0, 0, 1})).t, 1.0f, 1e-6f);  // from inside: far side
    EXPECT_NEAR(es.intersect1(ray({0, 0, -5}, {0, 0, 2})).t, 1.5f, 1e-6f);  // t in units of dir
    EXPECT_NEAR(es.intersect1(ray({0, 0, -5}, {0, 0, 1}, 4.0f)).t, 7.0f, 1e-6f);  // tnear
    EXPECT_FALSE(es.intersect1(ray({0, 0, -5}, {0, 0, 1}, 0, 2.5f)).found());      // tfar
    EXPECT_FALSE(es.intersect1(ray({0, 0, 5}, {0, 0, 1})).found());                // behind

    const Scene tr = single(PrimKind::Triangle);
    const EmbreeAccel et(tr);
    for (float z : {-2.0f, 2.0f}) {  // both sides
        const Hitf h = et.intersect1(ray({0.25f, 0.5f, z}, {0, 0, -z / 2}));
        ASSERT_TRUE(h.found());
        EXPECT_NEAR(h.t, 2.0f, 1e-6f);
        EXPECT_NEAR(h.u, 0.25f, 1e-6f);  // weight of the second vertex
        EXPECT_NEAR(h.v, 0.5f, 1e-6f);   // weight of the third
    }
}

TEST_F(EmbreeAgreement, GlobalPrimitiveNumbers) {
    // Kinds interleaved in definition order: hits must report the scene-global
    // numbers, not Embree's per-geometry ids.
    Scene s;
    s.materials.push_back({});
    s.add_sphere({0, 0, 10}, 1, 0);                         // 0
    s.add_triangle({-1, -1, 20}, {1, -1, 20}, {0, 1, 20}, 0);  // 1
    s.add_cone({0, 0, 29}, 1, {0, 0, 31}, 1, 0);            // 2 (hit from the side)
    s.add_sphere({0, 0, 40}, 1, 0);                         // 3
    s.add_triangle({-1, -1, 50}, {1, -1, 50}, {0, 1, 50}, 0);  // 4
    s.update_features();
    const EmbreeAccel e(s);
    EXPECT_EQ(e.stats().name, "embree");
    const Hitf h0 = e.intersect1(ray({0, 0, 0}, {0, 0, 1}));
    EXPECT_EQ(h0.prim, 0u);
    EXPECT_EQ(e.intersect1(ray({0, 0, 15}, {0, 0, 1})).prim, 1u);
    EXPECT_EQ(e.intersect1(ray({-5, 0, 30}, {1, 0, 0})).prim, 2u);
    EXPECT_EQ(e.intersect1(ray({0, 0, 35}, {0, 0, 1})).prim, 3u);
    EXPECT_EQ(e.intersect1(ray({0, 0, 45}, {0, 0, 1})).prim, 4u);
    EXPECT_FALSE(e.intersect1(ray({0, 0, 55}, {0, 0, 1})).found());
}

TEST_F(EmbreeAgreement, ReportsNativePacketWidths) {
    const Scene s = single(PrimKind::Triangle);
    const EmbreeAccel e(s);
    EXPECT_TRUE(e.native_packet(1));
    EXPECT_FALSE(e.supports_packet(2));
    const std::string& b = e.stats().builder;
    ASSERT_NE(b.find("packets 4/8/16 "), std::string::npos) << b;
    std::string want;
    for (int w : {4, 8, 16}) want += std::string(w == 4 ? "" : "/") + (e.native_packet(w) ? "native" : "emulated");
    EXPECT_NE(b.find(want), std::string::npos) << b;
    // A ragged packet: 3 rays in a packet of 16, the first and last hit.
    std::vector<Rayf> rays = {ray({0.25f, 0.25f, 1}, {0, 0, -1}), ray({5, 5, 1}, {0, 0, -1}),
                              ray({0.1f, 0.1f, -1}, {0, 0, 1})};
    std::vector<Hitf> hits(3);
    e.intersect_packets(16, rays, hits);
    EXPECT_EQ(hits[0].prim, 0u);
    EXPECT_FALSE(hits[1].found());
    EXPECT_NEAR(hits[2].t, 1.0f, 1e-6f);
    std::vector<std::uint8_t> occ(3);
    e.occluded_packets(16, rays, occ);
    EXPECT_EQ(occ, (std::vector<std::uint8_t>{1, 0, 1}));
}

/// `embree` is Embree's fast mode and `embree-robust` its robust one, each at
/// the build quality asked for; every combination answers the camera and
/// shadow rays of a triangle scene as the default does but for a few rays at
/// shared edges, and says how it was run.
TEST_F(EmbreeAgreement, ModesAndBuildQualities) {
    const Scene scene = load_scene(std::string(RAYPACK_SOURCE_DIR) + "/scenes/tetra.nff");
    const int size = 128;
    const CameraFrame f = make_camera_frame(scene.camera, size, size);
    std::vector<Rayf> rays;
    for (int y = 0; y < size; ++y)
        for (int x = 0; x < size; ++x) rays.push_back(camera_ray(f, float(x) + 0.5f, float(y) + 0.5f));
    const EmbreeAccel reference(scene);
    EXPECT_EQ(reference.stats().name, "embree");
    EXPECT_EQ(reference.stats().builder.rfind("fast mode, medium quality, ", 0), 0u) << reference.stats().builder;
    const std::vector<Hitf> want = trace(reference, rays);
    for (const char* kind : {"embree", "embree-robust"})
        for (const char* quality : {"low", "medium", "high"}) {
            SCOPED_TRACE(std::string(kind) + " " + quality);
            AccelConfig config = accel_config(kind);
            config.build_quality = quality;
            const auto accel = build_accel(scene, config);
            EXPECT_EQ(accel->stats().name, kind);
            const std::string mode = std::string(kind) == "embree" ? "fast" : "robust";
            EXPECT_EQ(accel->stats().builder.rfind(mode + " mode, " + quality + " quality", 0), 0u)
                << accel->stats().builder;
            const std::vector<Hitf> got = trace(*accel, rays);
            std::size_t unlike = 0, hits = 0;
            for (std::size_t i = 0; i < rays.size(); ++i) {
                hits += want[i].found();
                unlike += want[i].found() != got[i].found() ||
                          (want[i].found() && std::fabs(want[i].t - got[i].t) > kRelT * want[i].t);
            }
            EXPECT_GT(hits, rays.size() / 8);  // tetra covers about a fifth of the frame
            EXPECT_LE(double(unlike), (1.0 - kRequired) * double(rays.size())) << unlike << " rays differ";
        }
    EXPECT_THROW(embree_options(false, "ultra"), std::invalid_argument);
    EXPECT_TRUE(embree_options(true, "high").robust);
    EXPECT_EQ(embree_options(false, "low").quality, RTC_BUILD_QUALITY_LOW);
}

TEST_F(EmbreeAgreement, ConePacketsUseEveryLane) {
    // User geometry called with N > 1: each lane its own answer.
    const Scene s = single(PrimKind::Cone);
    const EmbreeAccel e(s);
    std::vector<Rayf> rays;
    for (int i = 0; i < 16; ++i) rays.push_back(ray({-5, 0, 0.1f * float(i)}, {1, 0, 0}));
    for (int width : {4, 8, 16}) {
        std::vector<Hitf> hits(rays.size());
        e.intersect_packets(width, rays, hits);
        for (int i = 0; i < 16; ++i) {
            SCOPED_TRACE("width " + std::to_string(width) + " lane " + std::to_string(i));
            const Hitf one = e.intersect1(rays[i]);
            EXPECT_EQ(hits[i].found(), one.found());
            EXPECT_EQ(hits[i].t, one.t);
        }
        std::vector<std::uint8_t> occ(rays.size());
        e.occluded_packets(width, rays, occ);
        for (int i = 0; i < 16; ++i) EXPECT_EQ(occ[i] != 0, e.occluded1(rays[i]));
    }
}

}  // namespace
}  // namespace raypack

#else  // !RAYPACK_HAVE_EMBREE

TEST(EmbreeAgreement, Skipped) {
    GTEST_SKIP() << "built without Embree 3 (RAYPACK_HAVE_EMBREE undefined): install libembree-dev and "
                    "reconfigure, or pass -DRAYPACK_WITH_EMBREE=ON to make its absence an error";
}

#endif
