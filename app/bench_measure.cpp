#include "app/bench_measure.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <sstream>
#include <stdexcept>

#include "accel/threads_spread.h"
#include "measure/ray_sets.h"
#include "scene/ray_file.h"

namespace raypack::app {
namespace {

constexpr std::size_t kBatch = 256;        // rays per validation and counting block
constexpr std::size_t kTimedBatch = 4096;  // rays per call into the structure in the timed loop (cmd_trace.cpp)
constexpr std::size_t kSampleBlock = 64;  // consecutive rays per sample block (a multiple of every packet width)

/// Positions of up to `max_rays` rays of `n`, in blocks of `block` spread evenly.
std::vector<std::size_t> sample_positions(std::size_t n, std::size_t max_rays, std::size_t block) {
    std::vector<std::size_t> index;
    if (n <= max_rays) {
        for (std::size_t i = 0; i < n; ++i) index.push_back(i);
        return index;
    }
    const std::size_t blocks = std::max<std::size_t>(1, max_rays / block), stride = n / blocks;
    for (std::size_t b = 0; b < blocks; ++b)
        for (std::size_t i = b * stride; i < std::min(n, b * stride + block); ++i) index.push_back(i);
    return index;
}

std::vector<Rayf> gather(const std::vector<Rayf>& rays, const std::vector<std::size_t>& index) {
    std::vector<Rayf> out;
    out.reserve(index.size());
    for (std::size_t i : index) out.push_back(rays[i]);
    return out;
}

/// Any-hit answers stored as hits: prim 0 marks an occluded ray (docs/rays.md).
void trace_block(const Accel& accel, int packet, bool any_hit, std::span<const Rayf> rays, std::span<Hitf> hits) {
    if (!any_hit) return accel.intersect_packets(packet, rays, hits);
    std::uint8_t occluded[kTimedBatch];
    for (std::size_t lo = 0; lo < rays.size(); lo += kTimedBatch) {
        const std::size_t n = std::min(kTimedBatch, rays.size() - lo);
        accel.occluded_packets(packet, rays.subspan(lo, n), std::span<std::uint8_t>(occluded, n));
        for (std::size_t i = 0; i < n; ++i) {
            hits[lo + i] = Hitf{};
            if (occluded[i]) hits[lo + i].prim = 0;
        }
    }
}

void trace_all(const Accel& accel, int packet, bool any_hit, std::span<const Rayf> rays, std::span<Hitf> hits,
               std::size_t grain) {
    const std::size_t n = rays.size();
    ThreadsSpread spread;  // one CPU per thread
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, (n + grain - 1) / grain), [&](const auto& r) {
        spread.enter();
        for (std::size_t b = r.begin(); b < r.end(); ++b) {
            const std::size_t lo = b * grain, count = std::min(n, lo + grain) - lo;
            trace_block(accel, packet, any_hit, rays.subspan(lo, count), hits.subspan(lo, count));
        }
    });
}

std::string describe(const Rayf& r) {
    std::ostringstream s;
    s.precision(9);
    s << "org (" << r.org.x << ", " << r.org.y << ", " << r.org.z << ") dir (" << r.dir.x << ", " << r.dir.y << ", "
      << r.dir.z << ") t [" << r.tnear << ", " << r.tfar << "]";
    return s.str();
}

std::string describe(const Hitf& h, bool any_hit) {
    if (!h.found()) return any_hit ? "not occluded" : "miss";
    if (any_hit) return "occluded";
    std::ostringstream s;
    s.precision(9);
    s << "prim " << h.prim << " at t " << h.t;
    return s.str();
}

}  // namespace

BenchRays make_bench_rays(const Scene& scene, const std::string& kind, int width, int height, OffsetPolicy offset) {
    // In tiles, as `raypack rays` writes them (measure/ray_sets.h).
    constexpr PixelOrder kOrder = PixelOrder::Tiles;
    if (kind == "camera") return {kind, false, camera_ray_set(scene, width, height, nullptr, kOrder)};
    if (kind == "shadow") return {kind, true, shadow_ray_set(scene, width, height, offset, nullptr, kOrder)};
    if (kind == "diffuse") return {kind, false, diffuse_ray_set(scene, width, height, 1, offset, nullptr, kOrder)};
    throw std::invalid_argument("unknown ray kind '" + kind + "' (expected camera, shadow or diffuse)");
}

BenchRays load_bench_rays(const std::string& path) {
    RayFile file = read_rays(path);
    return {"file:" + std::filesystem::path(path).stem().string(), file.kind == RayKind::AnyHit, std::move(file.rays)};
}

OracleSample oracle_sample(const Scene& scene, const BenchRays& set, std::size_t max_rays, KernelChoice kernels) {
    OracleSample s;
    s.index = sample_positions(set.rays.size(), max_rays, kSampleBlock);
    s.rays = gather(set.rays, s.index);
    s.expected.resize(s.rays.size());
    const auto oracle = build_accel(scene, accel_config("brute", kernels));
    trace_all(*oracle, 1, set.any_hit, s.rays, s.expected, 16);
    return s;
}

void validate_against_oracle(const Accel& accel, int packet, const BenchRays& set, const OracleSample& sample,
                             const std::string& context) {
    std::vector<Hitf> got(sample.rays.size());
    trace_all(accel, packet, set.any_hit, sample.rays, got, kSampleBlock);
    for (std::size_t i = 0; i < got.size(); ++i) {
        const Hitf &g = got[i], &e = sample.expected[i];
        const bool same = g.found() == e.found() &&
                          (set.any_hit || !e.found() || std::fabs(g.t - e.t) <= 1e-5f * std::fabs(e.t));
        if (same) continue;
        throw std::runtime_error("validation failed for " + context + ": ray " + std::to_string(sample.index[i]) +
                                 " (" + describe(sample.rays[i]) + "): oracle " + describe(e, set.any_hit) + ", got " +
                                 describe(g, set.any_hit));
    }
}

std::optional<WorkPerRay> work_per_ray(const Accel& accel, const BenchRays& set, std::size_t max_rays) {
    const std::vector<std::size_t> index = sample_positions(set.rays.size(), max_rays, kBatch);
    const std::vector<Rayf> rays = gather(set.rays, index);
    std::atomic<std::uint64_t> nodes{0}, prims{0}, leaves{0}, empty_leaves{0};
    std::atomic<bool> available{true};
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rays.size(), kBatch), [&](const auto& r) {
        std::vector<Hitf> hits(r.size());
        TraversalCounts c;
        if (!accel.count_traversal(std::span<const Rayf>(rays).subspan(r.begin(), r.size()), set.any_hit, hits, c))
            available = false;
        nodes += c.nodes;
        prims += c.prims;
        leaves += c.leaves;
        empty_leaves += c.empty_leaves;
    });
    if (!available || rays.empty()) return std::nullopt;
    const double n = double(rays.size());
    return WorkPerRay{double(prims) / n, double(nodes) / n, double(leaves) / n, double(empty_leaves) / n};
}

std::vector<double> time_passes(const Accel& accel, int packet, const BenchRays& set, int repeat,
                                std::size_t& hits_found) {
    std::vector<Hitf> hits(set.rays.size());
    std::vector<double> ms;
    for (int pass = -1; pass < repeat; ++pass) {  // pass -1: the warm-up
        const auto start = std::chrono::steady_clock::now();
        trace_all(accel, packet, set.any_hit, set.rays, hits, kTimedBatch);
        const auto stop = std::chrono::steady_clock::now();
        if (pass >= 0) ms.push_back(std::chrono::duration<double, std::milli>(stop - start).count());
    }
    hits_found = std::size_t(std::count_if(hits.begin(), hits.end(), [](const Hitf& h) { return h.found(); }));
    return ms;
}

}  // namespace raypack::app
