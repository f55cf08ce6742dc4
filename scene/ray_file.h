#pragma once
// The .rays / .hits exchange format (docs/rays.md): the same rays traced by
// raypack and by any other tracer, compared ray by ray.
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "kernels/ray.h"

namespace raypack {

enum class RayKind : std::uint32_t { ClosestHit = 0, AnyHit = 1 };

struct RayFile {
    RayKind kind = RayKind::ClosestHit;
    std::vector<Rayf> rays;
    /// Version 2 files (`RAYS0002`): each ray's scene time (motion blur);
    /// empty for version 1, whose rays are at the shutter's opening.
    std::vector<float> times;
};

/// Reads both versions. Throws std::runtime_error naming the file and the
/// problem (bad magic, truncated, unknown kind, non-finite origin,
/// direction or time, absurd count).
RayFile read_rays(const std::string& path);
std::vector<Hitf> read_hits(const std::string& path);
/// The same readers on a file's bytes already in memory; `name` is the
/// file the errors name.
RayFile parse_rays(std::string_view bytes, const std::string& name);
std::vector<Hitf> parse_hits(std::string_view bytes, const std::string& name);

/// Both write to a temporary file beside `path` and rename it into place, so
/// an existing file is never left half-written.
/// With `times` (one per ray) a version 2 file, else version 1.
void write_rays(const std::string& path, RayKind kind, std::span<const Rayf> rays, std::span<const float> times = {});
void write_hits(const std::string& path, std::span<const Hitf> hits);

}  // namespace raypack
