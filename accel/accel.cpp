#include "accel/accel.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>

#include "accel/brute/brute_force.h"
#include "accel/bvh/bvh2_accel.h"
#include "accel/bvh/wide_bvh_accel.h"
#include "accel/grid/grid2_accel.h"
#include "accel/grid/grid_accel.h"
#include "accel/kdtree/kdtree_accel.h"
#include "accel/motion/motion_bvh.h"
#include "accel/names.h"
#include "accel/octree/octree_accel.h"
#ifdef RAYPACK_HAVE_EMBREE
#include "accel/embree/embree_accel.h"
#endif

namespace raypack {

std::span<const char* const> accel_kinds() {
    static constexpr const char* kinds[] = {
        "bvh2",
#if defined(__SSE4_2__)
        "bvh4",
#endif
#if defined(__AVX2__)
        "bvh8",
#endif
        "grid",
        "grid2",
        "kdtree",
        "octree",
        "brute",
#ifdef RAYPACK_HAVE_EMBREE
        "embree",
        "embree-robust",
#endif
    };
    return kinds;
}

std::string accel_kinds_list() { return names_joined(accel_kinds()); }

namespace {

/// A scene with instances: the structures of its objects (built first, in
/// definition order, so that an object's own instances find theirs), the
/// structure over the scene (whose instance primitives point to them) and,
/// for moving placements, a motion BVH. Static queries are the top
/// structure's; a moving placement can only be closer or block, so it is
/// traced after, with the span cut at the top structure's hit.
class InstancedAccel final : public Accel {
public:
    InstancedAccel(const Scene& scene, std::unique_ptr<ObjectAccels> objects, std::unique_ptr<Accel> top,
                   std::unique_ptr<MotionBvh> motion)
        : scene_(scene), objects_(std::move(objects)), top_(std::move(top)), motion_(std::move(motion)) {
        stats_ = top_->stats();
        stats_.build_ms = 0;  // the whole build's, set by build_accel
        for (const auto& o : objects_->accels) stats_.bytes += o->stats().bytes;
        if (motion_) {
            stats_.bytes += motion_->bytes();
            stats_.nodes += motion_->node_count();
        }
    }
    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override {
        top_->intersect(rays, hits);
        add_motion(rays, {}, hits);
    }
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override {
        top_->occluded(rays, occluded);
        add_motion(rays, {}, occluded);
    }
    bool supports_packet(int width) const override { return top_->supports_packet(width); }
    void intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const override {
        top_->intersect_packets(width, rays, hits);
        add_motion(rays, {}, hits);
    }
    void occluded_packets(int width, std::span<const Rayf> rays, std::span<std::uint8_t> out) const override {
        top_->occluded_packets(width, rays, out);
        add_motion(rays, {}, out);
    }
    void intersect_at(int width, std::span<const Rayf> rays, std::span<const float> times,
                      std::span<Hitf> hits) const override {
        top_->intersect_packets(width, rays, hits);
        add_motion(rays, times, hits);
    }
    void occluded_at(int width, std::span<const Rayf> rays, std::span<const float> times,
                     std::span<std::uint8_t> out) const override {
        top_->occluded_packets(width, rays, out);
        add_motion(rays, times, out);
    }
    bool count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                         TraversalCounts& counts) const override {
        return !motion_ && top_->count_traversal(rays, any_hit, hits, counts);
    }

private:
    /// Ray i at shutter fraction of times[i] (the opening without times).
    float fraction(std::span<const float> times, std::size_t i) const {
        return times.empty() ? 0.0f : scene_.shutter_fraction(times[i]);
    }
    /// Each ray's shutter fraction, in batches of kMotionBatch.
    static constexpr std::size_t kMotionBatch = 256;
    template <class F>
    void in_batches(std::span<const Rayf> rays, std::span<const float> times, F&& f) const {
        float fractions[kMotionBatch];
        for (std::size_t b = 0; b < rays.size(); b += kMotionBatch) {
            const std::size_t n = std::min(kMotionBatch, rays.size() - b);
            for (std::size_t i = 0; i < n; ++i) fractions[i] = fraction(times, b + i);
            f(b, n, std::span<const float>(fractions, n));
        }
    }
    void add_motion(std::span<const Rayf> rays, std::span<const float> times, std::span<Hitf> hits) const {
        if (!motion_) return;
        in_batches(rays, times, [&](std::size_t b, std::size_t n, std::span<const float> s) {
            motion_->intersect(rays.subspan(b, n), s, hits.subspan(b, n));
        });
    }
    void add_motion(std::span<const Rayf> rays, std::span<const float> times, std::span<std::uint8_t> out) const {
        if (!motion_) return;
        in_batches(rays, times, [&](std::size_t b, std::size_t n, std::span<const float> s) {
            motion_->occluded(rays.subspan(b, n), s, out.subspan(b, n));
        });
    }

    const Scene& scene_;
    std::unique_ptr<ObjectAccels> objects_;
    std::unique_ptr<Accel> top_;
    std::unique_ptr<MotionBvh> motion_;
};

std::unique_ptr<Accel> build_one(const Scene& scene, const AccelConfig& config);

}  // namespace

std::unique_ptr<Accel> build_accel(const Scene& scene, const AccelConfig& config) {
    // Every structure's construction timed here, whole (its statistics
    // included); Embree keeps its own time, which leaves out the creation of
    // its device (an application creates one for all its scenes).
    const auto start = std::chrono::steady_clock::now();
    std::unique_ptr<Accel> accel;
    // Embree refuses instances itself.
    if (!scene.placements() || is_embree_kind(config.kind)) {
        accel = build_one(scene, config);
    } else {
        auto objects = std::make_unique<ObjectAccels>();
        AccelConfig with_objects = config;
        with_objects.kernels.objects = objects.get();
        for (const auto& object : scene.objects) objects->accels.push_back(build_one(*object, with_objects));
        auto top = build_one(scene, with_objects);
        std::unique_ptr<MotionBvh> motion;
        if (!scene.moving_instances.empty())
            motion = std::make_unique<MotionBvh>(scene, *objects, config.kernels, config.kind == "brute");
        accel = std::make_unique<InstancedAccel>(scene, std::move(objects), std::move(top), std::move(motion));
    }
    if (!is_embree_kind(config.kind))
        accel->stats_.build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    return accel;
}

namespace {

std::unique_ptr<Accel> build_one(const Scene& scene, const AccelConfig& config) {
    if (config.kind == "bvh2") return std::make_unique<Bvh2Accel>(scene, config);
#if defined(__SSE4_2__)
    if (config.kind == "bvh4") return std::make_unique<Bvh4Accel>(scene, config);
#endif
#if defined(__AVX2__)
    if (config.kind == "bvh8") return std::make_unique<Bvh8Accel>(scene, config);
#endif
    if (config.kind == "grid") return std::make_unique<GridAccel>(scene, config);
    if (config.kind == "grid2") return std::make_unique<Grid2Accel>(scene, config);
    if (config.kind == "kdtree") {
        KdTreeConfig kd;
        kd.packet_groups = config.packet_group != 1;
        return std::make_unique<KdTreeAccel>(scene, config, kd);
    }
    if (config.kind == "octree") {
        OctreeConfig oc;
        oc.packet_groups = config.packet_group != 1;
        return std::make_unique<OctreeAccel>(scene, config, oc);
    }
    if (config.kind == "brute") return std::make_unique<BruteForce>(scene, config.kernels);
#ifdef RAYPACK_HAVE_EMBREE
    if (is_embree_kind(config.kind))
        return std::make_unique<EmbreeAccel>(scene, embree_options(config.kind == "embree-robust", config.build_quality));
#endif
    throw std::invalid_argument("unknown acceleration structure '" + config.kind + "' (expected " + accel_kinds_list() + ")");
}

}  // namespace

}  // namespace raypack
