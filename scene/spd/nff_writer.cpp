// NFF statements formatted like the SPD library's output routines.
#include "scene/spd/nff_writer.h"

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace raypack::spd {

namespace {

/// Two neighbouring vertices closer than this count as one (SPD's EPSILON2).
constexpr double kDuplicateVertexDistance = 1.0e-6;

/// Indices of the vertices that survive SPD's "collapse adjacent duplicates"
/// pass, which compares each vertex with its cyclic successor and removes it
/// (shifting the rest down) when the two coincide.
std::vector<std::size_t> distinct_vertices(std::span<const Vec3> vertices) {
    std::vector<std::size_t> kept(vertices.size());
    for (std::size_t i = 0; i < kept.size(); ++i) kept[i] = i;
    for (std::size_t i = 0; i < kept.size();) {
        Vec3 gap = vertices[kept[i]] - vertices[kept[(i + 1) % kept.size()]];
        if (normalize(gap) < kDuplicateVertexDistance)
            kept.erase(kept.begin() + static_cast<std::ptrdiff_t>(i));
        else
            ++i;
    }
    return kept;
}

}  // namespace

void NffWriter::number(double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%g", v);
    text_ += buf;
}

void NffWriter::vec(const Vec3& v) {
    number(v.x);
    text_ += ' ';
    number(v.y);
    text_ += ' ';
    number(v.z);
}

void NffWriter::height_field(int nx, int ny, const Vec3& lo, const Vec3& hi, std::span<const double> heights) {
    text_ += "hf " + std::to_string(nx) + ' ' + std::to_string(ny) + ' ';
    vec(lo);
    text_ += ' ';
    vec(hi);
    text_ += '\n';
    for (int j = 0; j < ny; ++j) {
        for (int i = 0; i < nx; ++i) {
            if (i) text_ += ' ';
            number(heights[std::size_t(j) * std::size_t(nx) + std::size_t(i)]);
        }
        text_ += '\n';
    }
}

void NffWriter::background(const Vec3& color) {
    text_ += "b ";
    vec(color);
    text_ += '\n';
}

void NffWriter::viewpoint(const Vec3& from, const Vec3& at, const Vec3& up, double fov_deg, double hither, int res_x,
                          int res_y) {
    text_ += "v\nfrom ";
    vec(from);
    text_ += "\nat ";
    vec(at);
    text_ += "\nup ";
    vec(up);
    text_ += "\nangle ";
    number(fov_deg);
    text_ += "\nhither ";
    number(hither);
    text_ += "\nresolution " + std::to_string(res_x) + ' ' + std::to_string(res_y) + '\n';
}

void NffWriter::begin_object(const std::string& name) { text_ += "begin " + name + '\n'; }

void NffWriter::end_object() { text_ += "end\n"; }

void NffWriter::instance(const std::string& name, const std::array<double, 12>& matrix) {
    text_ += "inst " + name;
    for (const double m : matrix) {
        text_ += ' ';
        number(m);
    }
    text_ += '\n';
}

void NffWriter::light(const Vec3& position) {
    text_ += "l ";
    vec(position);
    text_ += '\n';
}

void NffWriter::surface(const Vec3& color, double /*ka*/, double kd, double ks, double /*ks_spec*/,
                        double highlight_deg, double kt, double ior) {
    // Phong exponent whose cos^n falls to one half at the highlight angle;
    // SPD's fallbacks for a zero (mirror-sharp) or too wide angle.
    const double radians = kPi * highlight_deg / 180.0;
    double phong = 0.0;
    if (radians <= 0.0)
        phong = 100000.0;
    else if (radians >= kPi / 2.0)
        phong = 1.0;
    else
        phong = std::log(0.5) / std::log(std::cos(radians));
    text_ += "f ";
    vec(color);
    for (double v : {kd, ks, phong, kt, ior}) {
        text_ += ' ';
        number(v);
    }
    text_ += '\n';
}

void NffWriter::sphere(const Vec4& center) {
    text_ += "s ";
    vec(center.xyz());
    text_ += ' ';
    number(center.w);
    text_ += '\n';
}

void NffWriter::cone(const Vec4& base, const Vec4& apex) {
    text_ += "c ";
    vec(base.xyz());
    text_ += ' ';
    number(base.w);
    text_ += ' ';
    vec(apex.xyz());
    text_ += ' ';
    number(apex.w);
    text_ += '\n';
}

void NffWriter::polygon(std::span<const Vec3> vertices) {
    const std::vector<std::size_t> kept = distinct_vertices(vertices);
    if (kept.size() < 3) return;
    text_ += "p " + std::to_string(kept.size()) + '\n';
    for (std::size_t i : kept) {
        vec(vertices[i]);
        text_ += '\n';
    }
}

void NffWriter::triangle_patch(const std::array<Vec3, 3>& vertices, const std::array<Vec3, 3>& normals) {
    text_ += "pp 3\n";
    for (std::size_t i = 0; i < 3; ++i) {
        vec(vertices[i]);
        text_ += ' ';
        vec(normals[i]);
        text_ += '\n';
    }
}

}  // namespace raypack::spd
