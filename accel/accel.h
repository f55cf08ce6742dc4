#pragma once
// The interface every acceleration structure offers: build from a scene,
// then closest-hit and any-hit queries on batches of rays. Dispatch is once
// per batch; inside, each structure runs its own templated loops.
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>

#include "accel/primitive_intersector.h"
#include "accel/traversal_counts.h"
#include "kernels/ray.h"
#include "scene/scene.h"

namespace raypack {

struct AccelStats {
    std::string name;        ///< e.g. "bvh2"
    std::string builder;     ///< e.g. "binned"
    double build_ms = 0;
    std::size_t nodes = 0;
    std::size_t leaves = 0;
    std::size_t bytes = 0;   ///< memory of the structure itself
    int depth = 0;
    double sah_cost = 0;     ///< SAH cost for trees, 0 where it means nothing
    double refs_per_prim = 1;       ///< primitive references per primitive (> 1 where split or duplicated)
    std::size_t empty_leaves = 0;   ///< empty leaves, or empty cells for the grid
    std::size_t primitives = 0;     ///< primitives in the scene the structure was built over
    /// The primitive kinds its hot loops were compiled for (bvh4, bvh8;
    /// the other structures run the general loops).
    KindSpecialisation specialisation = KindSpecialisation::General;
    double bytes_per_prim() const { return primitives ? double(bytes) / double(primitives) : 0.0; }
};

struct AccelConfig {
    std::string kind = "bvh2";  ///< bvh2 | brute
    KernelChoice kernels;
    int max_leaf_size = 4;
    int sah_bins = 32;
    float traversal_cost = 1.0f;   ///< SAH cost of visiting a node ...
    float intersection_cost = 1.0f;  ///< ... relative to one primitive test
    /// BVH builder (bvh2, bvh4, bvh8): binned | sweep | morton | sbvh
    /// (accel/bvh/bvh_builders.h); the wide layouts collapse its BVH2.
    std::string builder = "binned";
    float spatial_alpha = 1e-5f;     ///< sbvh: overlap (relative to the root) that makes spatial splits worth trying
    float reference_budget = 1.3f;   ///< sbvh: at most this many references per primitive
    /// embree, embree-robust: Embree's build quality, low | medium | high
    /// (RTC_BUILD_QUALITY_*; medium is Embree's own default).
    std::string build_quality = "medium";
    /// bvh4, bvh8: packets that share one walk (accel/bvh/wide_group_traversal.h);
    /// 0: the default (default_wide_packet_config), 1: each packet alone.
    /// kdtree, octree: 1 makes each packet walk alone (their groups have a
    /// fixed size, kKdGroupPackets and octree_group_packets(K)).
    int packet_group = 0;
};

/// Embree's two modes: `embree` (its default, fast mode) and `embree-robust`
/// (RTC_SCENE_FLAG_ROBUST: no hits lost at shared edges, and slower).
inline bool is_embree_kind(std::string_view kind) { return kind == "embree" || kind == "embree-robust"; }

/// The structure `kind` with the given kernels and every other setting at its
/// default (designated initializers would leave -Wextra warning about the rest).
inline AccelConfig accel_config(std::string kind, KernelChoice kernels = {}) {
    AccelConfig config;
    config.kind = std::move(kind);
    config.kernels = kernels;
    return config;
}

class Accel;
std::unique_ptr<Accel> build_accel(const Scene& scene, const AccelConfig& config);

class Accel {
public:
    virtual ~Accel() = default;
    /// Closest hit for each ray (hits[i].prim == kNoPrim on a miss).
    virtual void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const = 0;
    /// Any hit in [tnear, tfar]: occluded[i] = 1 if so.
    virtual void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const = 0;
    /// What the structure is; build_ms is build_accel's measure of its
    /// construction (0 for a structure constructed directly).
    virtual const AccelStats& stats() const { return stats_; }

    /// Packet widths this structure traverses natively (1 is always there).
    virtual bool supports_packet(int width) const { return width == 1; }
    /// The same queries, traced as packets of `width` consecutive rays (the
    /// caller orders rays so that neighbours are coherent). Width 1, or a
    /// structure without packets, runs the single-ray path.
    virtual void intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
        (void)width;
        intersect(rays, hits);
    }
    virtual void occluded_packets(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded_out) const {
        (void)width;
        occluded(rays, occluded_out);
    }

    /// Whether intersect_stream and occluded_stream walk whole streams.
    virtual bool supports_stream() const { return false; }
    /// The same queries for rays whose neighbours go other ways (reflections
    /// off curved surfaces, shadow rays from points all over the scene): the
    /// whole batch walks the structure as one stream where it has streams
    /// (supports_stream: bvh4 and bvh8 with AVX-512), else as packets of
    /// `width`.
    virtual void intersect_stream(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const {
        intersect_packets(width, rays, hits);
    }
    virtual void occluded_stream(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded_out) const {
        occluded_packets(width, rays, occluded_out);
    }

    /// The same queries for rays at times: times[i] is ray i's scene time
    /// (Scene::shutter_fraction), and moving placements (Scene::
    /// moving_instances) sit where they are at that time. The queries above
    /// trace every ray at the shutter's opening. A structure of a static
    /// scene ignores the times.
    virtual void intersect_at(int width, std::span<const Rayf> rays, std::span<const float> times,
                              std::span<Hitf> hits) const {
        (void)times;
        intersect_packets(width, rays, hits);
    }
    virtual void occluded_at(int width, std::span<const Rayf> rays, std::span<const float> times,
                             std::span<std::uint8_t> occluded_out) const {
        (void)times;
        occluded_packets(width, rays, occluded_out);
    }

    /// Traces each ray alone, in the order of the single-ray path, adding its
    /// work to `counts`; hits[i] gets the answer (any_hit: found() = occluded).
    /// Never on a timed path. False where the structure cannot count (Embree).
    virtual bool count_traversal(std::span<const Rayf> rays, bool any_hit, std::span<Hitf> hits,
                                 TraversalCounts& counts) const {
        (void)rays, (void)any_hit, (void)hits, (void)counts;
        return false;
    }

    Hitf intersect1(const Rayf& ray) const {
        Hitf hit;
        intersect({&ray, 1}, {&hit, 1});
        return hit;
    }
    bool occluded1(const Rayf& ray) const {
        std::uint8_t o = 0;
        occluded({&ray, 1}, {&o, 1});
        return o != 0;
    }

protected:
    AccelStats stats_;  ///< filled by each structure's constructor

private:
    friend std::unique_ptr<Accel> build_accel(const Scene& scene, const AccelConfig& config);
};

/// Names accepted by AccelConfig::kind.
std::span<const char* const> accel_kinds();
/// The same names joined by '|', for help and error messages.
std::string accel_kinds_list();

/// Builds the structure the config names over every primitive of `scene`.
/// The scene must outlive the structure. Throws std::invalid_argument for an
/// unknown kind.
std::unique_ptr<Accel> build_accel(const Scene& scene, const AccelConfig& config);

}  // namespace raypack
