#include "accel/accel.h"

#include <array>
#include <stdexcept>

#include "accel/brute/brute_force.h"
#include "accel/bvh/bvh2_accel.h"
#include "accel/grid/grid_accel.h"
#ifdef RAYPACK_HAVE_EMBREE
#include "accel/embree/embree_accel.h"
#endif

namespace raypack {

std::span<const char* const> accel_kinds() {
#ifdef RAYPACK_HAVE_EMBREE
    static constexpr std::array<const char*, 4> kinds = {"bvh2", "grid", "brute", "embree"};
#else
    static constexpr std::array<const char*, 3> kinds = {"bvh2", "grid", "brute"};
#endif
    return kinds;
}

std::string accel_kinds_list() {
    std::string list;
    for (const char* k : accel_kinds()) {
        if (!list.empty()) list += '|';
        list += k;
    }
    return list;
}

std::unique_ptr<Accel> build_accel(const Scene& scene, const AccelConfig& config) {
    if (config.kind == "bvh2") return std::make_unique<Bvh2Accel>(scene, config);
    if (config.kind == "grid") return std::make_unique<GridAccel>(scene, config);
    if (config.kind == "brute") return std::make_unique<BruteForce>(scene, config.kernels);
#ifdef RAYPACK_HAVE_EMBREE
    if (config.kind == "embree") return std::make_unique<EmbreeAccel>(scene);
#endif
    throw std::invalid_argument("unknown acceleration structure '" + config.kind + "' (expected " + accel_kinds_list() + ")");
}

}  // namespace raypack
