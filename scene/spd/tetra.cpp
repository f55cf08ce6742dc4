// SPD "tetra": a recursive tetrahedral pyramid (Sierpinski tetrahedron) of
// triangles, after the Glassner 1984 / Kay-Kajiya 1986 test scene; one light
// (Haines 1987, "A Proposal for Standard Graphics Environments").
#include <algorithm>
#include <array>
#include <string>
#include <utility>

#include "scene/spd/generators.h"
#include "scene/spd/nff_writer.h"

namespace raypack::spd {

namespace {

/// The four cube corners (x*y*z == +1) of the cube centred at CENTER with
/// half-width CENTER.w, which form a regular tetrahedron, in SPD's order.
std::array<Vec3, 4> tetra_corners(const Vec4& c) {
    std::array<Vec3, 4> pts{};
    std::size_t n = 0;
    for (int x = -1; x <= 1; x += 2)
        for (int y = -1; y <= 1; y += 2)
            for (int z = -1; z <= 1; z += 2)
                if (x * y * z == 1)
                    pts[n++] = {c.x + static_cast<double>(x) * c.w, c.y + static_cast<double>(y) * c.w,
                                c.z + static_cast<double>(z) * c.w};
    return pts;
}

void output_tetrahedron(NffWriter& out, const Vec4& center) {
    const std::array<Vec3, 4> pts = tetra_corners(center);
    // Face k uses corners k, k+1, k+2 (mod 4), reversed on odd faces so that
    // every face winds outward: 012, 321, 230, 103.
    for (int face = 0; face < 4; ++face) {
        std::array<int, 3> order = {face % 4, (face + 1) % 4, (face + 2) % 4};
        if (face % 2 == 1) std::swap(order[0], order[2]);
        const std::array<Vec3, 3> tri = {pts[static_cast<std::size_t>(order[0])],
                                         pts[static_cast<std::size_t>(order[1])],
                                         pts[static_cast<std::size_t>(order[2])]};
        out.polygon(tri);
    }
}

void create_tetra(NffWriter& out, int depth, const Vec4& center) {
    if (depth <= 1) {
        output_tetrahedron(out, center);
        return;
    }
    // Four half-size tetrahedra at the same corners of the half-size cube.
    for (int x = -1; x <= 1; x += 2)
        for (int y = -1; y <= 1; y += 2)
            for (int z = -1; z <= 1; z += 2)
                if (x * y * z == 1) {
                    const Vec4 sub{center.x + static_cast<double>(x) * center.w / 2.0,
                                   center.y + static_cast<double>(y) * center.w / 2.0,
                                   center.z + static_cast<double>(z) * center.w / 2.0, center.w / 2.0};
                    create_tetra(out, depth - 1, sub);
                }
}

void tetra_setting(NffWriter& out) {
    out.background({0.078, 0.361, 0.753});
    // Kay & Kajiya's view and light, moved to SPD's world coordinates.
    out.viewpoint({1.022846, -3.177154, -2.174512}, {-0.004103, -0.004103, 0.216539}, {-0.816497, -0.816497, 0.816497},
                  45.0, 1.0, 512, 512);
    out.light({2.0, -18.0, -5.0});
    out.surface({1.0, 0.2, 0.2}, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
}

/// create_tetra's recursion `levels` deep, placing object `name` (a unit
/// tetra pyramid) where create_tetra would recurse further.
void place_tetra(NffWriter& out, const std::string& name, int levels, const Vec4& center) {
    if (levels == 0) {
        out.instance(name, {center.w, 0, 0, center.x, 0, center.w, 0, center.y, 0, 0, center.w, center.z});
        return;
    }
    for (int x = -1; x <= 1; x += 2)
        for (int y = -1; y <= 1; y += 2)
            for (int z = -1; z <= 1; z += 2)
                if (x * y * z == 1)
                    place_tetra(out, name, levels - 1,
                                {center.x + x * center.w / 2.0, center.y + y * center.w / 2.0,
                                 center.z + z * center.w / 2.0, center.w / 2.0});
}

}  // namespace

std::string generate_tetra(int size) {
    NffWriter out;
    tetra_setting(out);
    create_tetra(out, size, {0.0, 0.0, 0.0, 1.0});
    return out.take();
}

std::string generate_tetra_instanced(int size) {
    // The object in triangles: deeper, its triangles outgrow the savings.
    constexpr int kObjectDepth = 6;
    // Levels of the pyramid each object of placements spans: 64 placements
    // an object keeps the nesting shallow (each level of instances costs a
    // transform and a traversal set-up; docs/instancing.md).
    constexpr int kLevelsPerObject = 3;
    NffWriter out;
    tetra_setting(out);
    int depth = std::min(size, kObjectDepth);
    std::string name = "tetra" + std::to_string(depth);
    out.begin_object(name);
    create_tetra(out, depth, {0.0, 0.0, 0.0, 1.0});
    out.end_object();
    while (size - depth > kLevelsPerObject) {
        const std::string next = "tetra" + std::to_string(depth + kLevelsPerObject);
        out.begin_object(next);
        place_tetra(out, name, kLevelsPerObject, {0.0, 0.0, 0.0, 1.0});
        out.end_object();
        depth += kLevelsPerObject;
        name = next;
    }
    place_tetra(out, name, size - depth, {0.0, 0.0, 0.0, 1.0});
    return out.take();
}

}  // namespace raypack::spd
