#include "accel/accel.h"

#include <array>
#include <stdexcept>

#include "accel/brute/brute_force.h"
#include "accel/bvh/bvh2_accel.h"

namespace raypack {

std::span<const char* const> accel_kinds() {
    static constexpr std::array<const char*, 2> kinds = {"bvh2", "brute"};
    return kinds;
}

std::unique_ptr<Accel> build_accel(const Scene& scene, const AccelConfig& config) {
    if (config.kind == "bvh2") return std::make_unique<Bvh2Accel>(scene, config);
    if (config.kind == "brute") return std::make_unique<BruteForce>(scene, config.kernels);
    throw std::invalid_argument("unknown acceleration structure '" + config.kind + "' (expected bvh2 or brute)");
}

}  // namespace raypack
