#pragma once
// NFF text in the exact layout of the SPD library's NFF output path (Haines
// 1987, "A Proposal for Standard Graphics Environments"; NFF as documented in
// scenes/nff-format.txt): one statement per call, numbers printed with C's
// %g, cones and cylinders on one line ("curves" mode).
#include <array>
#include <span>
#include <string>

#include "scene/spd/spd_math.h"

namespace raypack::spd {

class NffWriter {
public:
    void background(const Vec3& color);
    /// The "v" block. The SPD programs also pass an aspect ratio, which NFF
    /// does not carry, so it is not a parameter here.
    void viewpoint(const Vec3& from, const Vec3& at, const Vec3& up, double fov_deg, double hither, int res_x,
                   int res_y);
    void light(const Vec3& position);
    /// The "f" line. ka and ks_spec are not in NFF; the highlight half-angle
    /// (degrees) becomes a Phong exponent the way the SPD library converts it.
    void surface(const Vec3& color, double ka, double kd, double ks, double ks_spec, double highlight_deg, double kt,
                 double ior);
    /// Center in xyz, radius in w.
    void sphere(const Vec4& center);
    /// Base and apex centres in xyz, their radii in w.
    void cone(const Vec4& base, const Vec4& apex);
    /// Drops vertices that coincide with their successor (as the SPD library
    /// does) and skips the polygon if fewer than three remain.
    void polygon(std::span<const Vec3> vertices);
    /// Triangle with per-vertex normals ("pp 3"). The SPD library sends
    /// patches through its triangle splitter, which does no duplicate check.
    void triangle_patch(const std::array<Vec3, 3>& vertices, const std::array<Vec3, 3>& normals);
    /// raypack's `hf nx ny x0 y0 z0 x1 y1 z1` and its nx * ny heights, one
    /// row of nx a line (not SPD: docs/scene-format.md).
    void height_field(int nx, int ny, const Vec3& lo, const Vec3& hi, std::span<const double> heights);

    /// raypack's `begin NAME` ... `end` and `inst NAME m00 .. m23` (a 3 x 4
    /// row-major matrix; not SPD: docs/scene-format.md).
    void begin_object(const std::string& name);
    void end_object();
    void instance(const std::string& name, const std::array<double, 12>& matrix);

    const std::string& text() const { return text_; }
    std::string take() { return std::move(text_); }

private:
    void number(double v);
    void vec(const Vec3& v);

    std::string text_;
};

}  // namespace raypack::spd
