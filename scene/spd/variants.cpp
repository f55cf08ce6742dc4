#include "scene/spd/variants.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numbers>
#include <sstream>
#include <stdexcept>

namespace raypack {

std::optional<SceneVariants> parse_scene_variants(std::string_view names) {
    SceneVariants v;
    while (!names.empty()) {
        const std::size_t plus = names.find('+');
        const std::string_view name = names.substr(0, plus);
        if (name == "area-lights") v.area_lights = true;
        else if (name == "lens") v.lens = true;
        else if (name == "glossy") v.glossy = true;
        else if (name == "motion") v.motion = true;
        else return std::nullopt;
        names = plus == std::string_view::npos ? std::string_view{} : names.substr(plus + 1);
    }
    return v;
}

namespace {

std::string number(double x) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", x);
    return buf;
}

}  // namespace

std::string apply_scene_variants(const std::string& nff, const SceneVariants& variants) {
    // The viewing distance |from - at| sets the scale of the lights and lens.
    std::istringstream in(nff);
    std::string line;
    double from[3] = {0, 0, 0}, at[3] = {0, 0, 0};
    bool have_from = false, have_at = false;
    while (std::getline(in, line)) {
        std::istringstream words(line);
        std::string key;
        words >> key;
        if (key == "from") have_from = bool(words >> from[0] >> from[1] >> from[2]);
        if (key == "at") have_at = bool(words >> at[0] >> at[1] >> at[2]);
    }
    if (!have_from || !have_at) throw std::invalid_argument("scene variants need the scene's viewpoint");
    const double distance =
        std::sqrt((from[0] - at[0]) * (from[0] - at[0]) + (from[1] - at[1]) * (from[1] - at[1]) +
                  (from[2] - at[2]) * (from[2] - at[2]));
    std::string out;
    std::istringstream again(nff);
    bool gloss_written = false, moving = false;
    std::uint64_t spheres = 0;
    while (std::getline(again, line)) {
        std::istringstream words(line);
        std::string key;
        words >> key;
        if (variants.area_lights && key == "l") {
            double x, y, z;
            words >> x >> y >> z;
            std::string rest;
            std::getline(words, rest);  // the optional colour
            out += "ls " + number(x) + " " + number(y) + " " + number(z) + " " + number(0.05 * distance) + rest + "\n";
            continue;
        }
        if (variants.motion && key == "s") {
            double x, y, z, r;
            if (words >> x >> y >> z >> r) {
                // A direction of the sphere's own from its number (a hash to
                // two angles), the same on every run.
                std::uint64_t h = (++spheres) * 0x9E3779B97F4A7C15ull;
                h ^= h >> 31;
                h *= 0xBF58476D1CE4E5B9ull;
                h ^= h >> 29;
                const double u = double(h >> 40) / double(1ull << 24), w = double(h & 0xFFFFFF) / double(1 << 24);
                const double cz = 2 * u - 1, sz = std::sqrt(std::max(0.0, 1 - cz * cz)), phi = 2 * std::numbers::pi * w;
                const double len = 1.5 * std::fabs(r);
                out += "move " + number(len * sz * std::cos(phi)) + " " + number(len * sz * std::sin(phi)) + " " +
                       number(len * cz) + "\n";
                moving = true;
            }
        } else if (moving && key != "f" && !key.empty() && key[0] != '#') {
            out += "move 0 0 0\n";
            moving = false;
        }
        if (variants.glossy && key == "f" && !gloss_written) {
            out += "gloss 40\n";
            gloss_written = true;
        }
        out += line + "\n";
        if (variants.lens && key == "resolution")  // the end of the viewpoint block
            out += "lens " + number(0.02 * distance) + " " + number(distance) + "\n";
    }
    if (moving) out += "move 0 0 0\n";
    return out;
}

}  // namespace raypack
