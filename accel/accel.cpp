#include "accel/accel.h"

#include <stdexcept>

#include "accel/brute/brute_force.h"
#include "accel/bvh/bvh2_accel.h"
#include "accel/bvh/wide_bvh_accel.h"
#include "accel/grid/grid_accel.h"
#include "accel/kdtree/kdtree_accel.h"
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

std::unique_ptr<Accel> build_accel(const Scene& scene, const AccelConfig& config) {
    if (config.kind == "bvh2") return std::make_unique<Bvh2Accel>(scene, config);
#if defined(__SSE4_2__)
    if (config.kind == "bvh4") return std::make_unique<Bvh4Accel>(scene, config);
#endif
#if defined(__AVX2__)
    if (config.kind == "bvh8") return std::make_unique<Bvh8Accel>(scene, config);
#endif
    if (config.kind == "grid") return std::make_unique<GridAccel>(scene, config);
    if (config.kind == "kdtree") return std::make_unique<KdTreeAccel>(scene, config);
    if (config.kind == "octree") return std::make_unique<OctreeAccel>(scene, config);
    if (config.kind == "brute") return std::make_unique<BruteForce>(scene, config.kernels);
#ifdef RAYPACK_HAVE_EMBREE
    if (is_embree_kind(config.kind))
        return std::make_unique<EmbreeAccel>(scene, embree_options(config.kind == "embree-robust", config.build_quality));
#endif
    throw std::invalid_argument("unknown acceleration structure '" + config.kind + "' (expected " + accel_kinds_list() + ")");
}

}  // namespace raypack
