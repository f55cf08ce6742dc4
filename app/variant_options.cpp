#include "app/variant_options.h"

namespace raypack::app {

OptionSpec offset_option_spec() { return {"--offset", "", 1}; }

OffsetPolicy offset_policy_from(const ParsedArgs& args) {
    if (!args.has("--offset")) return kDefaultOffset;
    const std::string name = args.text("--offset");
    if (const auto policy = parse_offset_policy(name)) return *policy;
    throw UsageError("--offset: expected " + offset_policy_list() + ", got '" + name + "'");
}

std::string offset_option_help() {
    return std::string("  --offset ") + offset_policy_list() +
           "  secondary-ray origins: fixed 1e-4, 1e-4 x max(|p|, 1e-3 x extent),\n"
           "                 or Waechter & Binder's 256 ULPs (Ray Tracing Gems ch. 6) (default " +
           offset_policy_name(kDefaultOffset) + ")\n";
}

}  // namespace raypack::app
