#pragma once
// Options shared by render and trace that choose the structure and kernels.
#include <string>
#include <vector>

#include "accel/accel.h"
#include "app/commands.h"

namespace raypack::app {

/// --accel, --builder, --sphere, --triangle, --slabs, --precision, --rcp, --packet
std::vector<OptionSpec> accel_option_specs();
/// --sphere, --triangle, --slabs, --precision, --rcp: the kernel variants.
std::vector<OptionSpec> kernel_option_specs();
KernelChoice kernel_choice_from(const ParsedArgs& args);
std::string kernel_options_help();
/// The option values that name each kernel variant.
const char* sphere_method_name(SphereMethod m);
const char* triangle_method_name(TriangleMethod m);
const char* slab_method_name(SlabMethod m);
const char* precision_name(Precision p);
const char* rcp_method_name(RcpMethod m);
/// e.g. "moeller triangles, geometric spheres, robust slabs, exact rcp, float".
std::string kernel_choice_summary(const KernelChoice& k);
AccelConfig accel_config_from(const ParsedArgs& args);
/// --embree-quality low|medium|high (default medium); a usage error unless
/// `accels` (one kind, or a comma-separated list) names an Embree mode.
std::string embree_quality_from(const ParsedArgs& args, const std::string& accels);
/// --packet K, checked against what `accel` traverses natively.
int packet_width_from(const ParsedArgs& args, const Accel& accel);
std::string accel_options_help();
/// True when the command line names none of --accel, --packet, --builder:
/// trace and render then run the fastest measured configuration
/// (app/default_config.h).
bool uses_fastest_config(const ParsedArgs& args);
/// `packet`, or the next narrower width `accel` traverses natively.
int supported_packet(const Accel& accel, int packet);

/// --threads T: limits oneTBB for the life of the returned object.
class ThreadLimit {
public:
    explicit ThreadLimit(int threads);
    ~ThreadLimit();
    ThreadLimit(const ThreadLimit&) = delete;
    ThreadLimit& operator=(const ThreadLimit&) = delete;
    int threads() const { return threads_; }

private:
    struct Impl;
    Impl* impl_;
    int threads_;
};

}  // namespace raypack::app
