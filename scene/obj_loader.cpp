// Wavefront OBJ through tinyobjloader, plus the camera and light OBJ lacks.
#include <tiny_obj_loader.h>

#include <cmath>
#include <numbers>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "scene/load.h"
#include "scene/nff_text.h"
#include "scene/number_token.h"
#include "scene/read_file.h"
#include "scene/triangulate.h"

namespace raypack {

namespace {

/// tinyobjloader counts face vertices in an unsigned char.
constexpr std::size_t kMaxFaceVertices = 255;

std::vector<std::string_view> split_blank(std::string_view s) {
    std::vector<std::string_view> out;
    std::size_t i = 0;
    while (true) {
        i = s.find_first_not_of(" \t\r\v\f", i);
        if (i == std::string_view::npos) break;
        std::size_t j = s.find_first_of(" \t\r\v\f", i);
        if (j == std::string_view::npos) j = s.size();
        out.push_back(s.substr(i, j - i));
        i = j;
    }
    return out;
}

/// What tinyobjloader does not check: it reads "nan" as 0 and a missing
/// coordinate as 0, and truncates face sizes above 255. Returns the line of
/// each "f", in order, so that later errors about faces can name their line.
std::vector<int> prescan(std::string_view text, const std::string& path) {
    std::vector<int> face_lines;
    int line = 0;
    std::vector<std::string_view> tokens;
    for (std::size_t pos = 0; pos < text.size();) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view ln = text.substr(pos, end - pos);
        pos = end + 1;
        ++line;
        if (const std::size_t hash = ln.find('#'); hash != std::string_view::npos) ln = ln.substr(0, hash);
        tokens = split_blank(ln);
        if (tokens.empty()) continue;
        const std::string_view kw = tokens[0];
        if (kw == "v" || kw == "vn") {
            if (tokens.size() < 4)
                throw SceneError(path, line, "'" + std::string(kw) + "' needs 3 coordinates, got " +
                                                 std::to_string(tokens.size() - 1));
            for (std::size_t i = 1; i < tokens.size(); ++i) {
                float x;
                switch (parse_float_token(tokens[i], x)) {
                    case NumberToken::Ok: break;
                    case NumberToken::NotNumber:
                        throw SceneError(path, line, "expected a number, got '" + std::string(tokens[i]) + "'");
                    case NumberToken::NonFinite:
                        throw SceneError(path, line, "non-finite number '" + std::string(tokens[i]) + "'");
                    case NumberToken::OutOfRange:
                        throw SceneError(path, line, "number '" + std::string(tokens[i]) + "' out of range");
                }
            }
        } else if (kw == "f") {
            const std::size_t n = tokens.size() - 1;
            if (n < 3) throw SceneError(path, line, "a face needs at least 3 vertices, got " + std::to_string(n));
            if (n > kMaxFaceVertices)
                throw SceneError(path, line, "face with " + std::to_string(n) + " vertices; at most " +
                                                 std::to_string(kMaxFaceVertices) + " are supported");
            face_lines.push_back(line);
        }
    }
    return face_lines;
}

/// "... line 12 ..." in a tinyobjloader message -> 12, else 0.
int line_in_message(const std::string& msg) {
    for (std::size_t at = msg.find("line "); at != std::string::npos; at = msg.find("line ", at + 1)) {
        std::size_t i = at + 5;
        int v = 0;
        bool digits = false;
        while (i < msg.size() && msg[i] >= '0' && msg[i] <= '9' && v < 100'000'000) {
            v = v * 10 + (msg[i++] - '0');
            digits = true;
        }
        if (digits) return v;
    }
    return 0;
}

std::string first_line(const std::string& msg) {
    const std::size_t b = msg.find_first_not_of(" \n\r");
    if (b == std::string::npos) return {};
    return msg.substr(b, msg.find('\n', b) - b);
}

/// Materials are not read (one default material for the mesh), so warnings
/// about them are noise; every other warning is an error.
std::string relevant_warning(const std::string& warn) {
    std::istringstream in(warn);
    for (std::string w; std::getline(in, w);) {
        if (w.find_first_not_of(" \r.") == std::string::npos) continue;
        if (w.find("material") != std::string::npos || w.find("mtl") != std::string::npos) continue;
        return w;
    }
    return {};
}

/// A view of the whole mesh from above, right and in front: the bounding
/// sphere fits the 45 degree field of view, up is +y (the OBJ convention), and
/// one light sits above and to the right of the eye.
void frame(Scene& scene) {
    Vec3d lo{INFINITY, INFINITY, INFINITY}, hi{-INFINITY, -INFINITY, -INFINITY};
    const TriangleSoA& t = scene.triangles;
    for (const auto* ps : {&t.p0, &t.p1, &t.p2})
        for (const Vec3f& p : *ps) {
            lo = min(lo, Vec3d(p));
            hi = max(hi, Vec3d(p));
        }
    const Vec3d c = (lo + hi) * 0.5;
    double r = 0;
    for (const auto* ps : {&t.p0, &t.p1, &t.p2})
        for (const Vec3f& p : *ps) r = std::max(r, length(Vec3d(p) - c));
    if (!(r > 0)) r = 1;  // a mesh of one point: any scale will do

    Camera& cam = scene.camera;
    cam.fov_deg = 45;
    const double dist = r / std::sin(0.5 * cam.fov_deg * std::numbers::pi / 180);
    const Vec3d dir = normalize(Vec3d{1, 0.6, 1.4});
    const Vec3d from = c + dir * dist;
    cam.from = Vec3f(from);
    cam.at = Vec3f(c);
    cam.up = {0, 1, 0};
    cam.hither = float(0.01 * r);
    cam.width = cam.height = 512;
    scene.has_camera = true;

    const Vec3d right = normalize(cross(-dir, Vec3d{0, 1, 0}));
    PointLight light;
    light.position = Vec3f(from + right * (0.5 * dist) + Vec3d{0, 0.5 * dist, 0});
    scene.lights.push_back(light);
}

}  // namespace

void append_obj_triangles(const std::string& path, std::uint32_t material, Scene& scene) {
    append_obj_text(read_scene_file(path), path, material, scene);
}

void append_obj_text(std::string_view text, const std::string& path, std::uint32_t material, Scene& scene) {
    const std::vector<int> face_lines = prescan(text, path);

    tinyobj::attrib_t attrib;
    std::vector<tinyobj::shape_t> shapes;
    std::vector<tinyobj::material_t> materials;
    std::string warn, err;
    std::istringstream in{std::string(text)};
    // No material reader: "mtllib" is skipped. Faces are triangulated here,
    // with the same triangulation as NFF polygons.
    const bool ok = tinyobj::LoadObj(&attrib, &shapes, &materials, &warn, &err, &in, nullptr,
                                     /*triangulate=*/false, /*default_vcols_fallback=*/false);
    if (!ok || !err.empty()) {
        const std::string msg = first_line(err.empty() ? std::string("failed to parse") : err);
        throw SceneError(path, line_in_message(msg), "tinyobjloader: " + msg);
    }

    const std::size_t nv = attrib.vertices.size() / 3, nn = attrib.normals.size() / 3;
    auto position = [&](int i) {
        return Vec3f(float(attrib.vertices[3 * i]), float(attrib.vertices[3 * i + 1]), float(attrib.vertices[3 * i + 2]));
    };
    auto normal = [&](int i) {
        return Vec3f(float(attrib.normals[3 * i]), float(attrib.normals[3 * i + 1]), float(attrib.normals[3 * i + 2]));
    };
    const std::size_t triangles_before = scene.triangles.size();
    std::vector<Vec3f> pos, nrm;
    std::size_t face = 0;
    for (const tinyobj::shape_t& shape : shapes) {
        std::size_t k = 0;
        for (const unsigned char count : shape.mesh.num_face_vertices) {
            const int line = face < face_lines.size() ? face_lines[face] : 0;
            ++face;
            pos.clear();
            nrm.clear();
            bool normals = true;
            for (std::size_t j = 0; j < count; ++j, ++k) {
                const tinyobj::index_t& idx = shape.mesh.indices[k];
                if (idx.vertex_index < 0 || std::size_t(idx.vertex_index) >= nv)
                    throw SceneError(path, line, "vertex index out of range in face");
                pos.push_back(position(idx.vertex_index));
                if (idx.normal_index >= 0 && std::size_t(idx.normal_index) >= nn)
                    throw SceneError(path, line, "normal index out of range in face");
                if (idx.normal_index < 0) {
                    normals = false;
                } else {
                    nrm.push_back(normal(idx.normal_index));
                    // Lenient, unlike NFF "pp": exporters write zero normals
                    // for degenerate faces; such a face falls back to flat.
                    if (nrm.back() == Vec3f{}) normals = false;
                }
            }
            for (const auto& tri : triangulate_polygon(std::span<const Vec3f>(pos))) {
                if (normals)
                    scene.add_triangle(pos[tri[0]], pos[tri[1]], pos[tri[2]], nrm[tri[0]], nrm[tri[1]], nrm[tri[2]],
                                       material);
                else
                    scene.add_triangle(pos[tri[0]], pos[tri[1]], pos[tri[2]], material);
            }
        }
    }
    if (const std::string w = relevant_warning(warn); !w.empty())
        throw SceneError(path, line_in_message(w), "tinyobjloader: " + w);
    if (scene.triangles.size() == triangles_before) throw SceneError(path, 0, "no faces");
}

Scene load_obj_text(std::string_view text, const std::string& name) {
    Scene scene;
    scene.source = name;
    Material grey;
    grey.color = {0.8f, 0.8f, 0.8f};
    grey.kd = 0.8f;
    scene.materials.push_back(grey);
    append_obj_text(text, name, 0, scene);
    frame(scene);
    scene.update_features();
    return scene;
}

Scene load_obj_file(const std::string& path) { return load_obj_text(read_scene_file(path), path); }

}  // namespace raypack
