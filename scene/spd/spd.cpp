// Registry of the SPD generators (Haines 1987, "A Proposal for Standard
// Graphics Environments"): name -> size range -> generator function.
#include "scene/spd/spd.h"

#include <stdexcept>
#include <string>

#include "scene/memory_budget.h"
#include "scene/spd/generators.h"

namespace raypack {

namespace {

struct Entry {
    const char* name;
    int default_size;
    int limit;  ///< the generator's own largest size (its arithmetic), or 0
    std::string (*generate)(int size);
    double (*primitives)(int size);  ///< primitives as loaded (polygons as triangles; with the objects')
    /// Bytes budgeted for loading and tracing it; nullptr: kSpdBytesPerPrimitive a primitive.
    double (*bytes)(int size) = nullptr;
};

double power(double base, int exponent) {
    double p = 1.0;
    for (int i = 0; i < exponent; ++i) p *= base;
    return p;
}

// Default size factors as in SPD 3.14. SPD itself has no upper bound; ours
// is what raypack's structures address (kMaxPrimitives) and what fits in
// memory (generate_spd). mount stops at 15: its original hash shifts by
// (15 - size) bits.
constexpr Entry kGenerators[] = {
    {"balls", 4, 0, spd::generate_balls, [](int n) { return (power(9, n + 1) - 1.0) / 8.0 + 2.0; }},
    {"tetra", 6, 0, spd::generate_tetra, [](int n) { return power(4, n); }},
    // Stored: one object of 4^min(n, 6) triangles and at most 64
    // placements for each further 3 levels; 15 is the deepest whose 4^n
    // instanced triangles have 32-bit hit ids.
    {"tetra-instanced", 6, 15, spd::generate_tetra_instanced, [](int n) {
         if (n <= 6) return power(4, n) + 1.0;  // the object, placed once
         const int groups = (n - 7) / 3;        // objects of 64 placements
         return power(4, 6) + 64.0 * groups + power(4, n - 6 - 3 * groups);
     }},
    {"mount", 6, 15, spd::generate_mount, [](int n) { return 2.0 * power(4, n) + 4.0; }},
    {"rings", 7, 0, spd::generate_rings, [](int n) { return 10.0 * n * (n + 1.0) * (2.0 * n + 1.0) + 2.0; }},
    {"tree", 11, 0, spd::generate_tree, [](int n) { return 2.0 * (power(2, n + 1) - 1.0) + 2.0; }},
    {"gears", 4, 0, spd::generate_gears, [](int n) { return 572.0 * n * n * n + 2.0; }},
    {"teapot", 6, 0, spd::generate_teapot, [](int n) { return 66.0 * n * n - 8.0 * n; }},
    {"cornell", 1, 2, spd::generate_cornell, [](int n) { return n == 1 ? 32.0 : 14.0; }},
    // One field of (2^n + 1)^2 samples and mount's 4 spheres; its memory
    // is per sample (text, floats, pyramid: ~40 bytes), not per primitive.
    {"terrain", 9, 13, spd::generate_terrain, [](int) { return 5.0; },
     [](int n) { return 40.0 * (power(2, n) + 1.0) * (power(2, n) + 1.0); }},
};

/// The largest size whose scene raypack can address.
int max_size(const Entry& e) {
    int size = 1;
    while ((e.limit == 0 || size < e.limit) && e.primitives(size + 1) <= double(kMaxSpdPrimitives)) ++size;
    return size;
}

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
    for (const Entry& e : kGenerators) out.push_back({e.name, e.default_size, max_size(e)});
    return out;
}

std::uint64_t spd_primitives(std::string_view name, int size) {
    for (const Entry& e : kGenerators)
        if (name == e.name && size >= 1 && size <= max_size(e)) return std::uint64_t(e.primitives(size));
    return 0;
}

std::string generate_spd(std::string_view name, int size) {
    for (const Entry& e : kGenerators) {
        if (name != e.name) continue;
        if (size < 1 || size > max_size(e))
            throw std::invalid_argument("generate_spd: size " + std::to_string(size) + " out of range 1.." +
                                        std::to_string(max_size(e)) + " for '" + std::string(name) + "'" +
                                        (size > max_size(e) && e.limit == 0 ? " (larger sizes exceed " +
                                                                        std::to_string(kMaxSpdPrimitives) +
                                                                        " primitives)"
                                                                  : ""));
        const auto prims = std::uint64_t(e.primitives(size));
        require_memory(e.bytes ? std::uint64_t(e.bytes(size)) : prims * kSpdBytesPerPrimitive,
                       std::string(name) + " size " + std::to_string(size) + " (" + std::to_string(prims) +
                           " primitives)");
        return e.generate(size);
    }
    throw std::invalid_argument("generate_spd: unknown SPD generator '" + std::string(name) +
                                "' (valid: " + valid_names() + ")");
}

}  // namespace raypack
