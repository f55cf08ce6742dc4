// SPD "balls" (sphereflake): a sphere with nine children of a third its
// radius, recursively, over a floor square; three lights (Haines 1987,
// "A Proposal for Standard Graphics Environments").
#include <array>
#include <cmath>

#include "scene/spd/generators.h"
#include "scene/spd/nff_writer.h"

namespace raypack::spd {

namespace {

/// Directions (w = 0) to the nine children of a sphere that sits on +Z: a
/// ring of six around the equator and three above, rotated together.
using ChildDirections = std::array<Vec4, 9>;

ChildDirections make_child_directions() {
    const double d = 1.0 / std::sqrt(2.0);
    std::array<Vec4, 3> trio = {Vec4{d, d, 0.0, 0.0}, Vec4{d, 0.0, -d, 0.0}, Vec4{0.0, d, -d, 0.0}};

    // Tilt the trio so that it straddles the equator.
    Vec3 tilt_axis{1.0, -1.0, 0.0};
    normalize(tilt_axis);
    const Mat4 tilt = axis_rotate_matrix(tilt_axis, std::asin(2.0 / std::sqrt(6.0)));
    for (Vec4& v : trio) v = transform_coord(v, tilt);

    // Three copies of the trio, 120 degrees apart about Z.
    ChildDirections out{};
    for (int set = 0; set < 3; ++set) {
        const Mat4 spin = rotate_matrix(Axis::Z, set * 2.0 * kPi / 3.0);
        for (int v = 0; v < 3; ++v)
            out[static_cast<std::size_t>(set * 3 + v)] = transform_coord(trio[static_cast<std::size_t>(v)], spin);
    }
    return out;
}

/// Rotation taking +Z to DIRECTION (which is unit length up to rounding).
Mat4 rotation_from_z(const Vec3& direction) {
    if (direction.z >= 0.9999) return identity_matrix();
    if (direction.z <= -0.9999) return rotate_matrix(Axis::Y, kPi);
    const Vec3 z_axis{0.0, 0.0, 1.0};
    Vec3 axis = cross(z_axis, direction);
    normalize(axis);
    return axis_rotate_matrix(axis, std::acos(dot(z_axis, direction)));
}

/// CENTER: position and radius. DIRECTION: unit direction from the parent in
/// xyz, child/parent radius ratio in w.
void output_flake(NffWriter& out, const ChildDirections& dirs, int depth, const Vec4& center, const Vec4& direction) {
    out.sphere(center);
    if (depth <= 0) return;

    const Mat4 mx = rotation_from_z(direction.xyz());
    // Children touch the parent: centre distance = r_parent + r_child.
    const double scale = center.w * (1.0 + direction.w);
    for (const Vec4& dir : dirs) {
        Vec4 child = transform_coord(dir, mx);
        child.x = child.x * scale + center.x;
        child.y = child.y * scale + center.y;
        child.z = child.z * scale + center.z;
        child.w = center.w * direction.w;
        Vec4 child_dir{child.x - center.x, child.y - center.y, child.z - center.z, direction.w};
        child_dir.x /= scale;
        child_dir.y /= scale;
        child_dir.z /= scale;
        output_flake(out, dirs, depth - 1, child, child_dir);
    }
}

}  // namespace

std::string generate_balls(int size) {
    NffWriter out;
    const double radius = 1.0;  // of the sphere enclosing the whole flake

    out.background({0.078, 0.361, 0.753});
    out.viewpoint({2.1, 1.3, 1.7}, {0.0, 0.0, 0.0}, {0.0, 0.0, 1.0}, 45.0, 0.01, 512, 512);
    out.light({4.0, 3.0, 2.0});
    out.light({1.0, -4.0, 4.0});
    out.light({-3.0, 1.0, 5.0});

    // Beige floor square.
    out.surface({1.0, 0.75, 0.33}, 0.2, 0.8, 0.0, 0.0, 0.0, 0.0, 1.0);
    const Vec3 b{12.0 * radius, 12.0 * radius, -radius / 2.0};
    const std::array<Vec3, 4> floor = {Vec3{b.x, b.y, b.z}, Vec3{-b.x, b.y, b.z}, Vec3{-b.x, -b.y, b.z},
                                       Vec3{b.x, -b.y, b.z}};
    out.polygon(floor);

    // Mirrored spheres.
    out.surface({1.0, 0.9, 0.7}, 0.0, 0.5, 0.5, 0.5, 37.0, 0.0, 1.0);
    const ChildDirections dirs = make_child_directions();
    output_flake(out, dirs, size, {0.0, 0.0, 0.0, radius / 2.0}, {0.0, 0.0, 1.0, 1.0 / 3.0});
    return out.take();
}

}  // namespace raypack::spd
