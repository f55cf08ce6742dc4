#pragma once
// --offset, shared by render, rays and bench: how secondary rays leave a surface.
#include <string>
#include <vector>

#include "app/commands.h"
#include "render/ray_offset.h"

namespace raypack::app {

/// --offset epsilon|scaled|robust
OptionSpec offset_option_spec();
/// The policy --offset names (kDefaultOffset without it); UsageError otherwise.
OffsetPolicy offset_policy_from(const ParsedArgs& args);
std::string offset_option_help();

}  // namespace raypack::app
