#include "app/bench_html.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

#include "app/json_table.h"

namespace raypack::app {
namespace {

std::string escape(const std::string& text) {
    std::string out;
    for (const char c : text) {
        switch (c) {
            case '<': out += "&lt;"; break;
            case '>': out += "&gt;"; break;
            case '&': out += "&amp;"; break;
            case '"': out += "&quot;"; break;
            default: out += c;
        }
    }
    return out;
}

std::string format(const char* fmt, double v) {
    char buf[48];
    std::snprintf(buf, sizeof buf, fmt, v);
    return buf;
}

std::string optional_cell(const std::optional<double>& v) { return v ? format("%.2f", *v) : "-"; }

std::string base64(const std::string& bytes) {
    static const char* const kDigits = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    std::string out;
    out.reserve((bytes.size() + 2) / 3 * 4);
    for (std::size_t i = 0; i < bytes.size(); i += 3) {
        const std::uint32_t b0 = std::uint8_t(bytes[i]);
        const std::uint32_t b1 = i + 1 < bytes.size() ? std::uint8_t(bytes[i + 1]) : 0u;
        const std::uint32_t b2 = i + 2 < bytes.size() ? std::uint8_t(bytes[i + 2]) : 0u;
        const std::uint32_t n = (b0 << 16) | (b1 << 8) | b2;
        out += kDigits[(n >> 18) & 63];
        out += kDigits[(n >> 12) & 63];
        out += i + 1 < bytes.size() ? kDigits[(n >> 6) & 63] : '=';
        out += i + 2 < bytes.size() ? kDigits[n & 63] : '=';
    }
    return out;
}

/// Havran and Sixta's figures for the SPD scenes (their grid and octree
/// tables, erich666/StandardProceduralDatabases docs; docs/structures.md):
/// N_IT, N_TS, N_ETS, N_EETS per ray over all rays of a 513 x 513 render.
struct HavranFigures {
    const char* scene;
    double grid[4];    ///< uniform grid, customary resolution
    double octree[4];  ///< Octree84-C, depth 7
};
constexpr HavranFigures kHavranSixta1999[] = {
    {"balls", {41.48, 17.32, 17.32, 13.93}, {94.75, 167, 24.71, 16.12}},
    {"gears", {17.52, 18.95, 18.95, 14.62}, {39.13, 88.60, 13.20, 6.27}},
    {"mount", {13.32, 15.01, 15.01, 9.60}, {18.52, 60.08, 9.44, 3.31}},
    {"rings", {21.48, 33.71, 33.71, 27.22}, {35.20, 121, 17.65, 8.29}},
    {"teapot", {13.30, 41.24, 41.24, 38.08}, {40.02, 83.40, 13.75, 9.53}},
    {"tetra", {9.17, 18.24, 18.24, 16.63}, {47.07, 58.09, 9.21, 7.22}},
    {"tree", {355, 56.36, 56.36, 45.36}, {741, 219, 32.74, 23.33}},
};

/// The SPD scene a bench scene is, if it is one of the shared files.
const HavranFigures* spd_scene(const BenchRow& row) {
    const std::string& f = row.scene_file;
    const std::string base = f.substr(f.find_last_of('/') == std::string::npos ? 0 : f.find_last_of('/') + 1);
    for (const HavranFigures& h : kHavranSixta1999)
        if (base == std::string(h.scene) + ".nff") return &h;
    return nullptr;
}

using GroupKey = std::tuple<std::string, std::string, int>;  // scene, rays, threads

/// The fastest width of each structure in each group, in the run's order.
struct Best {
    std::string accel;
    double mrays;
    int packet;
};

std::vector<std::pair<GroupKey, std::vector<Best>>> best_per_group(const std::vector<BenchRow>& rows) {
    std::vector<std::pair<GroupKey, std::vector<Best>>> groups;
    for (const BenchRow& r : rows) {
        const GroupKey key{r.scene_file, r.rays, r.threads};
        auto g = std::find_if(groups.begin(), groups.end(), [&](const auto& e) { return e.first == key; });
        if (g == groups.end()) g = groups.insert(groups.end(), {key, {}});
        auto b = std::find_if(g->second.begin(), g->second.end(), [&](const Best& e) { return e.accel == r.accel; });
        if (b == g->second.end()) g->second.push_back({r.accel, r.mrays_per_s_median, r.packet});
        else if (r.mrays_per_s_median > b->mrays) *b = {r.accel, r.mrays_per_s_median, r.packet};
    }
    return groups;
}

std::string bar_chart(const std::vector<Best>& bests) {
    double top = 0;
    for (const Best& b : bests) top = std::max(top, b.mrays);
    const int bar_h = 18, label_w = 70, width = 520, height = int(bests.size()) * (bar_h + 6) + 6;
    std::ostringstream s;
    s << "<svg width=\"" << width << "\" height=\"" << height << "\">";
    int y = 6;
    for (const Best& b : bests) {
        const double w = top > 0 ? (width - label_w - 110) * b.mrays / top : 0;
        s << "<text x=\"0\" y=\"" << y + 13 << "\" font-size=\"12\">" << escape(b.accel) << "</text>"
          << "<rect x=\"" << label_w << "\" y=\"" << y << "\" width=\"" << format("%.1f", w) << "\" height=\""
          << bar_h << "\" fill=\"#3b6ea5\"/>"
          << "<text x=\"" << format("%.1f", label_w + w + 4) << "\" y=\"" << y + 13 << "\" font-size=\"12\">"
          << format("%.2f", b.mrays) << " (K=" << b.packet << ")</text>";
        y += bar_h + 6;
    }
    s << "</svg>";
    return s.str();
}

}  // namespace

std::string processor_name() {
    std::ifstream in("/proc/cpuinfo");
    std::string line;
    while (std::getline(in, line))
        if (line.rfind("model name", 0) == 0) {
            const std::size_t colon = line.find(':');
            if (colon != std::string::npos) return line.substr(line.find_first_not_of(' ', colon + 1));
        }
    return "unknown";
}

std::string bmp_bytes(const Image& image) {
    const int w = image.width, h = image.height;
    const int row = (3 * w + 3) / 4 * 4;
    const std::uint32_t data = std::uint32_t(row) * std::uint32_t(h), size = 54 + data;
    std::string out(size, '\0');
    auto put32 = [&](std::size_t at, std::uint32_t v) {
        for (int i = 0; i < 4; ++i) out[at + std::size_t(i)] = char((v >> (8 * i)) & 0xFF);
    };
    out[0] = 'B', out[1] = 'M';
    put32(2, size);
    put32(10, 54);
    put32(14, 40);
    put32(18, std::uint32_t(w));
    put32(22, std::uint32_t(h));
    out[26] = 1, out[28] = 24;
    put32(34, data);
    for (int y = 0; y < h; ++y) {
        std::size_t at = 54 + std::size_t(h - 1 - y) * std::size_t(row);  // bottom-up rows
        for (int x = 0; x < w; ++x) {
            const Vec3f c = image.at(x, y);
            for (int ch = 2; ch >= 0; --ch)  // BGR
                out[at++] = char(std::lround(std::clamp(c[ch], 0.0f, 1.0f) * 255.0f));
        }
    }
    return out;
}

void write_bench_html(const std::string& path, const std::vector<BenchRow>& rows, const BenchHtmlContext& context) {
    std::ostringstream h;
    const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
    char date[32];
    std::strftime(date, sizeof date, "%Y-%m-%d %H:%M UTC", std::gmtime(&now));
    h << "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>raypack bench</title>\n"
      << "<style>body{font-family:sans-serif;margin:2em;max-width:70em}table{border-collapse:collapse;margin:1em 0}"
         "td,th{border:1px solid #bbb;padding:2px 6px;text-align:right}th{background:#eee}"
         "td:first-child,th:first-child{text-align:left}figure{display:inline-block;margin:0.5em}"
         "img{image-rendering:pixelated}</style></head><body>\n";
    h << "<h1>raypack bench</h1>\n<p>Command: <code>" << escape(context.command) << "</code><br>Machine: "
      << escape(context.machine) << "<br>Date: " << date << "<br>Rows: " << rows.size()
      << " (every one validated against the brute-force oracle on a sample of its rays)</p>\n";

    // Each structure at its fastest width.
    h << "<h2 id=\"best\">Each structure at its fastest width</h2>\n"
      << "<p>Mrays/s (median of the timed passes); the ratio is to the fastest structure of the group, and to "
         "the BVH default (bvh4, K = 16) where the run has it.</p>\n";
    const auto groups = best_per_group(rows);
    for (const auto& [key, bests] : groups) {
        const auto& [scene, rays, threads] = key;
        double fastest = 0;
        std::optional<double> bvh_default;
        for (const Best& b : bests) fastest = std::max(fastest, b.mrays);
        for (const BenchRow& r : rows)
            if (r.scene_file == scene && r.rays == rays && r.threads == threads && r.accel == "bvh4" && r.packet == 16)
                bvh_default = r.mrays_per_s_median;
        h << "<h3>" << escape(scene) << ", " << escape(rays) << " rays, " << threads << " thread"
          << (threads > 1 ? "s" : "") << "</h3>\n<table class=\"best\"><tr><th>structure</th><th>Mrays/s</th>"
          << "<th>K</th><th>/ fastest</th><th>/ bvh4 K=16</th></tr>\n";
        for (const Best& b : bests)
            h << "<tr><td>" << escape(b.accel) << "</td><td>" << format("%.2f", b.mrays) << "</td><td>" << b.packet
              << "</td><td>" << format("%.2f", fastest > 0 ? b.mrays / fastest : 0) << "</td><td>"
              << (bvh_default && *bvh_default > 0 ? format("%.2f", b.mrays / *bvh_default) : "-") << "</td></tr>\n";
        h << "</table>\n" << bar_chart(bests) << "\n";
    }

    // Every row.
    h << "<h2 id=\"rows\">Every row</h2>\n<p>Havran's measures per ray: N_IT intersection tests, N_TS traversal "
         "steps, N_ETS leaves or cells entered, N_EETS empty ones (docs/bench.md).</p>\n"
      << "<table class=\"rows\"><tr><th>scene</th><th>rays</th><th>threads</th><th>structure</th><th>K</th>"
         "<th>Mrays/s</th><th>min</th><th>max</th><th>build ms</th><th>memory KiB</th><th>N_IT</th><th>N_TS</th>"
         "<th>N_ETS</th><th>N_EETS</th></tr>\n";
    for (const BenchRow& r : rows)
        h << "<tr><td>" << escape(r.scene) << "</td><td>" << escape(r.rays) << "</td><td>" << r.threads << "</td><td>"
          << escape(r.accel) << "</td><td>" << r.packet << "</td><td>" << format("%.2f", r.mrays_per_s_median)
          << "</td><td>" << format("%.2f", r.mrays_per_s_min) << "</td><td>" << format("%.2f", r.mrays_per_s_max)
          << "</td><td>" << format("%.1f", r.build_ms) << "</td><td>" << format("%.1f", double(r.memory_bytes) / 1024.0)
          << "</td><td>" << optional_cell(r.n_it) << "</td><td>" << optional_cell(r.n_ts) << "</td><td>"
          << optional_cell(r.n_ets) << "</td><td>" << optional_cell(r.n_eets) << "</td></tr>\n";
    h << "</table>\n";

    // Havran and Sixta's figures beside this run's, for the SPD scenes.
    std::ostringstream havran;
    for (const HavranFigures& fig : kHavranSixta1999) {
        std::vector<std::string> shown;  // the measures do not depend on the width: one line per structure
        for (const BenchRow& r : rows) {
            if (spd_scene(r) != &fig || r.rays != "camera" || r.threads != rows.front().threads) continue;
            if (r.accel != "grid" && r.accel != "octree") continue;
            if (!r.n_it || std::find(shown.begin(), shown.end(), r.accel) != shown.end()) continue;
            shown.push_back(r.accel);
            const double* theirs = r.accel == "grid" ? fig.grid : fig.octree;
            havran << "<tr><td>" << fig.scene << "</td><td>" << escape(r.accel) << "</td><td>"
                   << optional_cell(r.n_it) << " / " << optional_cell(r.n_ts) << " / " << optional_cell(r.n_ets)
                   << " / " << optional_cell(r.n_eets) << "</td><td>" << format("%.2f", theirs[0]) << " / "
                   << format("%.2f", theirs[1]) << " / " << format("%.2f", theirs[2]) << " / "
                   << format("%.2f", theirs[3]) << "</td></tr>\n";
        }
    }
    h << "<h2 id=\"havran\">Havran's measures beside Havran and Sixta (1999)</h2>\n";
    if (havran.str().empty()) {
        h << "<p>No SPD scene file (scenes/balls.nff, gears, mount, rings, teapot, tetra, tree) was traced with "
             "the grid or the octree in this run.</p>\n";
    } else {
        h << "<p>N_IT / N_TS / N_ETS / N_EETS per ray. Raypack: this run's camera rays. Havran and Sixta: all rays "
             "of the SPD render at 513 x 513 (camera, shadow, reflected), their uniform grid at its customary "
             "resolution and their Octree84-C of depth 7. The rays differ, so the figures compare in kind, not "
             "digit for digit; docs/structures.md compares whole renders (<code>render --counts</code>).</p>\n"
          << "<table class=\"havran\"><tr><th>scene</th><th>raypack</th><th>raypack N_IT / N_TS / N_ETS / N_EETS</th>"
             "<th>Havran and Sixta</th></tr>\n"
          << havran.str() << "</table>\n";
    }

    // Cost heat maps.
    h << "<h2 id=\"cost\">Cost of the camera rays</h2>\n<p>Nodes or cells entered plus primitive tests per pixel's "
         "camera ray, from dark (the picture's least) to yellow (its most), the scale under each picture "
         "(measure/cost_map.h).</p>\n";
    if (context.maps.empty()) h << "<p>No structure that counts its work was run.</p>\n";
    for (const CostMapPicture& m : context.maps)
        h << "<figure><img alt=\"" << escape(m.scene + " " + m.accel) << "\" width=\"" << m.image.width * 2
          << "\" src=\"data:image/bmp;base64," << base64(bmp_bytes(m.image)) << "\"><figcaption>" << escape(m.scene)
          << ", " << escape(m.accel) << "</figcaption></figure>\n";

    // Marks, once loaded, how many pictures decoded: what a browser test reads.
    h << "<script>window.addEventListener('load',function(){var i=Array.prototype.slice.call(document.images);"
         "document.body.setAttribute('data-images-ok',i.filter(function(x){return x.complete&&x.naturalWidth>0;})"
         ".length+'/'+i.length);});</script>\n</body></html>\n";
    write_text_atomically(path, h.str());
}

}  // namespace raypack::app
