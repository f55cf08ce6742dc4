#pragma once
// The configuration trace and render use when the command line names no
// structure, builder or packet width: the fastest one for the kind of rays,
// as measured (app/default_config.cpp says where).
#include <span>
#include <string>

#include "kernels/ray.h"

namespace raypack::app {

/// The ray sets the measured table distinguishes.
enum class RayWorkload { Camera, Shadow, Diffuse };

const char* workload_name(RayWorkload workload);

/// Shadow for any-hit rays; camera when every ray starts at one point (a
/// pinhole camera's rays); diffuse (incoherent closest-hit rays) otherwise.
RayWorkload classify_workload(std::span<const Rayf> rays, bool any_hit);

struct TraceConfig {
    std::string accel;
    int packet;
    /// Batches walk the structure as streams (Accel::intersect_stream).
    bool stream = false;
};

/// The fastest measured configuration for `workload`, with the packet width
/// narrowed to what this build compiles (16 needs AVX-512).
TraceConfig fastest_config(RayWorkload workload);

}  // namespace raypack::app
