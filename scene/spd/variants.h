#pragma once
// Variants of a generated scene that show the distribution effects
// (docs/scene-format.md): its point lights made spherical area lights, a
// thin lens focused on the view point, glossy instead of mirror surfaces,
// moving spheres (motion blur).
#include <optional>
#include <string>
#include <string_view>

namespace raypack {

struct SceneVariants {
    bool area_lights = false;  ///< each `l` becomes an `ls` of radius 5% of the viewing distance
    bool lens = false;         ///< `lens` of radius 2% of the viewing distance, focused on `at`
    bool glossy = false;       ///< `gloss 40` before the first material
    /// Each sphere moves over the shutter (`move` before each `s`, `move 0 0
    /// 0` after the last) by 1.5 of its radius, in a direction of its own.
    bool motion = false;
    bool any() const { return area_lights || lens || glossy || motion; }
};

/// "area-lights", "lens", "glossy", "motion" joined by '+', or nullopt for a bad name.
std::optional<SceneVariants> parse_scene_variants(std::string_view names);

/// The NFF text of a generated scene rewritten with the variants. The text
/// must have a viewpoint (every SPD generator writes one).
std::string apply_scene_variants(const std::string& nff, const SceneVariants& variants);

}  // namespace raypack
