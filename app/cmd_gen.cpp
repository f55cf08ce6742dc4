// raypack gen NAME --size S -o FILE.nff
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "app/commands.h"
#include "scene/atomic_file.h"
#include "scene/spd/spd.h"
#include "scene/spd/variants.h"

namespace raypack::app {

int run_gen(const Args& args) {
    const ParsedArgs p(args,
                       {{"--size", "-s", 1}, {"--output", "-o", 1}, {"--area-lights", "", 0}, {"--lens", "", 0},
                        {"--glossy", "", 0}, {"--motion", "", 0}},
                       1);
    if (p.help() || p.positional().empty()) {
        std::printf("usage: raypack gen NAME --size S [--area-lights] [--lens] [--glossy] [--motion] -o FILE.nff\n"
                    "  --area-lights  point lights become spherical area lights (ls)\n"
                    "  --lens         a thin lens focused on the view point (lens)\n"
                    "  --glossy       glossy instead of mirror surfaces (gloss 40)\n"
                    "  --motion       every sphere moves by 1.5 radii over the shutter (move; motion blur)\n"
                    "generators (default size, max):");
        for (const auto& g : spd_generators()) std::printf(" %s (%d, %d)", g.name.c_str(), g.default_size, g.max_size);
        std::printf("\n");
        if (!p.help()) throw UsageError("missing generator NAME");
        return 0;
    }
    const std::string name = p.positional()[0];
    const SpdGeneratorInfo* info = nullptr;
    const auto gens = spd_generators();
    for (const auto& g : gens)
        if (g.name == name) info = &g;
    if (!info) throw UsageError("unknown generator '" + name + "'");
    const int size = int(p.integer("--size", info->default_size, 1, info->max_size));
    if (!p.has("--output")) throw UsageError("missing -o FILE.nff");
    const std::string out = p.text("--output");
    std::string text;
    try {
        text = generate_spd(name, size);
        SceneVariants v;
        v.area_lights = p.has("--area-lights");
        v.lens = p.has("--lens");
        v.glossy = p.has("--glossy");
        v.motion = p.has("--motion");
        if (v.any()) text = apply_scene_variants(text, v);
    } catch (const std::invalid_argument& e) {
        throw UsageError(e.what());
    }
    write_atomically(out, [&](const std::string& tmp) {
        std::ofstream f(tmp, std::ios::binary);
        f << text;
        if (!f.flush()) throw std::runtime_error(out + ": write failed");
    });
    std::printf("wrote %s (%s size %d, %zu bytes)\n", out.c_str(), name.c_str(), size, text.size());
    return 0;
}

}  // namespace raypack::app
