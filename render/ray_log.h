#pragma once
// The rays a render traced, by kind, in the order it traced them, so that
// `raypack trace` can time exactly the render's own rays (`raypack render
// --save-rays`; scripts/integrator_throughput.py compares the two rates).
#include <cstddef>
#include <cstdint>
#include <mutex>
#include <span>
#include <vector>

#include "kernels/ray.h"

namespace raypack {

class RayLog {
public:
    /// Eye: camera rays; bounce: closest-hit rays after them (reflected,
    /// refracted, diffuse and glossy); shadow: any-hit rays.
    enum Kind : int { Eye, Bounce, Shadow };
    static constexpr int kKinds = 3;

    /// At most `max_rays` rays in all; add() throws std::runtime_error past it.
    explicit RayLog(std::uint64_t max_rays) : max_rays_(max_rays) {}

    /// Appends one query's rays (and their scene times, if the render samples
    /// time: one per ray, else empty). Safe from any thread.
    void add(Kind kind, std::span<const Rayf> rays, std::span<const float> times = {});

    std::span<const Rayf> rays(Kind kind) const { return rays_[kind]; }
    /// Empty unless the render's rays carried times.
    std::span<const float> times(Kind kind) const { return times_[kind]; }

    static const char* name(Kind kind);

private:
    std::uint64_t max_rays_;
    std::uint64_t count_ = 0;
    std::mutex mutex_;
    std::vector<Rayf> rays_[kKinds];
    std::vector<float> times_[kKinds];
};

}  // namespace raypack
