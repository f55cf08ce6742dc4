// The BVH4/BVH8 packet traversal (accel/bvh/wide_packet.h) against the
// single-ray wide traversal and the brute-force oracle, for K = 4, 8, 16,
// three switch points (never fall back: pure packets; the default; always:
// every lane alone below the root) and packets alone or in groups of 4 and
// 16 that share one walk (accel/bvh/wide_group_traversal.h), with and
// without the any-hit walks' occluder cache (accel/bvh/wide_traversal.h).
//
// Against the single-ray traversal (see wide_packet_traversal.h for why):
// the same hit or miss and the same occlusion on every ray; for the same
// primitive the same t, u, v bit for bit; another primitive only at t within
// relative 1e-5 of the single ray's (two nearly coincident hits, of which
// the visiting order decides the one that survives culling against the
// shrinking tfar; seen on rays aimed exactly at box corners). Against the oracle: the same hit or miss, t
// within relative 1e-5, the same occlusion, where a difference is only
// accepted if the single-ray traversal gives the very same answer (those
// cases, hits outside the primitive's own box, are test_wide_bvh.cpp's).
// Streams of rays (accel/bvh/wide_stream_traversal.h) are held to the same.
#include <gtest/gtest.h>
#include "tests/test_paths.h"
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <functional>
#include <random>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "accel/brute/brute_force.h"
#include "accel/bvh/wide_bvh_accel.h"
#include "measure/ray_sets.h"
#include "scene/load.h"
#include "tests/oracle_harness.h"

namespace raypack {
namespace {

using namespace oracle_harness;

std::vector<std::string> scene_specs() {
    std::vector<std::string> specs;
    for (const auto& e : std::filesystem::directory_iterator(std::string(RAYPACK_SOURCE_DIR) + "/scenes"))
        if (e.path().extension() == ".nff") specs.push_back(e.path().filename().string());
    std::sort(specs.begin(), specs.end());
    specs.push_back("bunny.obj");
    for (const char* g : {"gen:balls:1", "gen:tetra:3", "gen:mount:3"}) specs.push_back(g);
    return specs;
}

Scene load(const std::string& spec) {
    return load_scene(spec.rfind("gen:", 0) == 0 ? spec : std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + spec);
}

/// Closest hits or occlusion (prim 0) of every ray, in batches of `grain`
/// to 2 `grain` rays (so that every width gets a ragged last packet and
/// group per batch when the count is not a multiple of it), traced with
/// `width`.
/// Stream: the same through intersect_stream / occluded_stream.
std::vector<Hitf> trace(const Accel& accel, int width, bool any_hit, const std::vector<Rayf>& rays,
                        std::size_t grain = 61, bool stream = false) {
    std::vector<Hitf> hits(rays.size());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), grain), [&](const auto& r) {
        const std::span<const Rayf> in(rays.data() + r.begin(), r.size());
        const std::span<Hitf> out(hits.data() + r.begin(), r.size());
        if (!any_hit) return stream ? accel.intersect_stream(width, in, out) : accel.intersect_packets(width, in, out);
        std::vector<std::uint8_t> occ(r.size());
        if (stream) accel.occluded_stream(width, in, occ);
        else accel.occluded_packets(width, in, occ);
        for (std::size_t i = 0; i < r.size(); ++i) out[i].prim = occ[i] ? 0 : kNoPrim;
    });
    return hits;
}

// ---- Ray sets ------------------------------------------------------------------

struct RaySet {
    std::string name;
    std::vector<Rayf> rays;
    bool any_hit = false;
};

/// Every used child box of the tree.
template <int N>
std::vector<Box3f> child_boxes(const WideBvh<N, 8>& bvh) {
    std::vector<Box3f> boxes;
    for (const WideNode<N>& node : bvh.nodes)
        for (int i = 0; i < N; ++i)
            if (node.child[i] != wide_child::kEmpty) boxes.push_back(node.box(i));
    return boxes;
}

/// Rays that stress the node test lane by lane: axis-parallel with +-0 in
/// the other components, from the faces of the tree's child boxes, and rays
/// aimed at the corners of those boxes; neighbours share a box, so packets
/// mix lanes that graze it with lanes that miss it.
template <int N>
std::vector<Rayf> adversarial_rays(const WideBvh<N, 8>& bvh, std::mt19937& rng, int n) {
    const std::vector<Box3f> boxes = child_boxes(bvh);
    std::vector<Rayf> rays;
    if (boxes.empty()) return rays;
    std::uniform_real_distribution<float> u(0, 1);
    while (int(rays.size()) < n) {
        const Box3f& b = boxes[rng() % boxes.size()];
        const int axis = int(rng() % 3), side = int(rng() % 2);
        for (int k = 0; k < 4; ++k) {
            // From a face, parallel to it (+-0 along the face normal).
            Rayf r;
            r.org = random_point(rng, b);
            r.org[axis] = side ? b.hi[axis] : b.lo[axis];
            r.dir = random_direction(rng);
            r.dir[axis] = signed_zero(rng);
            rays.push_back(r);
            // Axis-parallel through the face.
            Rayf p;
            p.org = random_point(rng, grown(b, 0.5f));
            p.dir = {signed_zero(rng), signed_zero(rng), signed_zero(rng)};
            p.dir[int(rng() % 3)] = rng() % 2 ? 1.0f : -1.0f;
            p.org[axis] = side ? b.hi[axis] : b.lo[axis];
            rays.push_back(p);
            // At a corner, from outside.
            Rayf c;
            const Vec3f corner{rng() % 2 ? b.hi.x : b.lo.x, rng() % 2 ? b.hi.y : b.lo.y, rng() % 2 ? b.hi.z : b.lo.z};
            c.org = corner + random_direction(rng) * (1.0f + u(rng)) * length(b.extent());
            c.dir = corner - c.org;
            rays.push_back(c);
        }
    }
    return rays;
}

/// Rays from one small box beyond the scene's low corner to the corners of
/// the tree's child boxes and to points on their edges: every direction
/// positive, so that packets form groups whose interval test (origins and
/// reciprocals as intervals) meets boxes the rays only graze. Every third
/// ray stops at its target, every third a little before it.
template <int N>
std::vector<Rayf> corner_fan(const WideBvh<N, 8>& bvh, const Scene& scene, std::mt19937& rng, int n) {
    const std::vector<Box3f> boxes = child_boxes(bvh);
    std::vector<Rayf> rays;
    if (boxes.empty()) return rays;
    const Box3f scene_box = scene_bounds(scene);
    const Vec3f extent = scene_box.extent();
    // Within the spread a group may have (a sixteenth of the scene, max_origin_spread).
    const Box3f origins{scene_box.lo - extent * 0.52f, scene_box.lo - extent * 0.5f};
    std::uniform_real_distribution<float> u(0, 1);
    // Neighbouring rays aim at the same box, so that a packet's lanes split on it.
    for (int i = 0; int(rays.size()) < n; ++i) {
        const Box3f& b = boxes[rng() % boxes.size()];
        for (int k = 0; k < 8; ++k) {
            Vec3f target{k & 1 ? b.hi.x : b.lo.x, k & 2 ? b.hi.y : b.lo.y, k & 4 ? b.hi.z : b.lo.z};
            Rayf r;
            r.org = i % 3 == 0 ? origins.lo : random_point(rng, origins);
            if (i % 2) {
                const int a = int(rng() % 3);
                target[a] = b.lo[a] + u(rng) * (b.hi[a] - b.lo[a]);  // on an edge
            }
            r.dir = target - r.org;
            if (k % 3 == 1) r.tfar = 1.0f;
            if (k % 3 == 2) r.tfar = 0.999f;
            rays.push_back(r);
        }
    }
    return rays;
}

// ---- Comparisons ---------------------------------------------------------------------

/// Packet answers against the single-ray ones: see the file comment.
std::size_t count_unlike_single(const RaySet& set, const std::vector<Hitf>& single, const std::vector<Hitf>& packet,
                                std::string& first) {
    std::size_t bad = 0;
    for (std::size_t i = 0; i < set.rays.size(); ++i) {
        const Hitf &a = single[i], &b = packet[i];
        bool ok = a.found() == b.found();
        if (ok && a.found() && !set.any_hit)
            ok = a.prim == b.prim ? a.t == b.t && a.u == b.u && a.v == b.v
                                  : std::fabs(a.t - b.t) <= 1e-5f * std::max(std::fabs(a.t), std::fabs(b.t));
        if (ok) continue;
        if (++bad <= 3)
            first += "\n  ray " + std::to_string(i) + ": " + describe(set.rays[i]) + "\n    single " + describe(a) +
                     ", packet " + describe(b);
    }
    return bad;
}

/// Packet answers against the oracle; a difference the single-ray traversal
/// shares exactly is counted in `shared`, not as a failure.
std::size_t count_unlike_oracle(const RaySet& set, const std::vector<Hitf>& truth, const std::vector<Hitf>& single,
                                const std::vector<Hitf>& packet, std::size_t& shared, std::string& first) {
    std::size_t bad = 0;
    for (std::size_t i = 0; i < set.rays.size(); ++i) {
        const Hitf &w = truth[i], &g = packet[i];
        bool ok = w.found() == g.found();
        if (ok && w.found() && !set.any_hit)
            ok = std::fabs(w.t - g.t) <= 1e-5f * std::max(std::fabs(w.t), std::fabs(g.t));
        if (ok) continue;
        if (single[i].found() == g.found() && single[i].t == g.t) {
            ++shared;
            continue;
        }
        if (++bad <= 3)
            first += "\n  ray " + std::to_string(i) + ": " + describe(set.rays[i]) + "\n    brute " + describe(w) +
                     ", packet " + describe(g);
    }
    return bad;
}

template <int N>
void check_scene(const Scene& scene, const std::string& label) {
    using Accel8 = WideBvhAccel<N, 8>;
    const AccelConfig config;
    Accel8 accel(scene, config);
    const BruteForce brute(scene, config.kernels);
    std::mt19937 rng(4242);
    const bool big = scene.primitive_count() > 20000;  // the oracle is the slow part
    std::vector<RaySet> sets;
    sets.push_back({"camera", camera_ray_set(scene, big ? 40 : 64, big ? 40 : 64)});
    // Random origins in the scene box grown by 0.1, random directions, half
    // with a finite tfar: incoherent packets, where lanes part early.
    const Box3f random_box = grown(scene_bounds(scene), 0.1f);
    sets.push_back({"random", random_rays_in(rng, random_box, length(random_box.extent()), big ? 503 : 1503)});
    sets.push_back({"adversarial", adversarial_rays(accel.bvh(), rng, big ? 300 : 1000)});
    sets.push_back({"camera in tiles", camera_ray_set(scene, big ? 40 : 64, big ? 40 : 64, nullptr, PixelOrder::Tiles)});
    sets.push_back({"corner fan", corner_fan(accel.bvh(), scene, rng, big ? 800 : 2400)});
    sets.push_back({"corner fan occlusion", sets.back().rays, true});
    {
        const std::vector<Hitf> cam = trace(brute, 1, false, sets[0].rays);
        sets.push_back({"shadow", shadow_rays(scene, sets[0].rays, cam), true});
        RaySet occ{"random occlusion", sets[1].rays, true};
        sets.push_back(occ);
        const std::vector<Hitf> tiled = trace(brute, 1, false, sets[3].rays);
        sets.push_back({"shadow in tiles", shadow_rays(scene, sets[3].rays, tiled), true});
    }
    std::size_t shared = 0;
    for (const RaySet& set : sets) {
        const std::vector<Hitf> truth = trace(brute, 1, set.any_hit, set.rays);
        const std::vector<Hitf> single = trace(accel, 1, set.any_hit, set.rays);
        for (int k : {4, 8, 16}) {
            if (!accel.supports_packet(k)) continue;
            const int fallback = default_wide_switch_below(N, k);
            // The occluder cache (any hit) on, except in the last two.
            const std::tuple<int, int, bool> configs[] = {{0, 1, true},         {fallback, 1, true},
                                                          {k + 1, 1, true},     {fallback, 4, true},
                                                          {fallback, 16, true}, {0, 16, true},
                                                          {fallback, 1, false}, {fallback, 16, false}};
            for (auto [below, group, cached] : configs) {
                WidePacketConfig c;
                c.switch_below = below;
                c.group_packets = group;
                c.occluder_cache = cached;
                accel.set_packet_config(k, c);
                SCOPED_TRACE(label + " bvh" + std::to_string(N) + " " + set.name + " K=" + std::to_string(k) +
                             " switch_below=" + std::to_string(below) + " group=" + std::to_string(group) +
                             (cached ? "" : " no occluder cache"));
                // Batches of several groups, with a ragged group at their end.
                const std::vector<Hitf> packet =
                    trace(accel, k, set.any_hit, set.rays, group == 1 ? 61 : std::size_t(group) * k * 3 - 5);
                std::string first;
                EXPECT_EQ(count_unlike_single(set, single, packet, first), 0u)
                    << "of " << set.rays.size() << " rays differ from the single-ray traversal" << first;
                first.clear();
                EXPECT_EQ(count_unlike_oracle(set, truth, single, packet, shared, first), 0u)
                    << "of " << set.rays.size() << " rays differ from brute force" << first;
            }
            accel.set_packet_config(k, default_wide_packet_config(N, k));
        }
        // Streams (wide_stream_traversal.h): the whole set as one, and
        // batches of 300 to 600 rays (with the lists' ragged chunks); lists
        // left alone below 1 ray (never), the default and 64 rays.
        if (accel.supports_stream()) {
            for (int below : {1, default_wide_packet_config(N, 16).stream_single_below, 64}) {
                for (std::size_t grain : {set.rays.size(), std::size_t(300)}) {
                    WidePacketConfig c = default_wide_packet_config(N, 16);
                    c.stream_single_below = below;
                    accel.set_packet_config(16, c);
                    SCOPED_TRACE(label + " bvh" + std::to_string(N) + " " + set.name + " stream, alone below " +
                                 std::to_string(below) + ", batches of " + std::to_string(grain));
                    const std::vector<Hitf> stream = trace(accel, 16, set.any_hit, set.rays, grain, true);
                    std::string first;
                    EXPECT_EQ(count_unlike_single(set, single, stream, first), 0u)
                        << "of " << set.rays.size() << " rays differ from the single-ray traversal" << first;
                    first.clear();
                    EXPECT_EQ(count_unlike_oracle(set, truth, single, stream, shared, first), 0u)
                        << "of " << set.rays.size() << " rays differ from brute force" << first;
                }
            }
            accel.set_packet_config(16, default_wide_packet_config(N, 16));
        }
    }
    if (shared != 0)
        std::printf("[   NOTE   ] %s bvh%d: %zu packet answers differ from brute force exactly as the single "
                    "ray's do\n", label.c_str(), N, shared);
}

class WideBvhPacket : public ::testing::TestWithParam<std::string> {};

TEST_P(WideBvhPacket, MatchesSingleRayAndBruteForce) {
    const Scene scene = load(GetParam());
    ASSERT_GT(scene.primitive_count(), 0u);
    check_scene<4>(scene, GetParam());
    check_scene<8>(scene, GetParam());
}

std::string spec_name(const ::testing::TestParamInfo<std::string>& info) {
    std::string s = info.param;
    std::replace_if(s.begin(), s.end(), [](char c) { return !std::isalnum(static_cast<unsigned char>(c)); }, '_');
    return s;
}

INSTANTIATE_TEST_SUITE_P(, WideBvhPacket, ::testing::ValuesIn(scene_specs()), spec_name);

// A batch of more than 65,536 rays walks as several streams (ray numbers
// are 32-bit fields of the lists): the same answers as single rays.
TEST(WideBvhPacketApi, StreamsLongerThanOneWalk) {
    const Scene scene = load("gen:balls:1");
    WideBvhAccel<4, 8> accel(scene, AccelConfig{});
    if (!accel.supports_stream()) GTEST_SKIP() << "no streams in this build (AVX-512)";
    std::mt19937 rng(7);
    const Box3f box = grown(scene_bounds(scene), 0.1f);
    for (bool any_hit : {false, true}) {
        const RaySet set{"random", random_rays_in(rng, box, length(box.extent()), 70001), any_hit};
        const std::vector<Hitf> single = trace(accel, 1, any_hit, set.rays, set.rays.size());
        const std::vector<Hitf> stream = trace(accel, 16, any_hit, set.rays, set.rays.size(), true);
        std::string first;
        EXPECT_EQ(count_unlike_single(set, single, stream, first), 0u) << first;
    }
}

TEST(WideBvhPacketApi, WidthsAndEmptyScene) {
    Scene empty;
    empty.update_features();
    const AccelConfig config;
    const WideBvhAccel<8, 8> accel(empty, config);
    EXPECT_TRUE(accel.supports_packet(1));
    EXPECT_FALSE(accel.supports_packet(2));
    EXPECT_EQ(accel.supports_packet(16), kWidthCompiled<16>);
    // A variant without packets says so and still answers through single rays.
    const WideBvhAccel<8, 8, NodeTest::Robust> robust(empty, config);
    EXPECT_FALSE(robust.supports_packet(8));
    Rayf r;
    r.dir = {0, 0, 1};
    // Every answer written, none found: packets of 8 on 5 rays, and streams
    // (a batch of 600; where AVX-512 is compiled in, for the packets'
    // variant only) on the empty tree.
    EXPECT_EQ(accel.supports_stream(), kWideStreamCompiled);
    EXPECT_FALSE(robust.supports_stream());
    for (const bool stream : {false, true}) {
        const std::vector<Rayf> batch(stream ? 600 : 5, r);
        std::vector<Hitf> hits(batch.size());
        hits[2].prim = 7;
        if (stream) accel.intersect_stream(16, batch, hits);
        else accel.intersect_packets(8, batch, hits);
        for (const Hitf& h : hits) EXPECT_FALSE(h.found());
        std::vector<std::uint8_t> occ(batch.size(), 1);
        if (stream) accel.occluded_stream(16, batch, occ);
        else accel.occluded_packets(8, batch, occ);
        for (std::uint8_t o : occ) EXPECT_EQ(o, 0);
    }
}

}  // namespace
}  // namespace raypack
