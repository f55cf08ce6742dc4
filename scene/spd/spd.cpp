// Registry of the SPD generators (Haines 1987, "A Proposal for Standard
// Graphics Environments"): name -> size range -> generator function.
#include "scene/spd/spd.h"

#include <stdexcept>
#include <string>

namespace raypack {

namespace {

struct Entry {
    const char* name;
    int default_size;
    int max_size;
};

// Sizes as in SPD 3.14: default size factor and the largest the program accepts.
constexpr Entry kGenerators[] = {
    {"balls", 4, 5},
    {"tetra", 6, 10},
    {"mount", 6, 8},
};

std::string valid_names() {
    std::string out;
    for (const Entry& e : kGenerators) {
        if (!out.empty()) out += ", ";
        out += e.name;
    }
    return out;
}

}  // namespace

std::vector<SpdGeneratorInfo> spd_generators() {
    std::vector<SpdGeneratorInfo> out;
    for (const Entry& e : kGenerators) out.push_back({e.name, e.default_size, e.max_size});
    return out;
}

std::string generate_spd(std::string_view name, int size) {
    for (const Entry& e : kGenerators) {
        if (name != e.name) continue;
        if (size < 1 || size > e.max_size)
            throw std::invalid_argument("generate_spd: size " + std::to_string(size) + " out of range 1.." +
                                        std::to_string(e.max_size) + " for '" + std::string(name) + "'");
        throw std::invalid_argument("generate_spd: generator '" + std::string(name) + "' not implemented yet");
    }
    throw std::invalid_argument("generate_spd: unknown SPD generator '" + std::string(name) +
                                "' (valid: " + valid_names() + ")");
}

}  // namespace raypack
