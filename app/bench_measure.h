#pragma once
// The measuring steps of `raypack bench` for one structure and ray set:
// check against the oracle, count the work per ray, time the passes.
#include <optional>
#include <string>
#include <vector>

#include "accel/accel.h"
#include "render/ray_offset.h"
#include "scene/scene.h"

namespace raypack::app {

/// A named ray set and the query it asks (closest hit or occlusion).
struct BenchRays {
    std::string name;  ///< camera | shadow | diffuse | file:NAME
    bool any_hit = false;
    std::vector<Rayf> rays;
};

/// The standard sets of measure/ray_sets.h at w x h (diffuse: seed 1), secondary
/// origins moved off the surface by `offset`.
BenchRays make_bench_rays(const Scene& scene, const std::string& kind, int width, int height,
                          OffsetPolicy offset = kDefaultOffset);
/// A docs/rays.md file; throws naming the file when it cannot be read.
BenchRays load_bench_rays(const std::string& path);

/// A deterministic part of a ray set, in blocks of consecutive rays spread
/// evenly over it (so packets stay as coherent as in the full set), with the
/// oracle's answers.
struct OracleSample {
    std::vector<std::size_t> index;  ///< positions in the full set
    std::vector<Rayf> rays;
    std::vector<Hitf> expected;      ///< brute force (any hit: found() = occluded)
};
/// Brute force with the primitive tests and precision of `kernels` (it has
/// no boxes, so slabs and reciprocals do not apply): a structure is checked
/// for finding what its own tests find, not for the tests' rounding.
OracleSample oracle_sample(const Scene& scene, const BenchRays& set, std::size_t max_rays, KernelChoice kernels = {});

/// Traces the sample as the timed loop does (packets of `packet`) and
/// compares: hit or miss identical, t within relative 1e-5, occlusion
/// identical. Throws std::runtime_error naming `context` and the first
/// differing ray.
void validate_against_oracle(const Accel& accel, int packet, const BenchRays& set, const OracleSample& sample,
                             const std::string& context);

/// Havran's measures per ray (accel/traversal_counts.h) over a
/// deterministic sample of up to `max_rays` rays (single-ray counting walks,
/// in parallel); empty when the structure cannot count.
struct WorkPerRay {
    double n_it = 0, n_ts = 0, n_ets = 0, n_eets = 0;
};
std::optional<WorkPerRay> work_per_ray(const Accel& accel, const BenchRays& set, std::size_t max_rays);

/// One untimed warm-up pass, then `repeat` timed passes over all rays in
/// batches spread over the threads; milliseconds per pass. `hits_found`
/// gets the number of hits (or occluded rays) of the last pass.
std::vector<double> time_passes(const Accel& accel, int packet, const BenchRays& set, int repeat,
                                std::size_t& hits_found);

}  // namespace raypack::app
