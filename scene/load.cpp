// The one entry point for scenes: picks the loader by extension or gen: prefix.
#include "scene/load.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <limits>
#include <optional>
#include <stdexcept>
#include <string_view>

#include "scene/nff_text.h"
#include "scene/number_token.h"
#include "scene/spd/spd.h"
#include "scene/spd/variants.h"

namespace raypack {

SceneError::SceneError(const std::string& file, int line, const std::string& problem)
    : std::runtime_error(file + ":" + std::to_string(line) + ": " + problem), file_(file), line_(line),
      problem_(problem) {}

namespace {
HeightImageReader& height_image_reader_slot() {
    static HeightImageReader reader;
    return reader;
}
}  // namespace

void set_height_image_reader(HeightImageReader reader) { height_image_reader_slot() = std::move(reader); }
const HeightImageReader& height_image_reader() { return height_image_reader_slot(); }

namespace {

/// gen:NAME:SIZE -> the SPD generator's NFF text, parsed in memory.
Scene load_generated(const std::string& spec) {
    const std::string_view rest = std::string_view(spec).substr(4);
    const std::size_t colon = rest.find(':');
    if (colon == std::string_view::npos || colon == 0)
        throw SceneError(spec, 0, "bad generator spec: expected gen:NAME:SIZE");
    const std::string name(rest.substr(0, colon));
    std::string_view size_text = rest.substr(colon + 1);
    // gen:NAME:SIZE:VARIANTS, e.g. gen:balls:4:area-lights+lens (scene/spd/variants.h).
    std::optional<SceneVariants> variants;
    if (const std::size_t second = size_text.find(':'); second != std::string_view::npos) {
        variants = parse_scene_variants(size_text.substr(second + 1));
        if (!variants || !variants->any())
            throw SceneError(spec, 0,
                             "bad generator spec: variants '" + std::string(size_text.substr(second + 1)) +
                                 "' (expected area-lights, lens, glossy, motion joined by '+')");
        size_text = size_text.substr(0, second);
    }
    long long size = 0;
    if (size_text.empty()) throw SceneError(spec, 0, "bad generator spec: missing SIZE in gen:NAME:SIZE");
    const NumberToken r = parse_int_token(size_text, size);
    if (r == NumberToken::NotNumber)
        throw SceneError(spec, 0, "bad generator spec: size '" + std::string(size_text) + "' is not an integer");
    if (r != NumberToken::Ok || size < std::numeric_limits<int>::min() || size > std::numeric_limits<int>::max())
        throw SceneError(spec, 0, "bad generator spec: size '" + std::string(size_text) + "' out of range");
    std::string text;
    try {
        text = generate_spd(name, int(size));
        if (variants) text = apply_scene_variants(text, *variants);
    } catch (const std::invalid_argument& e) {
        throw SceneError(spec, 0, std::string("bad generator spec: ") + e.what());
    } catch (const std::runtime_error& e) {  // too large for the memory available
        throw SceneError(spec, 0, e.what());
    }
    return load_nff_text(text, spec);
}

}  // namespace

Scene load_scene(const std::string& spec) {
    if (spec.starts_with("gen:")) return load_generated(spec);
    std::string ext = std::filesystem::path(spec).extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    if (ext == ".nff") return load_nff_file(spec);
    if (ext == ".obj") return load_obj_file(spec);
    throw SceneError(spec, 0,
                     (ext.empty() ? std::string("no file extension") : "unknown scene format '" + ext + "'") +
                         ": expected a .nff or .obj file, or gen:NAME:SIZE");
}

}  // namespace raypack
