// The SPD generators against the reference NFF files in scenes/, which are
// the unmodified output of Eric Haines' SPD 3.14 programs.
#include <gtest/gtest.h>
#include "tests/test_paths.h"

#include <algorithm>
#include <cctype>
#include <cstddef>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/load.h"
#include "scene/memory_budget.h"
#include "scene/spd/spd.h"

namespace {

std::string read_text(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw std::runtime_error("cannot open " + path);
    std::ostringstream ss;
    ss << in.rdbuf();
    return ss.str();
}

std::vector<std::string> split_lines(const std::string& text) {
    std::vector<std::string> lines;
    std::istringstream in(text);
    for (std::string line; std::getline(in, line);) lines.push_back(line);
    return lines;
}

std::string reference_path(const std::string& name) {
    return std::string(RAYPACK_SOURCE_DIR) + "/scenes/" + name + ".nff";
}

/// Compares line by line and reports the first differing lines (at most a
/// few) with their line numbers, then the whole-text equality.
void expect_matches_reference(const std::string& name, int size) {
    const std::string generated = raypack::generate_spd(name, size);
    const std::string reference = read_text(reference_path(name));
    const std::vector<std::string> got = split_lines(generated);
    const std::vector<std::string> want = split_lines(reference);

    int reported = 0;
    const std::size_t common = std::min(got.size(), want.size());
    for (std::size_t i = 0; i < common && reported < 5; ++i) {
        if (got[i] != want[i]) {
            ADD_FAILURE() << name << " line " << (i + 1) << " differs:\n  generated: " << got[i]
                          << "\n  reference: " << want[i];
            ++reported;
        }
    }
    EXPECT_EQ(got.size(), want.size()) << name << ": line counts differ";
    EXPECT_TRUE(generated == reference) << name << ": text is not byte-identical";
}

/// Number of statements per NFF keyword (first token of non-vertex lines).
std::map<std::string, int> count_keywords(const std::string& text) {
    std::map<std::string, int> counts;
    for (const std::string& line : split_lines(text)) {
        std::istringstream in(line);
        std::string word;
        in >> word;
        if (!word.empty() && (std::isalpha(static_cast<unsigned char>(word[0])) != 0)) ++counts[word];
    }
    return counts;
}

int power(int base, int exp) {
    int r = 1;
    for (int i = 0; i < exp; ++i) r *= base;
    return r;
}

}  // namespace

TEST(SpdGenerators, BallsMatchesReference) {
    expect_matches_reference("balls", 4);
}
TEST(SpdGenerators, TetraMatchesReference) {
    expect_matches_reference("tetra", 6);
}
TEST(SpdGenerators, MountMatchesReference) {
    expect_matches_reference("mount", 6);
}
TEST(SpdGenerators, RingsMatchesReference) {
    expect_matches_reference("rings", 7);
}
TEST(SpdGenerators, TreeMatchesReference) {
    expect_matches_reference("tree", 11);
}
TEST(SpdGenerators, GearsMatchesReference) {
    expect_matches_reference("gears", 4);
}
TEST(SpdGenerators, TeapotMatchesReference) {
    expect_matches_reference("teapot", 6);
}

TEST(SpdGenerators, BallsCountsFollowFormula) {
    // Every sphere has nine children down to depth SIZE: sum of 9^k, k = 0..SIZE.
    for (int size = 1; size <= 3; ++size) {
        int spheres = 0;
        for (int k = 0; k <= size; ++k) spheres += power(9, k);
        auto counts = count_keywords(raypack::generate_spd("balls", size));
        EXPECT_EQ(counts["s"], spheres) << "size " << size;
        EXPECT_EQ(counts["p"], 1) << "size " << size;
        EXPECT_EQ(counts["l"], 3) << "size " << size;
    }
    EXPECT_EQ(count_keywords(raypack::generate_spd("balls", 1))["s"], 10);
}

TEST(SpdGenerators, TetraCountsFollowFormula) {
    // 4^SIZE triangles: four sub-tetrahedra per level, four faces at the bottom.
    for (int size = 1; size <= 4; ++size) {
        auto counts = count_keywords(raypack::generate_spd("tetra", size));
        EXPECT_EQ(counts["p"], power(4, size)) << "size " << size;
        EXPECT_EQ(counts["s"], 0) << "size " << size;
    }
}

TEST(SpdGenerators, MountCountsFollowFormula) {
    // 2 * 4^SIZE triangles (a 2^SIZE square grid) plus the four glass spheres.
    for (int size = 1; size <= 4; ++size) {
        auto counts = count_keywords(raypack::generate_spd("mount", size));
        EXPECT_EQ(counts["p"], 2 * power(4, size)) << "size " << size;
        EXPECT_EQ(counts["s"], 4) << "size " << size;
    }
}

TEST(SpdGenerators, RingsCountsFollowFormula) {
    // Layer k (1-based) holds k*k objects of 30 cylinders and 30 spheres:
    // 30 * sum k^2 = 5 * SIZE * (SIZE+1) * (2*SIZE+1), plus the wall.
    for (int size = 1; size <= 3; ++size) {
        auto counts = count_keywords(raypack::generate_spd("rings", size));
        const int expected = 5 * size * (size + 1) * (2 * size + 1);
        EXPECT_EQ(counts["s"], expected) << "size " << size;
        EXPECT_EQ(counts["c"], expected) << "size " << size;
        EXPECT_EQ(counts["p"], 1) << "size " << size;
    }
}

TEST(SpdGenerators, TreeCountsFollowFormula) {
    // A full binary tree of depth SIZE: 2^(SIZE+1) - 1 branches, each a cone
    // and a sphere, plus the field.
    for (int size = 1; size <= 4; ++size) {
        auto counts = count_keywords(raypack::generate_spd("tree", size));
        EXPECT_EQ(counts["c"], power(2, size + 1) - 1) << "size " << size;
        EXPECT_EQ(counts["s"], power(2, size + 1) - 1) << "size " << size;
        EXPECT_EQ(counts["p"], 1) << "size " << size;
        EXPECT_EQ(counts["l"], 7) << "size " << size;
    }
}

TEST(SpdGenerators, GearsCountsFollowFormula) {
    // SIZE^3 gears, each two 144-gon faces and 4*36 side quads, plus the floor.
    for (int size = 1; size <= 3; ++size) {
        const std::string text = raypack::generate_spd("gears", size);
        const int gears = size * size * size;
        EXPECT_EQ(count_keywords(text)["p"], gears * (2 + 4 * 36) + 1) << "size " << size;
        int big_faces = 0;
        for (const std::string& line : split_lines(text))
            if (line == "p 144") ++big_faces;
        EXPECT_EQ(big_faces, 2 * gears) << "size " << size;
        EXPECT_EQ(count_keywords(text)["l"], 5) << "size " << size;
    }
}

TEST(SpdGenerators, TeapotCountsFollowFormula) {
    // 32 patches x SIZE^2 cells x 2 triangles, less the 8*SIZE degenerate
    // ones at the lid and bottom cusps; SIZE^2 board squares.
    for (int size = 2; size <= 4; ++size) {
        auto counts = count_keywords(raypack::generate_spd("teapot", size));
        EXPECT_EQ(counts["pp"], 64 * size * size - 8 * size) << "size " << size;
        EXPECT_EQ(counts["p"], size * size) << "size " << size;
    }
}

TEST(SpdGenerators, ListsGeneratorsWithDefaults) {
    const auto gens = raypack::spd_generators();
    std::map<std::string, int> defaults;
    for (const auto& g : gens) {
        defaults[g.name] = g.default_size;
        EXPECT_GE(g.max_size, g.default_size) << g.name;
    }
    EXPECT_EQ(defaults["balls"], 4);
    EXPECT_EQ(defaults["tetra"], 6);
    EXPECT_EQ(defaults["mount"], 6);
    EXPECT_EQ(defaults["rings"], 7);
    EXPECT_EQ(defaults["tree"], 11);
    EXPECT_EQ(defaults["gears"], 4);
    EXPECT_EQ(defaults["teapot"], 6);
    EXPECT_EQ(defaults["cornell"], 1);
    EXPECT_EQ(defaults["terrain"], 9);
    EXPECT_EQ(defaults["tetra-instanced"], 6);
    EXPECT_EQ(gens.size(), 10u);
}

TEST(SpdGenerators, RejectsUnknownNamesAndBadSizes) {
    EXPECT_THROW(raypack::generate_spd("nosuch", 1), std::invalid_argument);
    EXPECT_THROW(raypack::generate_spd("", 1), std::invalid_argument);
    EXPECT_THROW(raypack::generate_spd("BALLS", 1), std::invalid_argument);
    for (const auto& g : raypack::spd_generators()) {
        EXPECT_THROW(raypack::generate_spd(g.name, 0), std::invalid_argument) << g.name;
        EXPECT_THROW(raypack::generate_spd(g.name, -1), std::invalid_argument) << g.name;
        EXPECT_THROW(raypack::generate_spd(g.name, g.max_size + 1), std::invalid_argument) << g.name;
    }
    try {
        raypack::generate_spd("nosuch", 1);
    } catch (const std::invalid_argument& e) {
        // The message names the valid generators.
        EXPECT_NE(std::string(e.what()).find("balls"), std::string::npos);
        EXPECT_NE(std::string(e.what()).find("mount"), std::string::npos);
    }
}

TEST(SpdGenerators, PrimitiveCountsAreTheLoadedScenes) {
    // spd_primitives (what the size limit and the memory check use) against
    // the scene as loaded, polygons triangulated.
    for (const auto& g : raypack::spd_generators()) {
        for (int size = 1; size <= std::min(g.name == "tetra-instanced" ? 11 : 3, g.max_size); ++size) {
            const raypack::Scene scene = raypack::load_scene("gen:" + g.name + ":" + std::to_string(size));
            std::size_t stored = scene.primitive_count();
            for (const auto& object : scene.objects) stored += object->primitive_count();
            EXPECT_EQ(raypack::spd_primitives(g.name, size), stored) << g.name << " " << size;
        }
        EXPECT_EQ(raypack::spd_primitives(g.name, g.max_size + 1), 0u) << g.name;
    }
    EXPECT_EQ(raypack::spd_primitives("tetra", 10), 1048576u);  // the million triangles
    EXPECT_EQ(raypack::spd_primitives("mount", 10), 2u * 1048576u + 4u);
}

TEST(SpdGenerators, SizesStopAtWhatTheStructuresAddress) {
    for (const auto& g : raypack::spd_generators()) {
        EXPECT_LE(raypack::spd_primitives(g.name, g.max_size), raypack::kMaxSpdPrimitives) << g.name;
    }
    std::map<std::string, int> max;
    for (const auto& g : raypack::spd_generators()) max[g.name] = g.max_size;
    EXPECT_EQ(max["tetra"], 14);  // 4^14 = 2^28 triangles; 4^15 is over 2^29
    EXPECT_EQ(max["mount"], 13);
    EXPECT_EQ(max["balls"], 9);
    EXPECT_EQ(max["cornell"], 2);
    EXPECT_EQ(max["terrain"], 13);  // (2^13 + 1)^2 samples, under the 2^28 an `hf` may have
}

TEST(SpdGenerators, MountAboveItsOriginalRangeIsDefined) {
    // Size 8 is past the 1987 hash's range (c <= 7); UBSan checks the shifts.
    const std::string text = raypack::generate_spd("mount", 8);
    EXPECT_EQ(count_keywords(text)["p"], 2 * power(4, 8));
    EXPECT_EQ(text, raypack::generate_spd("mount", 8));  // deterministic
}

TEST(SpdGenerators, RefusesScenesLargerThanTheMemory) {
    const std::uint64_t need = raypack::spd_primitives("tetra", 14) * raypack::kSpdBytesPerPrimitive;
    const std::uint64_t available = raypack::available_memory();
    if (available == 0 || available >= need) GTEST_SKIP() << "this machine has room for tetra 14";
    try {
        raypack::load_scene("gen:tetra:14");
        FAIL() << "tetra 14 loaded";
    } catch (const std::runtime_error& e) {
        const std::string msg = e.what();
        EXPECT_NE(msg.find("gen:tetra:14"), std::string::npos) << msg;
        EXPECT_NE(msg.find("268435456 primitives"), std::string::npos) << msg;
        EXPECT_NE(msg.find("MiB of memory available"), std::string::npos) << msg;
    }
}
