#pragma once
// Eric Haines' Standard Procedural Databases, regenerated from the published
// algorithms: the NFF text the SPD 3.14 programs print in their default
// (curves) mode, number for number.
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace raypack {

/// Most primitives a generated scene may have: what the wide BVHs' leaf
/// references address (2^26 blocks of 8).
inline constexpr std::uint64_t kMaxSpdPrimitives = std::uint64_t(1) << 29;

/// Memory a generated scene is budgeted per primitive, from its NFF text to
/// a built structure: peak resident memory of `raypack trace` measured at
/// 330 (tetra 9) to 380 bytes (balls 6) per primitive, with a margin.
inline constexpr std::uint64_t kSpdBytesPerPrimitive = 512;

/// NFF text of SPD scene NAME at size factor SIZE. Throws std::invalid_argument
/// for an unknown name or a size out of the generator's range (1 to the
/// largest size under kMaxSpdPrimitives), and std::runtime_error when the
/// scene would need more memory than is available (scene/memory_budget.h).
std::string generate_spd(std::string_view name, int size);

/// Primitives (polygons counted as their triangles) of generate_spd(NAME,
/// SIZE) once loaded; 0 for an unknown name or size out of range.
std::uint64_t spd_primitives(std::string_view name, int size);

/// Names generate_spd accepts, and each one's default size (the SPD's).
struct SpdGeneratorInfo {
    std::string name;
    int default_size;
    int max_size;  ///< the largest size under kMaxSpdPrimitives
};
std::vector<SpdGeneratorInfo> spd_generators();

}  // namespace raypack
