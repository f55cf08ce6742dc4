// SPD "rings": objects of six pentagonal rings (cylinders joined by spheres)
// through the edge midpoints of a dodecahedron, stacked in a pyramid that the
// viewer looks at from its apex, with a wall behind; three lights (Haines
// 1987, "A Proposal for Standard Graphics Environments").
#include <array>
#include <cmath>

#include "scene/spd/generators.h"
#include "scene/spd/nff_writer.h"

namespace raypack::spd {

namespace {

constexpr double kRingRadius = 0.07412;  // of every cylinder and sphere
constexpr int kSpreadOut = 1;            // > 1 spreads later layers further apart

/// The 30 ring vertices, five per pentagon, for an object that fits in the
/// unit sphere once the tube radius is added.
using RingVertices = std::array<Vec3, 30>;

RingVertices make_ring_vertices(double tube_radius) {
    RingVertices v{};
    const double scale = 1.0 / (1.0 + tube_radius);
    // First pentagon in the XY plane, starting on +X.
    for (int i = 0; i < 5; ++i) {
        const double a = static_cast<double>(i) * 2.0 * kPi / 5.0;
        v[static_cast<std::size_t>(i)] = {scale * std::cos(a), scale * std::sin(a), 0.0};
    }
    // The others: tip it over by the dodecahedron's dihedral angle about X,
    // then turn it to each of five positions about Z.
    const double x_rotation = 2.0 * std::acos(std::cos(kPi / 3.0) / std::sin(kPi / 5.0));
    const Mat4 tip = rotate_matrix(Axis::X, x_rotation);
    for (int p = 1; p < 6; ++p) {
        const double z_rotation = kPi * (2.0 * static_cast<double>(p - 1) + 1.0) / 5.0;
        const Mat4 turn = rotate_matrix(Axis::Z, z_rotation);
        for (int i = 0; i < 5; ++i)
            v[static_cast<std::size_t>(5 * p + i)] =
                transform_point(transform_point(v[static_cast<std::size_t>(i)], tip), turn);
    }
    return v;
}

void output_ring_object(NffWriter& out, const RingVertices& dodec, const Vec3& offset) {
    static constexpr std::array<Vec3, 6> kColors = {Vec3{1.0, 0.0, 0.0}, Vec3{0.0, 1.0, 0.0}, Vec3{0.0, 0.0, 1.0},
                                                    Vec3{0.0, 1.0, 1.0}, Vec3{1.0, 0.0, 1.0}, Vec3{1.0, 1.0, 0.0}};
    for (int e = 0; e < 30; ++e) {
        // Each vertex joins the previous one of its pentagon (cyclically).
        int prev = e - 1;
        if (e % 5 == 0) {
            prev = e + 4;
            out.surface(kColors[static_cast<std::size_t>(e / 5)], 0.0, 0.5, 0.2, 0.3, 37.0, 0.0, 0.0);
        }
        const Vec3 b = dodec[static_cast<std::size_t>(e)] + offset;
        const Vec3 a = dodec[static_cast<std::size_t>(prev)] + offset;
        const Vec4 base{b.x, b.y, b.z, kRingRadius};
        out.cone(base, {a.x, a.y, a.z, kRingRadius});
        out.sphere(base);
    }
}

}  // namespace

std::string generate_rings(int size) {
    NffWriter out;

    // Layers step back so that the pyramid fills a 45 degree view.
    const double spread = 1 / std::sin(kPi / 8.0);
    double y_diff = 1.0;
    double xz_diff = 1.0;
    if (kSpreadOut <= spread)
        y_diff = spread / kSpreadOut;
    else
        xz_diff = kSpreadOut / spread;

    out.background({0.078, 0.361, 0.753});
    const Vec3 from{-1.0, -spread, 0.5};
    out.viewpoint(from, {from.x, from.y + 1.0, from.z}, {0.0, 0.0, 1.0}, 45.0, 1.0, 512, 512);
    out.light({3.0, -spread, 3.0});
    out.light({-4.0, -spread, 1.0});
    out.light({2.0, -spread, -4.0});

    // White wall just spanning the view, plus 1%.
    out.surface({1.0, 1.0, 1.0}, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0);
    const double wy = y_diff * (size + 1);
    const double wxz = 1.01 * (wy - from.y) * std::tan(kPi / 8.0);
    const std::array<Vec3, 4> wall = {Vec3{wxz + from.x, wy, wxz + from.z}, Vec3{-wxz + from.x, wy, wxz + from.z},
                                      Vec3{-wxz + from.x, wy, -wxz + from.z}, Vec3{wxz + from.x, wy, -wxz + from.z}};
    out.polygon(wall);

    const RingVertices dodec = make_ring_vertices(kRingRadius);
    for (int depth = 0; depth < size; ++depth) {
        Vec3 offset{};
        offset.y = y_diff * static_cast<double>(depth + 1);
        for (int oz = 0; oz <= depth; ++oz) {
            offset.z = xz_diff * static_cast<double>(2 * oz - depth);
            for (int ox = 0; ox <= depth; ++ox) {
                offset.x = xz_diff * static_cast<double>(2 * ox - depth);
                output_ring_object(out, dodec, offset);
            }
        }
    }
    return out.take();
}

}  // namespace raypack::spd
