// embree_direct: Embree 3 called directly on a .rays file, in the way its own
// documentation recommends, with no raypack code on the timed path. It is
// the yardstick for raypack's Embree backend (`raypack bench --accel
// embree,embree-robust`): scripts/embree_check.py runs both on the same rays
// and reports their ratio (docs/embree.md).
//
// raypack's loaders read the scene and the rays before anything is timed;
// the rays are then laid out once in Embree's own structures (RTCRayHit,
// and aligned RTCRayHit4/8/16 / RTCRay4/8/16 packets). A timed pass copies
// calls rtcIntersect1/4/8/16 or rtcOccluded1/4/8/16 on them in place (each
// pass gets a fresh copy, made before its clock starts), one thread, with flush-to-zero
// and denormals-are-zero set (Embree API, "Performance Recommendations"),
// and in the coherent context when every ray shares one origin.
#include <embree3/rtcore.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

#include "accel/embree/embree_packet_types.h"
#include "scene/load.h"
#include "scene/ray_file.h"

namespace {

using raypack::Rayf;

struct Options {
    std::string scene, rays;
    std::vector<int> widths{1, 4, 8, 16};
    std::vector<bool> robust{false, true};
    RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;
    int repeat = 5;
    std::string context = "auto";  // auto | coherent | incoherent
    bool json = false;
};

[[noreturn]] void usage(const std::string& problem) {
    std::fprintf(stderr,
                 "embree_direct: %s\n"
                 "usage: embree_direct SCENE FILE.rays [--packet 1,4,8,16] [--mode fast|robust|both]\n"
                 "                     [--quality low|medium|high] [--repeat R] [--context auto|coherent|incoherent]\n"
                 "                     [--json]\n",
                 problem.c_str());
    std::exit(2);
}

Options parse(int argc, char** argv) {
    Options o;
    std::vector<std::string> positional;
    for (int i = 1; i < argc; ++i) {
        const std::string a = argv[i];
        auto value = [&]() -> std::string {
            if (i + 1 >= argc) usage(a + " needs a value");
            return argv[++i];
        };
        if (a == "--packet") {
            o.widths.clear();
            const std::string list = value();
            for (std::size_t p = 0; p <= list.size();) {
                const std::size_t q = std::min(list.find(',', p), list.size());
                const std::string w = list.substr(p, q - p);
                if (w != "1" && w != "4" && w != "8" && w != "16") usage("--packet: expected 1, 4, 8, 16, got '" + w + "'");
                o.widths.push_back(std::stoi(w));
                p = q + 1;
            }
        } else if (a == "--mode") {
            const std::string m = value();
            if (m == "fast") o.robust = {false};
            else if (m == "robust") o.robust = {true};
            else if (m == "both") o.robust = {false, true};
            else usage("--mode: expected fast|robust|both, got '" + m + "'");
        } else if (a == "--quality") {
            const std::string q = value();
            if (q == "low") o.quality = RTC_BUILD_QUALITY_LOW;
            else if (q == "medium") o.quality = RTC_BUILD_QUALITY_MEDIUM;
            else if (q == "high") o.quality = RTC_BUILD_QUALITY_HIGH;
            else usage("--quality: expected low|medium|high, got '" + q + "'");
        } else if (a == "--repeat") {
            const std::string r = value();
            o.repeat = std::atoi(r.c_str());
            if (o.repeat < 1 || o.repeat > 1000) usage("--repeat: expected 1..1000, got '" + r + "'");
        } else if (a == "--context") {
            o.context = value();
            if (o.context != "auto" && o.context != "coherent" && o.context != "incoherent")
                usage("--context: expected auto|coherent|incoherent, got '" + o.context + "'");
        } else if (a == "--json") {
            o.json = true;
        } else if (!a.empty() && a[0] == '-') {
            usage("unknown option '" + a + "'");
        } else {
            positional.push_back(a);
        }
    }
    if (positional.size() != 2) usage("expected SCENE and FILE.rays");
    o.scene = positional[0];
    o.rays = positional[1];
    return o;
}

/// Triangles (indexed, three vertices each) and sphere points, as a user of
/// Embree would set them up. NFF cones would need user geometry, which is
/// raypack's own code; this program leaves them to the backend.
RTCScene build_scene(RTCDevice device, const raypack::Scene& s, bool robust, RTCBuildQuality quality) {
    if (s.cones.size()) throw std::runtime_error("the scene has cones, which Embree traces only as user geometry");
    RTCScene scene = rtcNewScene(device);
    rtcSetSceneFlags(scene, robust ? RTC_SCENE_FLAG_ROBUST : RTC_SCENE_FLAG_NONE);
    rtcSetSceneBuildQuality(scene, quality);
    if (const std::size_t n = s.triangles.size()) {
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
        auto* vertices = static_cast<raypack::Vec3f*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(raypack::Vec3f), 3 * n));
        auto* index = static_cast<std::uint32_t*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), n));
        for (std::size_t t = 0; t < n; ++t) {
            vertices[3 * t] = s.triangles.p0[t];
            vertices[3 * t + 1] = s.triangles.p1[t];
            vertices[3 * t + 2] = s.triangles.p2[t];
        }
        for (std::size_t k = 0; k < 3 * n; ++k) index[k] = std::uint32_t(k);
        rtcSetGeometryBuildQuality(g, quality);
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
    }
    if (const std::size_t n = s.spheres.size()) {
        RTCGeometry g = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_SPHERE_POINT);
        auto* points = static_cast<float*>(
            rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), n));
        for (std::size_t i = 0; i < n; ++i) {
            std::memcpy(points + 4 * i, &s.spheres.center[i], 3 * sizeof(float));
            points[4 * i + 3] = s.spheres.radius[i];
        }
        rtcSetGeometryBuildQuality(g, quality);
        rtcCommitGeometry(g);
        rtcAttachGeometry(scene, g);
        rtcReleaseGeometry(g);
    }
    rtcCommitScene(scene);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) throw std::runtime_error("Embree could not build the scene");
    return scene;
}

template <int K>
using Packet = raypack::EmbreePacket<K>;

/// Writes ray `r` into lane `i` of a single ray (K = 1) or of a packet.
void set_lane(RTCRay& ray, int, const Rayf& r) {
    ray = RTCRay{r.org.x, r.org.y, r.org.z, r.tnear, r.dir.x, r.dir.y, r.dir.z, 0.0f, r.tfar, 0xFFFFFFFFu, 0, 0};
}
template <class RayK>
void set_lane(RayK& ray, int i, const Rayf& r) {
    ray.org_x[i] = r.org.x, ray.org_y[i] = r.org.y, ray.org_z[i] = r.org.z, ray.tnear[i] = r.tnear;
    ray.dir_x[i] = r.dir.x, ray.dir_y[i] = r.dir.y, ray.dir_z[i] = r.dir.z, ray.time[i] = 0.0f;
    ray.tfar[i] = r.tfar, ray.mask[i] = 0xFFFFFFFFu, ray.id[i] = unsigned(i), ray.flags[i] = 0;
}
void clear_hit(RTCHit& hit, int) { hit.geomID = hit.primID = hit.instID[0] = RTC_INVALID_GEOMETRY_ID; }
template <class HitK>
void clear_hit(HitK& hit, int i) {
    hit.geomID[i] = hit.primID[i] = hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
}
bool lane_hit(const RTCRayHit& rh, int) { return rh.hit.geomID != RTC_INVALID_GEOMETRY_ID; }
template <class RayHitK>
bool lane_hit(const RayHitK& rh, int i) {
    return rh.hit.geomID[i] != RTC_INVALID_GEOMETRY_ID;
}
bool lane_occluded(const RTCRay& ray, int) { return ray.tfar == -std::numeric_limits<float>::infinity(); }
template <class RayK>
bool lane_occluded(const RayK& ray, int i) {
    return ray.tfar[i] == -std::numeric_limits<float>::infinity();
}

/// A packet's valid mask, aligned as Embree requires (to the packet's size).
template <int K>
struct alignas(4 * K) ValidMask {
    std::array<int, K> lanes;
    int& operator[](int i) { return lanes[std::size_t(i)]; }
    int operator[](int i) const { return lanes[std::size_t(i)]; }
    const int* data() const { return lanes.data(); }
};

/// The rays of a set as Embree packets of K, laid out before timing. Lanes
/// past the end repeat the last ray and are masked off.
template <int K, class T>
struct Prepared {
    std::vector<T> packets;
    std::vector<ValidMask<K>> valid;
};

template <int K, class T>
Prepared<K, T> prepare(const std::vector<Rayf>& rays) {
    Prepared<K, T> p;
    const std::size_t count = (rays.size() + K - 1) / K;
    p.packets.resize(count);
    p.valid.resize(count);
    for (std::size_t b = 0; b < count; ++b)
        for (int i = 0; i < K; ++i) {
            const std::size_t src = std::min(b * K + std::size_t(i), rays.size() - 1);
            if constexpr (std::is_same_v<T, typename Packet<K>::RayHit>) {
                set_lane(p.packets[b].ray, i, rays[src]);
                clear_hit(p.packets[b].hit, i);
            } else {
                set_lane(p.packets[b], i, rays[src]);
            }
            p.valid[b][i] = b * K + std::size_t(i) < rays.size() ? -1 : 0;
        }
    return p;
}

struct Pass {
    double seconds = 0;
    std::size_t hits = 0;
};

/// One pass over every ray: closest hits (or occluded rays) and the time.
/// The rays are laid out in Embree's packets before the clock starts and
/// traced in place.
template <int K>
Pass trace(RTCScene scene, bool coherent, bool any_hit, const std::vector<Rayf>& rays) {
    using RayHit = typename Packet<K>::RayHit;
    using Ray = typename Packet<K>::Ray;
    static_assert(alignof(RayHit) <= 64);  // std::vector keeps it (aligned operator new)
    Pass pass;
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    if (coherent) context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    auto run = [&](auto prepared, auto call, auto answered) {
        const auto start = std::chrono::steady_clock::now();
        for (std::size_t b = 0; b < prepared.packets.size(); ++b) call(prepared.valid[b].data(), &prepared.packets[b]);
        pass.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        for (std::size_t b = 0; b < prepared.packets.size(); ++b)
            for (int i = 0; i < K; ++i) pass.hits += prepared.valid[b][i] && answered(prepared.packets[b], i);
    };
    if (any_hit)
        run(prepare<K, Ray>(rays), [&](const int* v, Ray* r) { Packet<K>::occluded(v, scene, &context, r); },
            [](const Ray& r, int i) { return lane_occluded(r, i); });
    else
        run(prepare<K, RayHit>(rays), [&](const int* v, RayHit* r) { Packet<K>::intersect(v, scene, &context, r); },
            [](const RayHit& r, int i) { return lane_hit(r, i); });
    return pass;
}

Pass trace_width(int width, RTCScene scene, bool coherent, bool any_hit, const std::vector<Rayf>& rays) {
    switch (width) {
        case 4: return trace<4>(scene, coherent, any_hit, rays);
        case 8: return trace<8>(scene, coherent, any_hit, rays);
        case 16: return trace<16>(scene, coherent, any_hit, rays);
        default: return trace<1>(scene, coherent, any_hit, rays);
    }
}

bool one_origin(const std::vector<Rayf>& rays) {
    return std::all_of(rays.begin(), rays.end(), [&](const Rayf& r) {
        return r.org.x == rays[0].org.x && r.org.y == rays[0].org.y && r.org.z == rays[0].org.z;
    });
}

}  // namespace

int main(int argc, char** argv) {
    const Options o = parse(argc, argv);
    try {
        const raypack::Scene scene = raypack::load_scene(o.scene);
        const raypack::RayFile file = raypack::read_rays(o.rays);
        if (file.rays.empty()) throw std::runtime_error(o.rays + ": no rays");
        const bool any_hit = file.kind == raypack::RayKind::AnyHit;
        const bool coherent = o.context == "coherent" || (o.context == "auto" && one_origin(file.rays));
        _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
        _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
        RTCDevice device = rtcNewDevice("threads=1");
        if (!device) throw std::runtime_error("rtcNewDevice failed");
        if (!o.json)
            std::printf("%s, %zu %s rays, %s context, one thread\n%-7s %6s %10s %10s %10s %9s\n", o.rays.c_str(),
                        file.rays.size(), any_hit ? "any-hit" : "closest-hit", coherent ? "coherent" : "incoherent",
                        "mode", "packet", "median", "min", "max", "hits");
        for (const bool robust : o.robust) {
            RTCScene rtc_scene = build_scene(device, scene, robust, o.quality);
            // Validation before timing: every width answers as width 1 does
            // but for a few rays at shared edges (fast mode may let them
            // through, robust mode may not).
            const std::size_t reference_hits = trace_width(1, rtc_scene, coherent, any_hit, file.rays).hits;
            for (const int width : o.widths) {
                std::vector<double> mrays;
                std::size_t hits = trace_width(width, rtc_scene, coherent, any_hit, file.rays).hits;  // warm-up
                const double tolerance = 1e-4 * double(file.rays.size()) + 1;
                if (std::fabs(double(hits) - double(reference_hits)) > tolerance)
                    throw std::runtime_error("width " + std::to_string(width) + " found " + std::to_string(hits) +
                                             " hits, width 1 " + std::to_string(reference_hits));
                for (int r = 0; r < o.repeat; ++r) {
                    const Pass pass = trace_width(width, rtc_scene, coherent, any_hit, file.rays);
                    mrays.push_back(double(file.rays.size()) / pass.seconds * 1e-6);
                }
                std::sort(mrays.begin(), mrays.end());
                const std::size_t n = mrays.size();
                const double median = n % 2 ? mrays[n / 2] : 0.5 * (mrays[n / 2 - 1] + mrays[n / 2]);
                const char* mode = robust ? "robust" : "fast";
                if (o.json)
                    std::printf("{\"mode\": \"%s\", \"packet\": %d, \"coherent\": %s, \"rays\": %zu, \"hits\": %zu, "
                                "\"mrays_per_s_median\": %.4f, \"mrays_per_s_min\": %.4f, \"mrays_per_s_max\": %.4f}\n",
                                mode, width, coherent ? "true" : "false", file.rays.size(), hits, median, mrays.front(),
                                mrays.back());
                else
                    std::printf("%-7s %6d %10.2f %10.2f %10.2f %9zu\n", mode, width, median, mrays.front(),
                                mrays.back(), hits);
            }
            rtcReleaseScene(rtc_scene);
        }
        rtcReleaseDevice(device);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "embree_direct: %s\n", e.what());
        return 1;
    }
    return 0;
}
