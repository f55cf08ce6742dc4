#include "render/ray_log.h"

#include <stdexcept>
#include <string>

namespace raypack {

void RayLog::add(Kind kind, std::span<const Rayf> rays, std::span<const float> times) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (count_ + rays.size() > max_rays_)
        throw std::runtime_error("--save-rays: the render traces more than " + std::to_string(max_rays_) + " rays (" +
                                 std::to_string(max_rays_ * sizeof(Rayf) >> 20) +
                                 " MiB), more than the memory can hold; render fewer samples or a smaller image");
    count_ += rays.size();
    rays_[kind].insert(rays_[kind].end(), rays.begin(), rays.end());
    times_[kind].insert(times_[kind].end(), times.begin(), times.end());
}

const char* RayLog::name(Kind kind) {
    switch (kind) {
        case Eye: return "eye";
        case Bounce: return "bounce";
        case Shadow: return "shadow";
    }
    return "eye";
}

}  // namespace raypack
