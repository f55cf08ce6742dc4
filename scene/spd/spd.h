#pragma once
// Eric Haines' Standard Procedural Databases, regenerated from the published
// algorithms: the NFF text the SPD 3.14 programs print in their default
// (curves) mode, number for number.
#include <string>
#include <string_view>
#include <vector>

namespace raypack {

/// NFF text of SPD scene NAME at size factor SIZE. Throws std::invalid_argument
/// for an unknown name or a size out of the generator's range.
std::string generate_spd(std::string_view name, int size);

/// Names generate_spd accepts, and each one's default size (the SPD's).
struct SpdGeneratorInfo {
    std::string name;
    int default_size;
    int max_size;
};
std::vector<SpdGeneratorInfo> spd_generators();

}  // namespace raypack
