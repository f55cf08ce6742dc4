// Registry of the SPD generators (Haines 1987, "A Proposal for Standard
// Graphics Environments"): name -> size range -> generator function.
#include "scene/spd/spd.h"

#include <stdexcept>
#include <string>

#include "scene/spd/generators.h"

namespace raypack {

namespace {

struct Entry {
    const char* name;
    int default_size;
    int max_size;
    std::string (*generate)(int size);
};

// Default size factors as in SPD 3.14. SPD itself has no upper bound; ours
// keep a scene under about a million primitives, and mount stops at 7
// because its original hash shifts by (7 - size) bits.
constexpr Entry kGenerators[] = {
    {"balls", 4, 6, spd::generate_balls},
    {"tetra", 6, 9, spd::generate_tetra},
    {"mount", 6, 7, spd::generate_mount},
    {"rings", 7, 20, spd::generate_rings},
    {"tree", 11, 18, spd::generate_tree},
    {"gears", 4, 12, spd::generate_gears},
    {"teapot", 6, 64, spd::generate_teapot},
    {"cornell", 1, 2, spd::generate_cornell},
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
        return e.generate(size);
    }
    throw std::invalid_argument("generate_spd: unknown SPD generator '" + std::string(name) +
                                "' (valid: " + valid_names() + ")");
}

}  // namespace raypack
