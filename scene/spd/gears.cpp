// SPD "gears": a cube of SIZE^3 intermeshing 36-tooth gears, each a concave
// 144-gon top and bottom plus one quad per edge, over a reflective floor;
// five lights (Haines 1987, "A Proposal for Standard Graphics Environments").
#include <algorithm>
#include <array>
#include <cmath>

#include "scene/spd/generators.h"
#include "scene/spd/nff_writer.h"

namespace raypack::spd {

namespace {

constexpr int kTeeth = 36;  // a multiple of 4, so that neighbours mesh
constexpr int kGearVertices = 4 * kTeeth;
// Teeth span the outer 10% of the radius; the tips stop just short of it so
// that meshing gears never share a surface.
constexpr double kOuterEdgeRatio = 0.995;
constexpr double kInnerEdgeRatio = 0.9;
constexpr double kEdgeDiff = 1.0 - kInnerEdgeRatio;
constexpr double kDepthRatio = 0.1;  // gear thickness / width, at most

using GearOutline = std::array<Vec3, kGearVertices>;

Vec3 rotated_about_z(const Vec3& p, double angle, const Vec3& center) {
    return transform_vector(p, rotate_matrix(Axis::Z, angle)) + center;
}

/// One tooth's four outline points: two on the tip, two at the root.
void add_tooth(GearOutline& outline, int tooth, double gear_angle, double tooth_angle, const Vec3& center,
               const Vec3& outer, const Vec3& inner) {
    Vec3* p = &outline[static_cast<std::size_t>(tooth * 4)];
    p[0] = rotated_about_z(outer, gear_angle - 0.19 * tooth_angle, center);
    p[1] = rotated_about_z(outer, gear_angle + 0.19 * tooth_angle, center);
    p[2] = rotated_about_z(inner, gear_angle + 0.3 * tooth_angle, center);
    p[3] = rotated_about_z(inner, gear_angle + 0.7 * tooth_angle, center);
}

void output_gear(NffWriter& out, const Vec3& center, double offset_angle, double outer_radius, double inner_radius,
                 double thickness) {
    Vec3 outer{outer_radius, 0.0, 0.0};
    Vec3 inner{inner_radius, 0.0, 0.0};
    const double tooth_angle = 2.0 * kPi / static_cast<double>(kTeeth);

    // Top face, counter-clockwise seen from above.
    GearOutline outline{};
    for (int t = 0; t < kTeeth; ++t) {
        const double a = offset_angle + 2.0 * kPi * static_cast<double>(t) / static_cast<double>(kTeeth);
        add_tooth(outline, t, a, tooth_angle, center, outer, inner);
    }
    out.polygon(outline);

    // Sides: one quad down from each top edge.
    for (int i = 0; i < kGearVertices; ++i) {
        const Vec3& a = outline[static_cast<std::size_t>(i)];
        const Vec3& b = outline[static_cast<std::size_t>((i + 1) % kGearVertices)];
        const std::array<Vec3, 4> side = {a, Vec3{a.x, a.y, a.z - thickness}, Vec3{b.x, b.y, b.z - thickness}, b};
        out.polygon(side);
    }

    // Bottom face, traced the other way round so that it faces down.
    outer.z = -thickness;
    inner.z = -thickness;
    for (int t = 0; t < kTeeth; ++t) {
        const double a = offset_angle - 2.0 * kPi * static_cast<double>(t) / static_cast<double>(kTeeth);
        add_tooth(outline, t, a, -tooth_angle, center, outer, inner);
    }
    out.polygon(outline);
}

double fraction(double v) {
    return v - static_cast<int>(v);
}

/// A pseudo-random colour per gear, scaled so that its largest channel is 1.
Vec3 gear_color(int ix, int iy, int iz) {
    Vec3 c{0.01 + fraction(static_cast<double>(ix * 3 + iy * 2 + iz + 1) * 5.0 / 7.0),
           0.01 + fraction(static_cast<double>(iy * 3 + iz * 2 + ix + 1) * 3.0 / 7.0),
           0.01 + fraction(static_cast<double>(iz * 3 + ix * 2 + iy + 1) * 2.0 / 7.0)};
    double scale = c.x > c.y ? c.x : c.y;
    scale = scale > c.z ? scale : c.z;
    c.x /= scale;
    c.y /= scale;
    c.z /= scale;
    return c;
}

}  // namespace

std::string generate_gears(int size) {
    NffWriter out;
    out.background({0.078, 0.361, 0.753});
    out.viewpoint({-1.1, -2.1, 2.6}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 45.0, 1.0, 512, 512);
    out.light({2.0, 4.0, 4.0});
    out.light({-2.0, 4.0, 3.0});
    out.light({2.0, -2.5, 2.5});
    out.light({-1.0, -4.0, 2.0});
    out.light({-1.111, -2.121, 2.626});  // just behind the eye

    // Off-white reflective floor.
    out.surface({1.0, 0.85, 0.7}, 0.0, 0.3, 0.6, 0.3, 37.0, 0.0, 0.0);
    const std::array<Vec3, 4> ground = {Vec3{2.0, 2.0, 0.0}, Vec3{-2.0, 2.0, 0.0}, Vec3{-2.0, -2.0, 0.0},
                                        Vec3{2.0, -2.0, 0.0}};
    out.polygon(ground);

    // SIZE gears (whose teeth overlap by kEdgeDiff) span the unit square.
    const double outer_radius = 1.0 / (static_cast<double>(size) - static_cast<double>(size - 1) * kEdgeDiff / 2.0);
    const Vec3 first{-1.0 + outer_radius, -1.0 + outer_radius, 1.0};
    const Vec3 step{outer_radius * (2.0 - kEdgeDiff), outer_radius * (2.0 - kEdgeDiff),
                    -1.0 / static_cast<double>(size)};
    const double thickness = std::min(kDepthRatio, 1.0 / (2.0 * static_cast<double>(size)));

    for (int iz = 0; iz < size; ++iz) {
        Vec3 center{};
        center.z = first.z + static_cast<double>(iz) * step.z;
        for (int iy = 0; iy < size; ++iy) {
            center.y = first.y + static_cast<double>(iy) * step.y;
            for (int ix = 0; ix < size; ++ix) {
                center.x = first.x + static_cast<double>(ix) * step.x;
                const Vec3 color = gear_color(ix, iy, iz);
                if ((ix * 4 + iy * 2 + iz) % 5 == 0)
                    out.surface(color, 0.0, 0.2, 0.0, 0.0, 0.0, 0.8, 1.1);  // glassy
                else
                    out.surface(color, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
                // Neighbours are turned half a tooth so that they mesh.
                const double angle = kPi * static_cast<double>((ix + iy + iz) % 2) / static_cast<double>(kTeeth);
                output_gear(out, center, angle, kOuterEdgeRatio * outer_radius, (1.0 - kEdgeDiff) * outer_radius,
                            thickness);
            }
        }
    }
    return out.take();
}

}  // namespace raypack::spd
