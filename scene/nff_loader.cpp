// NFF (Haines, "Neutral File Format", scenes/nff-format.txt) as a stream of
// whitespace-separated tokens, so that the one-line cone the SPD programs
// write and the three-line cone the format document shows both load.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <memory>
#include <istream>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "scene/load.h"
#include "scene/memory_budget.h"
#include "scene/nff_text.h"
#include "scene/number_token.h"
#include "scene/read_file.h"
#include "scene/triangulate.h"

namespace raypack {

namespace {

/// Largest polygon we accept; checked before anything is allocated.
constexpr long long kMaxPolygonVertices = 1'000'000;
constexpr long long kMaxResolution = 65536;
/// Largest height field side, in samples (2^28 samples are 1 GiB of floats).
constexpr long long kMaxHeightFieldSide = 65536;
constexpr long long kMaxHeightFieldSamples = 1ll << 28;

/// Tokens with the line each starts on; '#' comments run to the end of a line.
class Tokenizer {
public:
    explicit Tokenizer(std::string_view text) : s_(text) {}

    /// The next token, empty at the end of the text.
    std::string_view next() {
        skip_blank();
        if (pos_ >= s_.size()) return {};
        const std::size_t start = pos_;
        while (pos_ < s_.size() && !is_blank(s_[pos_]) && s_[pos_] != '#') ++pos_;
        line_ = cur_line_;
        return s_.substr(start, pos_ - start);
    }

    std::string_view peek() {
        const std::size_t pos = pos_;
        const int cur = cur_line_, line = line_;
        const std::string_view tok = next();
        pos_ = pos;
        cur_line_ = cur;
        line_ = line;
        return tok;
    }

    /// Line of the token last returned; at the end of the text, still the last
    /// token's line, which is where a truncated entity stops.
    int line() const { return line_; }

private:
    static bool is_blank(char c) { return c == ' ' || c == '\n' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

    void skip_blank() {
        while (pos_ < s_.size()) {
            const char c = s_[pos_];
            if (c == '\n') {
                ++cur_line_;
                ++pos_;
            } else if (is_blank(c)) {
                ++pos_;
            } else if (c == '#') {
                while (pos_ < s_.size() && s_[pos_] != '\n') ++pos_;
            } else {
                break;
            }
        }
    }

    std::string_view s_;
    std::size_t pos_ = 0;
    int cur_line_ = 1;
    int line_ = 1;
};

std::string quote_token(std::string_view tok) {
    constexpr std::size_t kMax = 40;  // keep messages readable on binary junk
    // Appended piecewise: "'" + std::string(...) trips gcc 12's -Wrestrict.
    std::string q(1, '\'');
    q.append(tok.substr(0, kMax));
    q.append(tok.size() > kMax ? "...'" : "'");
    return q;
}

class NffParser {
public:
    NffParser(std::string_view text, const std::string& name) : tok_(text), name_(name) {}

    Scene parse() {
        scene_.source = name_;
        for (std::string_view kw = tok_.next(); !kw.empty(); kw = tok_.next()) {
            entity_ = kw;
            entity_line_ = tok_.line();
            if (kw == "v") viewpoint();
            else if (kw == "b") scene_.background = vec3("background colour");
            else if (kw == "l") light();
            else if (kw == "f") fill();
            else if (kw == "c") cone();
            else if (kw == "s") sphere();
            else if (kw == "p") polygon(false);
            else if (kw == "pp") polygon(true);
            else if (kw == "la") parallelogram_light();
            else if (kw == "ls") sphere_light();
            else if (kw == "ld") distant_light();
            else if (kw == "obj") obj_mesh();
            else if (kw == "lens") lens();
            else if (kw == "gloss") gloss();
            else if (kw == "hf") height_field();
            else if (kw == "begin") begin_object();
            else if (kw == "end") end_object();
            else if (kw == "inst") instance();
            else if (kw == "move") move();
            else if (kw == "shutter") shutter();
            else if (float x; parse_float_token(kw, x) != NumberToken::NotNumber)
                fail(entity_line_, "unexpected number " + quote_token(kw) +
                                       " where an entity keyword was expected (too many values before it?)");
            else
                fail(entity_line_, "unknown keyword " + quote_token(kw));
        }
        if (defining_)
            fail(entity_line_, "object " + quote_token(defining_name_) + " begun on line " +
                                   std::to_string(defining_line_) + " has no 'end'");
        close_moving_group();
        scene_.has_camera = camera_line_ != 0;
        scene_.update_features();
        if (scene_.hit_id_count() > kMaxHitIds - 1)
            fail(tok_.line(), "the scene holds more than 2^32 - 2 primitives with its instances expanded; "
                              "hits are numbered in 32 bits");
        return std::move(scene_);
    }

private:
    [[noreturn]] void fail(int line, const std::string& problem) const { throw SceneError(name_, line, problem); }

    /// " (p on line 12)": which entity a value belongs to.
    std::string where() const { return " (" + quote_token(entity_) + " on line " + std::to_string(entity_line_) + ")"; }

    std::string_view expect_token(const std::string& what) {
        const std::string_view t = tok_.next();
        if (t.empty()) fail(tok_.line(), "unexpected end of file: expected " + what + where());
        return t;
    }

    // `what` and `index` only build a message on failure, so the hot path does
    // not allocate.
    float number(const char* what, long long index = -1, long long of = 0) {
        const std::string_view t = tok_.next();
        float x = 0;
        const NumberToken r = t.empty() ? NumberToken::NotNumber : parse_float_token(t, x);
        if (r == NumberToken::Ok) return x;
        std::string desc = what;
        if (index >= 0) desc += " of vertex " + std::to_string(index + 1) + " of " + std::to_string(of);
        if (t.empty()) fail(tok_.line(), "unexpected end of file: expected " + desc + where());
        if (r == NumberToken::NotNumber)
            fail(tok_.line(), "expected a number for " + desc + where() + ", got " + quote_token(t));
        if (r == NumberToken::NonFinite)
            fail(tok_.line(), "non-finite number " + quote_token(t) + " for " + desc + where());
        fail(tok_.line(), "number " + quote_token(t) + " out of range for " + desc + where());
    }

    long long integer(const std::string& what) {
        const std::string_view t = expect_token(what);
        long long v = 0;
        const NumberToken r = parse_int_token(t, v);
        if (r == NumberToken::Ok) return v;
        if (r == NumberToken::OutOfRange) fail(tok_.line(), what + " " + quote_token(t) + " out of range" + where());
        fail(tok_.line(), "expected an integer for " + what + where() + ", got " + quote_token(t));
    }

    Vec3f vec3(const char* what, long long index = -1, long long of = 0) {
        // Three statements: argument evaluation order is unspecified.
        Vec3f v;
        v.x = number(what, index, of);
        v.y = number(what, index, of);
        v.z = number(what, index, of);
        return v;
    }

    void keyword(std::string_view expected) {
        const std::string_view t = expect_token(quote_token(expected));
        if (t != expected) fail(tok_.line(), "expected " + quote_token(expected) + where() + ", got " + quote_token(t));
    }

    /// Objects before any "f" get a default material rather than an error.
    std::uint32_t material() {
        if (current_material_ < 0) {
            scene_.materials.push_back(Material{});
            current_material_ = std::int32_t(scene_.materials.size() - 1);
        }
        return std::uint32_t(current_material_);
    }

    // The spec wants "v" before any object; nothing here depends on that, so
    // objects before it are accepted. A second "v" is an error: which one
    // would be meant is not clear.
    void viewpoint() {
        if (camera_line_ != 0)
            fail(entity_line_, "second viewpoint 'v' block (the first is on line " + std::to_string(camera_line_) + ")");
        Camera& cam = scene_.camera;
        keyword("from");
        cam.from = vec3("from");
        keyword("at");
        cam.at = vec3("at");
        const int at_line = tok_.line();
        keyword("up");
        cam.up = vec3("up");
        const int up_line = tok_.line();
        keyword("angle");
        cam.fov_deg = number("angle");
        if (!(cam.fov_deg > 0 && cam.fov_deg < 180))
            fail(tok_.line(), "view angle " + std::to_string(cam.fov_deg) + " not in (0, 180) degrees" + where());
        keyword("hither");
        cam.hither = number("hither");
        if (cam.hither < 0) fail(tok_.line(), "negative hither distance" + where());
        keyword("resolution");
        const long long w = integer("x resolution");
        const long long h = integer("y resolution");
        if (w <= 0 || h <= 0 || w > kMaxResolution || h > kMaxResolution)
            fail(tok_.line(), "resolution " + std::to_string(w) + " x " + std::to_string(h) + " not in 1.." +
                                  std::to_string(kMaxResolution) + where());
        cam.width = int(w);
        cam.height = int(h);
        if (cam.from == cam.at) fail(at_line, "from and at coincide" + where());
        if (cam.up == Vec3f{}) fail(up_line, "zero-length up vector" + where());
        if (cross(cam.up, cam.at - cam.from) == Vec3f{})
            fail(up_line, "up vector parallel to the view direction" + where());
        camera_line_ = entity_line_;
    }

    void light() {
        refuse_inside_object();
        PointLight l;
        l.position = vec3("light position");
        l.has_color = optional_color(l.color, false);
        scene_.lights.push_back(l);
    }

    /// A light's optional "r g b": present when a number follows. The
    /// extensions' lights (`emitting`) refuse negative components.
    bool optional_color(Vec3f& color, bool emitting) {
        float x;
        if (parse_float_token(tok_.peek(), x) == NumberToken::NotNumber) return false;
        color = vec3("light colour");
        if (emitting && (color.x < 0 || color.y < 0 || color.z < 0))
            fail(tok_.line(), "negative light colour" + where());
        return true;
    }

    /// The material of a light's own surface: the current one, marked as
    /// covering area light `light`.
    std::uint32_t emitter_material(std::size_t light) {
        Material m = scene_.materials[material()];
        m.area_light = std::int32_t(light);
        scene_.materials.push_back(m);
        return std::uint32_t(scene_.materials.size() - 1);
    }

    void parallelogram_light() {
        refuse_inside_object();
        AreaLight l;
        l.shape = AreaLightShape::Parallelogram;
        l.corner = vec3("light corner");
        l.edge1 = vec3("light edge e");
        l.edge2 = vec3("light edge f");
        if (!(length(cross(l.edge1, l.edge2)) > 0))
            fail(tok_.line(), "light edges e and f are zero or parallel" + where());
        l.has_color = optional_color(l.color, true);
        const std::uint32_t m = emitter_material(scene_.area_lights.size());
        const Vec3f a = l.corner, b = l.corner + l.edge1, c = b + l.edge2, d = l.corner + l.edge2;
        // Both triangles face cross(e, f), the emitting side.
        l.first_prim = scene_.add_triangle(a, b, c, m);
        scene_.add_triangle(a, c, d, m);
        l.prim_count = 2;
        scene_.area_lights.push_back(l);
    }

    void sphere_light() {
        refuse_inside_object();
        AreaLight l;
        l.shape = AreaLightShape::Sphere;
        l.center = vec3("light centre");
        l.radius = number("light radius");
        if (!(l.radius > 0)) fail(tok_.line(), "light radius must be positive" + where());
        l.has_color = optional_color(l.color, true);
        l.first_prim = scene_.add_sphere(l.center, l.radius, emitter_material(scene_.area_lights.size()));
        l.prim_count = 1;
        scene_.area_lights.push_back(l);
    }

    void distant_light() {
        refuse_inside_object();
        DistantLight l;
        const Vec3f d = vec3("light direction");
        if (!(length(d) > 0)) fail(tok_.line(), "zero light direction" + where());
        l.direction = normalize(d);
        l.has_color = optional_color(l.color, true);
        scene_.distant_lights.push_back(l);
    }

    // `obj FILE`: a relative FILE is relative to the NFF file's folder.
    void obj_mesh() {
        const std::string file(expect_token("OBJ file name"));
        std::filesystem::path path(file);
        if (path.is_relative() && !name_.starts_with("gen:")) path = std::filesystem::path(name_).parent_path() / path;
        try {
            append_obj_triangles(path.string(), material(), target());
        } catch (const SceneError& e) {
            fail(entity_line_, "obj " + quote_token(file) + ": " + e.what());
        }
    }

    // `hf nx ny x0 y0 z0 x1 y1 z1` and nx * ny heights (rows of nx along x,
    // from y0 to y1), or `hf FILE x0 y0 z0 x1 y1 z1` with the heights read
    // from an image's first channel (top row at y1). A height h in [0, 1]
    // lies at z0 + h (z1 - z0). docs/scene-format.md.
    void height_field() {
        const std::string_view first = expect_token("height field sample count or image file");
        long long nx = 0, ny = 0;
        std::string file;
        const NumberToken r = parse_int_token(first, nx);
        if (r == NumberToken::NotNumber) {
            file = std::string(first);
        } else {
            if (r != NumberToken::Ok) fail(tok_.line(), "sample count " + quote_token(first) + " out of range" + where());
            ny = integer("height field sample count ny");
            for (const long long n : {nx, ny})
                if (n < 2 || n > kMaxHeightFieldSide)
                    fail(tok_.line(), "height field sample count " + std::to_string(n) + " outside [2, " +
                                          std::to_string(kMaxHeightFieldSide) + "]" + where());
            if (nx * ny > kMaxHeightFieldSamples)
                fail(tok_.line(), "height field of " + std::to_string(nx * ny) + " samples exceeds the limit of " +
                                      std::to_string(kMaxHeightFieldSamples) + where());
        }
        HeightField f;
        f.lo = vec3("height field corner x0 y0 z0");
        f.hi = vec3("height field corner x1 y1 z1");
        if (!(f.lo.x < f.hi.x && f.lo.y < f.hi.y))
            fail(tok_.line(), "height field rectangle is empty (needs x0 < x1 and y0 < y1)" + where());
        const float z0 = f.lo.z, z1 = f.hi.z;
        if (file.empty()) {
            require_memory(std::uint64_t(nx) * std::uint64_t(ny) * 12, name_ + ": height field of " +
                                                                           std::to_string(nx * ny) + " samples");
            f.nx = std::uint32_t(nx);
            f.ny = std::uint32_t(ny);
            // Grown as the heights arrive: a count far beyond the text (a
            // truncated or hostile file) fails at its end, not at a huge allocation.
            f.z.reserve(std::size_t(std::min<long long>(nx * ny, 1 << 20)));
            for (long long k = 0; k < nx * ny; ++k) f.z.push_back(z0 + number("height") * (z1 - z0));
        } else {
            read_height_image(file, f);
            for (float& z : f.z) z = z0 + z * (z1 - z0);
        }
        for (const float z : f.z)
            if (!std::isfinite(z)) fail(entity_line_, "height field height overflows" + where());
        target().add_height_field(std::move(f), material());
    }

    void read_height_image(const std::string& file, HeightField& f) {
        std::filesystem::path path(file);
        if (path.is_relative() && !name_.starts_with("gen:")) path = std::filesystem::path(name_).parent_path() / path;
        const HeightImageReader& reader = height_image_reader();
        if (!reader) fail(entity_line_, "hf " + quote_token(file) + ": no image reader in this program");
        std::uint32_t w = 0, h = 0;
        std::vector<float> pixels;
        try {
            pixels = reader(path.string(), w, h);
        } catch (const std::exception& e) {
            fail(entity_line_, "hf " + quote_token(file) + ": " + e.what());
        }
        if (w < 2 || h < 2 || w > kMaxHeightFieldSide || h > kMaxHeightFieldSide)
            fail(entity_line_, "hf " + quote_token(file) + ": image of " + std::to_string(w) + " x " +
                                   std::to_string(h) + " pixels (each side must be in [2, " +
                                   std::to_string(kMaxHeightFieldSide) + "])");
        f.nx = w;
        f.ny = h;
        f.z.resize(std::size_t(w) * h);
        for (std::uint32_t j = 0; j < h; ++j)  // image rows run from the top, y1, down
            for (std::uint32_t i = 0; i < w; ++i) f.z[std::size_t(j) * w + i] = pixels[std::size_t(h - 1 - j) * w + i];
        for (const float z : f.z)
            if (!std::isfinite(z)) fail(entity_line_, "hf " + quote_token(file) + ": non-finite pixel value");
    }

    /// Primitives go to the object being defined, else while a `move` is in
    /// force to the moving group, else to the scene.
    Scene& target() {
        if (defining_) return *defining_;
        if (move_ == Vec3f{}) return scene_;
        if (!moving_group_) {
            moving_group_ = std::make_shared<Scene>();
            moving_group_->source = name_;
        }
        return *moving_group_;
    }

    // `move dx dy dz`: the primitives and instances that follow move by
    // (dx, dy, dz) over the shutter. The primitives of one `move` form an
    // object of their own, placed by a moving instance from the identity to
    // the translation: one placement for the group, so a group of many
    // primitives gets one structure of its own.
    void move() {
        if (defining_)
            fail(entity_line_, "'move' inside object " + quote_token(defining_name_) +
                                   ": objects are static (move their placements instead)");
        const Vec3f d = vec3("motion");
        close_moving_group();
        move_ = d;
        move_line_ = entity_line_;
    }

    /// Places the primitives gathered under the last `move`, if any.
    void close_moving_group() {
        if (!moving_group_) return;
        moving_group_->update_features(&scene_);
        const auto k = std::uint32_t(scene_.objects.size());
        const std::string name = "move on line " + std::to_string(move_line_);
        scene_.objects.push_back(std::move(moving_group_));
        scene_.object_names.push_back(name);
        moving_group_.reset();
        Affine3f end;
        end.m[0][3] = move_.x, end.m[1][3] = move_.y, end.m[2][3] = move_.z;
        scene_.add_moving_instance(k, Affine3f{}, end, scene_);
        count_top_ids(k);
    }

    // `shutter t0 t1`: the times rays may carry; motion runs from t0 to t1.
    void shutter() {
        if (shutter_line_ != 0)
            fail(entity_line_, "second 'shutter' line (the first is on line " + std::to_string(shutter_line_) + ")");
        const float t0 = number("shutter opening");
        const float t1 = number("shutter closing");
        if (!(t0 <= t1)) fail(tok_.line(), "shutter closes before it opens" + where());
        scene_.shutter_open = t0;
        scene_.shutter_close = t1;
        shutter_line_ = entity_line_;
    }

    /// Hit ids of a placement at the top, refused past 32 bits.
    void count_top_ids(std::uint32_t object) {
        top_instanced_ids_ += scene_.objects[object]->hit_id_count();
        if (scene_.prims.size() + top_instanced_ids_ > kMaxHitIds - 1)
            fail(entity_line_, "the scene holds more than 2^32 - 2 primitives with its instances expanded; "
                               "hits are numbered in 32 bits");
    }

    /// A 3 x 4 row-major matrix of an `inst` line, checked.
    Affine3f instance_matrix() {
        Affine3f m;
        for (auto& row : m.m)
            for (float& x : row) x = number("instance matrix entry");
        const double det = affine_cast<double>(m).determinant();
        if (!std::isfinite(det) || std::fabs(det) < 1e-30)
            fail(tok_.line(), "singular instance matrix (determinant " + std::to_string(det) + ")" + where());
        const Affine3d inv = inverse(affine_cast<double>(m));
        for (const auto& row : inv.m)
            for (double x : row)
                if (!std::isfinite(float(x))) fail(tok_.line(), "instance matrix has no finite inverse" + where());
        return m;
    }

    /// Lights are the scene's, not an object's: an instance would have to
    /// place them, and light sampling knows only the scene's own.
    void refuse_inside_object() {
        if (defining_)
            fail(entity_line_, "a light inside object " + quote_token(defining_name_) +
                                   " (lights belong to the scene, outside 'begin' ... 'end')");
    }

    // `begin NAME` ... `end`: an object, placed only by `inst`.
    void begin_object() {
        const std::string_view name = expect_token("object name");
        if (defining_)
            fail(entity_line_, "'begin " + std::string(name) + "' inside object " + quote_token(defining_name_) +
                                   " (begun on line " + std::to_string(defining_line_) + "): objects do not nest");
        if (object_index_.count(std::string(name)) != 0)
            fail(entity_line_, "object " + quote_token(name) + " defined twice");
        defining_ = std::make_shared<Scene>();
        defining_->source = name_;
        defining_name_ = std::string(name);
        defining_line_ = entity_line_;
    }

    void end_object() {
        if (!defining_) fail(entity_line_, "'end' without 'begin'");
        if (defining_->prims.empty()) fail(entity_line_, "object " + quote_token(defining_name_) + " is empty");
        defining_->update_features(&scene_);
        if (defining_->hit_id_count() > kMaxHitIds - 1)
            fail(entity_line_, "object " + quote_token(defining_name_) + " holds " +
                                   std::to_string(defining_->hit_id_count()) +
                                   " primitives with its instances expanded; hits are numbered in 32 bits");
        object_index_.emplace(defining_name_, std::uint32_t(scene_.objects.size()));
        scene_.objects.push_back(std::move(defining_));
        scene_.object_names.push_back(defining_name_);
        defining_.reset();
    }

    // `inst NAME m00 m01 m02 m03 m10 .. m23`: places NAME by the 3 x 4
    // row-major affine matrix.
    void instance() {
        const std::string_view name = expect_token("object name");
        const auto found = object_index_.find(std::string(name));
        if (found == object_index_.end()) {
            if (defining_ && name == defining_name_)
                fail(entity_line_, "object " + quote_token(name) + " places itself (instances cannot be recursive)");
            fail(entity_line_, "unknown object " + quote_token(name) + " (define it with 'begin' ... 'end' first)");
        }
        const std::uint32_t k = found->second;
        if (scene_.objects[k]->instance_depth() + 1 > kMaxInstanceDepth)
            fail(entity_line_, "placing " + quote_token(name) + " nests instances more than " +
                                   std::to_string(kMaxInstanceDepth) + " levels deep");
        const Affine3f m = instance_matrix();
        // A second matrix: where the placement is at the shutter's closing.
        float x;
        const bool two = parse_float_token(tok_.peek(), x) != NumberToken::NotNumber;
        Affine3f end = two ? instance_matrix() : m;
        if (defining_) {
            if (two)
                fail(entity_line_, "a moving placement inside object " + quote_token(defining_name_) +
                                       ": objects are static (move their placements instead)");
            defining_->add_instance(k, m, scene_);
            return;
        }
        end.m[0][3] += move_.x, end.m[1][3] += move_.y, end.m[2][3] += move_.z;
        if (!end.finite()) fail(entity_line_, "the 'move' in force takes the placement past the float range" + where());
        if (end == m) {
            scene_.add_instance(k, m, scene_);
        } else {
            refuse_singular_motion(m, end);
            scene_.add_moving_instance(k, m, end, scene_);
        }
        count_top_ids(k);
    }

    /// The matrices are interpolated entry by entry, which can pass through a
    /// singular matrix (a half turn does, at mid-shutter): the determinant,
    /// a cubic in s, keeps its sign and stays away from 0 at 65 points.
    void refuse_singular_motion(const Affine3f& a, const Affine3f& b) {
        const double det0 = affine_cast<double>(a).determinant();
        for (int i = 1; i <= 64; ++i) {
            const double s = double(i) / 64.0;
            Affine3d m;
            for (int r = 0; r < 3; ++r)
                for (int c = 0; c < 4; ++c) m.m[r][c] = (1.0 - s) * double(a.m[r][c]) + s * double(b.m[r][c]);
            const double det = m.determinant();
            if (!(det * det0 > 0) || std::fabs(det) < 1e-30)
                fail(entity_line_, "the placement passes through a singular matrix at shutter fraction " +
                                       std::to_string(s) + " (the two matrices are interpolated entry by entry)" +
                                       where());
        }
    }

    void lens() {
        if (lens_line_ != 0)
            fail(entity_line_, "second 'lens' line (the first is on line " + std::to_string(lens_line_) + ")");
        Camera& cam = scene_.camera;
        cam.lens_radius = number("lens radius");
        if (cam.lens_radius < 0) fail(tok_.line(), "negative lens radius" + where());
        cam.focus_distance = number("focus distance");
        if (!(cam.focus_distance > 0)) fail(tok_.line(), "focus distance must be positive" + where());
        lens_line_ = entity_line_;
    }

    void gloss() {
        gloss_ = number("gloss exponent");
        if (gloss_ < 0) fail(tok_.line(), "negative gloss exponent" + where());
    }

    void fill() {
        Material m;
        m.color = vec3("fill colour");
        m.kd = number("Kd");
        m.ks = number("Ks");
        m.shine = number("Shine");
        m.transmittance = number("T");
        m.ior = number("index of refraction");
        m.gloss = gloss_;
        scene_.materials.push_back(m);
        current_material_ = std::int32_t(scene_.materials.size() - 1);
    }

    void sphere() {
        const Vec3f c = vec3("sphere centre");
        const float r = number("sphere radius");
        target().add_sphere(c, r, material());
    }

    void cone() {
        const Vec3f base = vec3("cone base");
        const float base_r = number("cone base radius");
        const Vec3f apex = vec3("cone apex");
        const float apex_r = number("cone apex radius");
        if (base == apex) fail(tok_.line(), "cone base and apex coincide" + where());
        // Negative radii mean "inside only", which needs both to agree.
        if ((base_r < 0 && apex_r > 0) || (base_r > 0 && apex_r < 0))
            fail(tok_.line(), "cone radii of opposite signs" + where());
        target().add_cone(base, base_r, apex, apex_r, material());
    }

    // A polygon of n vertices becomes n-2 triangles (triangulate_polygon). A
    // degenerate polygon (all vertices collinear, zero Newell normal) is not an
    // error: it loads as its fan of zero-area triangles, which no ray hits, so
    // counts stay n-2 and generated scenes with slivers still load.
    void polygon(bool patch) {
        const long long n = integer("vertex count");
        if (n < 0) fail(tok_.line(), "negative vertex count " + std::to_string(n) + where());
        if (n < 3) fail(tok_.line(), "a polygon needs at least 3 vertices, got " + std::to_string(n) + where());
        if (n > kMaxPolygonVertices)
            fail(tok_.line(), "vertex count " + std::to_string(n) + " exceeds the limit of " +
                                  std::to_string(kMaxPolygonVertices) + where());
        verts_.resize(std::size_t(n));
        normals_.resize(patch ? std::size_t(n) : 0);
        for (long long i = 0; i < n; ++i) {
            verts_[i] = vec3("position", i, n);
            if (patch) {
                normals_[i] = vec3("normal", i, n);
                if (normals_[i] == Vec3f{}) fail(tok_.line(), "zero-length vertex normal" + where());
            }
        }
        const std::uint32_t m = material();
        for (const auto& t : triangulate_polygon(std::span<const Vec3f>(verts_))) {
            if (patch)
                target().add_triangle(verts_[t[0]], verts_[t[1]], verts_[t[2]], normals_[t[0]], normals_[t[1]],
                                    normals_[t[2]], m);
            else
                target().add_triangle(verts_[t[0]], verts_[t[1]], verts_[t[2]], m);
        }
    }

    Tokenizer tok_;
    const std::string& name_;
    Scene scene_;
    std::string_view entity_;  ///< keyword of the entity being read
    int entity_line_ = 0;
    int camera_line_ = 0;  ///< line of the "v" block, 0 while none
    int lens_line_ = 0;    ///< line of the "lens" line, 0 while none
    float gloss_ = 0;      ///< the last "gloss" value, for the "f" lines after it
    /// The last "f" (lights' own surfaces get copies of it appended after it), -1 before any.
    std::int32_t current_material_ = -1;
    std::vector<Vec3f> verts_, normals_;  ///< reused between polygons
    std::shared_ptr<Scene> defining_;     ///< the object between 'begin' and 'end', if any
    std::string defining_name_;
    int defining_line_ = 0;
    std::uint64_t top_instanced_ids_ = 0;  ///< hit ids of the scene's instances so far
    Vec3f move_{};                         ///< the `move` in force
    int move_line_ = 0;
    std::shared_ptr<Scene> moving_group_;  ///< primitives under the `move` in force, if any
    int shutter_line_ = 0;
    std::unordered_map<std::string, std::uint32_t> object_index_;  ///< name -> Scene::objects index
};

}  // namespace

Scene load_nff_text(std::string_view text, const std::string& name) { return NffParser(text, name).parse(); }

Scene load_nff(std::istream& in, const std::string& name) {
    std::string text{std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    if (in.bad()) throw SceneError(name, 0, "read error");
    return load_nff_text(text, name);
}

Scene load_nff_file(const std::string& path) { return load_nff_text(read_scene_file(path), path); }

}  // namespace raypack
