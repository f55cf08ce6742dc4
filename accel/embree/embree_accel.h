#pragma once
// Embree 3 as an independent reference: same scene, same rays, a different
// BVH, different primitive tests. Compiled only when CMake found Embree.
#ifdef RAYPACK_HAVE_EMBREE

#include <array>
#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>
#include <vector>

#include <embree3/rtcore.h>

#include "accel/accel.h"

namespace raypack {

/// One NFF cone in its own frame: origin at the base centre, w along the
/// axis, u and v across it; radius rb + k z for 0 <= z <= h.
struct EmbreeCone {
    Vec3d base, u, v, w;
    double h = 0, rb = 0, k = 0;
};

/// How Embree is run. The defaults are Embree's own: fast mode (no
/// RTC_SCENE_FLAG_ROBUST) and medium build quality.
/// Auto: a packet whose rays share one origin runs in the coherent context
/// (RTC_INTERSECT_CONTEXT_FLAG_COHERENT), others in the incoherent one. The
/// fixed choices exist for tests and measurements.
enum class EmbreeContext { Auto, Coherent, Incoherent };

struct EmbreeOptions {
    bool robust = false;
    RTCBuildQuality quality = RTC_BUILD_QUALITY_MEDIUM;
    EmbreeContext context = EmbreeContext::Auto;
};

/// `quality` is low | medium | high; anything else throws std::invalid_argument.
EmbreeOptions embree_options(bool robust, const std::string& quality);
/// "low", "medium" or "high".
const char* embree_quality_name(RTCBuildQuality quality);

/// Triangles become RTC_GEOMETRY_TYPE_TRIANGLE and spheres
/// RTC_GEOMETRY_TYPE_SPHERE_POINT. NFF cones are user geometry with their own
/// intersector (see the .cpp for why not RTC_GEOMETRY_TYPE_CONE_LINEAR_CURVE).
/// Hits report raypack's global primitive numbers.
class EmbreeAccel final : public Accel {
public:
    explicit EmbreeAccel(const Scene& scene, EmbreeOptions options = {});
    ~EmbreeAccel() override;
    EmbreeAccel(const EmbreeAccel&) = delete;
    EmbreeAccel& operator=(const EmbreeAccel&) = delete;

    void intersect(std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;

    /// Packets of 4, 8 and 16 go through rtcIntersect4/8/16 and
    /// rtcOccluded4/8/16; width 1 through rtcIntersect1 / rtcOccluded1.
    bool supports_packet(int width) const override {
        return width == 1 || width == 4 || width == 8 || width == 16;
    }
    void intersect_packets(int width, std::span<const Rayf> rays, std::span<Hitf> hits) const override;
    void occluded_packets(int width, std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const override;
    /// Whether this Embree build traces packets of `width` natively
    /// (RTC_DEVICE_PROPERTY_NATIVE_RAY4/8/16_SUPPORTED); otherwise Embree
    /// emulates them. Width 1 is always native.
    bool native_packet(int width) const;

private:
    template <int K>
    void intersect_k(std::span<const Rayf> rays, std::span<Hitf> hits) const;
    template <int K>
    void occluded_k(std::span<const Rayf> rays, std::span<std::uint8_t> occluded) const;

    void build(const Scene& scene, const EmbreeOptions& options);
    bool coherent(bool one_origin) const;
    static bool memory_monitor(void* self, ssize_t bytes, bool post);
    static void on_error(void* self, RTCError code, const char* message);
    [[noreturn]] void fail(const std::string& what) const;

    RTCDevice device_ = nullptr;
    RTCScene scene_ = nullptr;
    /// Embree geometry id -> (primID -> raypack's global primitive number).
    std::vector<std::vector<std::uint32_t>> to_global_;
    std::vector<EmbreeCone> cones_;  ///< user data of the cone geometry
    std::array<std::uint32_t, 8> base_{};  ///< geometry -> global number of its primitive 0
    bool consecutive_ = false;             ///< every geometry's global numbers are base_ + primID
    EmbreeOptions options_;
    std::atomic<std::int64_t> allocated_{0};
    mutable std::mutex error_mutex_;
    std::string first_error_;  ///< Embree's own message, reported by fail()
    bool native_[3] = {false, false, false};  ///< RAY4, RAY8, RAY16
};

}  // namespace raypack

#endif  // RAYPACK_HAVE_EMBREE
