// Wavefront OBJ (vertices, normals and faces), plus the camera and light OBJ lacks.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <span>
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

/// Faces with more vertices are refused (a bound on one face's
/// triangulation work; real meshes stay far below it).
constexpr std::size_t kMaxFaceVertices = 255;

/// A face corner's normal index not given ("f 1 2 3" has none).
constexpr std::int32_t kAbsent = std::numeric_limits<std::int32_t>::min();
/// An index that names no vertex whatever the file holds (0-based, below 0
/// or above what 32 bits hold); the face reports it as out of range.
constexpr std::int32_t kOutOfRange = -1;

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/// Splits `s` at blanks into `out` (cleared first). A loop over the
/// characters: find_first_of with a set of five calls memchr per character
/// (a third of the time loading the bunny).
void split_blank(std::string_view s, std::vector<std::string_view>& out) {
    out.clear();
    const std::size_t n = s.size();
    for (std::size_t i = 0; i < n;) {
        if (is_blank(s[i])) {
            ++i;
            continue;
        }
        std::size_t j = i + 1;
        while (j < n && !is_blank(s[j])) ++j;
        out.push_back(s.substr(i, j - i));
        i = j;
    }
}

float parse_coordinate(std::string_view token, const std::string& path, int line) {
    float x = 0;
    switch (parse_float_token(token, x)) {
        case NumberToken::Ok: return x;
        case NumberToken::NotNumber: throw SceneError(path, line, "expected a number, got '" + std::string(token) + "'");
        case NumberToken::NonFinite: throw SceneError(path, line, "non-finite number '" + std::string(token) + "'");
        case NumberToken::OutOfRange: break;
    }
    throw SceneError(path, line, "number '" + std::string(token) + "' out of range");
}

/// One OBJ index (1-based, or negative: counted back from the last of the
/// `defined` so far) as a 0-based one, kOutOfRange if it cannot name a
/// vertex; indices past the end are caught when the faces are built.
std::int32_t parse_index(std::string_view token, std::size_t defined, std::string_view corner, const std::string& path,
                         int line) {
    long long i = 0;
    if (parse_int_token(token, i) != NumberToken::Ok)
        throw SceneError(path, line, "bad vertex reference '" + std::string(corner) + "' in face");
    if (i == 0) throw SceneError(path, line, "index 0 in face '" + std::string(corner) + "' (OBJ counts from 1)");
    const std::int64_t index = i > 0 ? std::int64_t(i) - 1 : std::int64_t(defined) + std::int64_t(i);
    return index < 0 || index > std::numeric_limits<std::int32_t>::max() ? kOutOfRange : std::int32_t(index);
}

/// The mesh as read: vertices, normals and each face's corners (absolute
/// 0-based indices, resolved as they were read: a negative index counts back
/// from the vertices defined before its line).
struct ObjMesh {
    std::vector<Vec3f> positions, normals;
    struct Corner {
        std::int32_t position, normal;  ///< normal: kAbsent if none
    };
    std::vector<Corner> corners;
    struct Face {
        std::uint32_t first, count;  ///< into corners
        int line;
    };
    std::vector<Face> faces;
};

/// Reads v, vn and f lines; every other statement (vt, o, g, s, usemtl,
/// mtllib, l, p ...) is skipped: raypack renders the faces with one material.
ObjMesh parse_obj(std::string_view text, const std::string& path) {
    ObjMesh mesh;
    // Capacity for a statement per line (only what is used gets touched):
    // growing by doubling touched twice the memory (fresh pages are slow).
    const auto lines = std::size_t(std::count(text.begin(), text.end(), '\n')) + 1;
    mesh.positions.reserve(lines);
    mesh.faces.reserve(lines);
    mesh.corners.reserve(3 * lines);
    std::vector<std::string_view> tokens;
    int line = 0;
    for (std::size_t pos = 0; pos < text.size();) {
        std::size_t end = text.find('\n', pos);
        if (end == std::string_view::npos) end = text.size();
        std::string_view ln = text.substr(pos, end - pos);
        pos = end + 1;
        ++line;
        if (const std::size_t hash = ln.find('#'); hash != std::string_view::npos) ln = ln.substr(0, hash);
        split_blank(ln, tokens);
        if (tokens.empty()) continue;
        const std::string_view kw = tokens[0];
        if (kw == "v" || kw == "vn") {
            // "v x y z [w]" and "v x y z r g b" (vertex colours): every value
            // must be a finite number; the first three are the point.
            if (tokens.size() < 4)
                throw SceneError(path, line, "'" + std::string(kw) + "' needs 3 coordinates, got " +
                                                 std::to_string(tokens.size() - 1));
            float c[3];
            for (std::size_t i = 1; i < tokens.size(); ++i) {
                const float x = parse_coordinate(tokens[i], path, line);
                if (i <= 3) c[i - 1] = x;
            }
            (kw == "v" ? mesh.positions : mesh.normals).push_back({c[0], c[1], c[2]});
        } else if (kw == "f") {
            const std::size_t n = tokens.size() - 1;
            if (n < 3) throw SceneError(path, line, "a face needs at least 3 vertices, got " + std::to_string(n));
            if (n > kMaxFaceVertices)
                throw SceneError(path, line, "face with " + std::to_string(n) + " vertices; at most " +
                                                 std::to_string(kMaxFaceVertices) + " are supported");
            mesh.faces.push_back({std::uint32_t(mesh.corners.size()), std::uint32_t(n), line});
            for (std::size_t k = 1; k <= n; ++k) {
                // v, v/vt, v//vn or v/vt/vn.
                const std::string_view corner = tokens[k];
                const std::size_t slash = corner.find('/');
                ObjMesh::Corner c{parse_index(corner.substr(0, slash), mesh.positions.size(), corner, path, line),
                                  kAbsent};
                if (slash != std::string_view::npos) {
                    const std::string_view rest = corner.substr(slash + 1);
                    const std::size_t slash2 = rest.find('/');
                    if (slash2 != std::string_view::npos) {
                        const std::string_view vn = rest.substr(slash2 + 1);
                        if (vn.find('/') != std::string_view::npos)
                            throw SceneError(path, line, "bad vertex reference '" + std::string(corner) + "' in face");
                        c.normal = parse_index(vn, mesh.normals.size(), corner, path, line);
                    }
                }
                mesh.corners.push_back(c);
            }
        }
    }
    return mesh;
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
    const ObjMesh mesh = parse_obj(text, path);
    const auto np = std::int64_t(mesh.positions.size()), nn = std::int64_t(mesh.normals.size());
    const std::size_t triangles_before = scene.triangles.size();
    scene.reserve_triangles(mesh.corners.size() - 2 * mesh.faces.size());  // n - 2 per polygon
    std::vector<Vec3f> pos, nrm;
    for (const ObjMesh::Face& face : mesh.faces) {
        pos.clear();
        nrm.clear();
        bool normals = true;
        for (std::uint32_t k = face.first; k < face.first + face.count; ++k) {
            const ObjMesh::Corner& c = mesh.corners[k];
            if (c.position < 0 || c.position >= np) throw SceneError(path, face.line, "vertex index out of range in face");
            pos.push_back(mesh.positions[std::size_t(c.position)]);
            if (c.normal == kAbsent) {
                normals = false;
                continue;
            }
            if (c.normal < 0 || c.normal >= nn) throw SceneError(path, face.line, "normal index out of range in face");
            nrm.push_back(mesh.normals[std::size_t(c.normal)]);
            // Lenient, unlike NFF "pp": exporters write zero normals for
            // degenerate faces; such a face falls back to flat.
            if (nrm.back() == Vec3f{}) normals = false;
        }
        for (const auto& tri : triangulate_polygon(std::span<const Vec3f>(pos))) {
            if (normals)
                scene.add_triangle(pos[tri[0]], pos[tri[1]], pos[tri[2]], nrm[tri[0]], nrm[tri[1]], nrm[tri[2]],
                                   material);
            else
                scene.add_triangle(pos[tri[0]], pos[tri[1]], pos[tri[2]], material);
        }
    }
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
