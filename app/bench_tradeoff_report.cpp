#include "app/bench_tradeoff_report.h"

#include <cmath>
#include <nlohmann/json.hpp>

#include "app/json_table.h"

namespace raypack::app {
namespace {

using Json = nlohmann::ordered_json;

Json number_or_null(bool present, double v) { return present && std::isfinite(v) ? Json(v) : Json(); }

/// One flat object per row; the same keys on every row (null where a
/// measure does not apply), which is the CSV header too. Schema: docs/accuracy.md.
Json to_json(const TradeoffRow& r) {
    Json j;
    j["family"] = r.family;
    j["variant"] = r.variant;
    j["throughput_scene"] = r.throughput_scene;
    j["throughput_rays"] = r.throughput_rays;
    j["timed_rays"] = r.timed_rays;
    j["repeat"] = r.repeat;
    j["mrays_per_s_median"] = r.mrays_per_s_median;
    j["mrays_per_s_min"] = r.mrays_per_s_min;
    j["mrays_per_s_max"] = r.mrays_per_s_max;
    const bool leaks = r.leaks.has_value();
    const LeakCounts l = r.leaks.value_or(LeakCounts{});
    j["leak_rays"] = leaks ? Json(l.rays()) : Json();
    j["leaks"] = leaks ? Json(l.leaks()) : Json();
    j["leak_fraction"] = number_or_null(leaks && l.rays() > 0, double(l.leaks()) / double(std::max<std::uint64_t>(l.rays(), 1)));
    j["leak_vertex_rays"] = leaks ? Json(l.vertex_rays) : Json();
    j["leak_vertex"] = leaks ? Json(l.vertex_leaks) : Json();
    j["leak_edge_rays"] = leaks ? Json(l.edge_rays) : Json();
    j["leak_edge"] = leaks ? Json(l.edge_leaks) : Json();
    j["leak_inside_rays"] = leaks ? Json(l.inside_rays) : Json();
    j["leak_inside"] = leaks ? Json(l.inside_leaks) : Json();
    const bool ulps = r.t_ulps.has_value();
    const UlpError u = r.t_ulps.value_or(UlpError{});
    j["t_ulp_rays"] = ulps ? Json(u.rays) : Json();
    j["t_ulp_missed"] = ulps ? Json(u.missed) : Json();
    j["t_ulp_median"] = number_or_null(ulps, u.median);
    j["t_ulp_p99"] = number_or_null(ulps, u.p99);
    j["t_ulp_max"] = number_or_null(ulps, u.max);
    const bool self = !r.self.empty();
    std::uint64_t self_rays = 0, self_hits = 0;
    for (const SelfIntersections& s : r.self) self_rays += s.rays(), self_hits += s.self();
    j["self_rays"] = self ? Json(self_rays) : Json();
    j["self_hits"] = self ? Json(self_hits) : Json();
    j["self_fraction"] = number_or_null(self && self_rays > 0, double(self_hits) / double(std::max<std::uint64_t>(self_rays, 1)));
    const auto& placements = self_intersection_placements();
    for (std::size_t i = 0; i < placements.size(); ++i) {
        const std::string label = placement_label(placements[i]);
        j["self_shadow_rays_" + label] = self ? Json(r.self[i].shadow_rays) : Json();
        j["self_shadow_hits_" + label] = self ? Json(r.self[i].shadow_self) : Json();
        j["shadow_wrong_" + label] = self ? Json(r.self[i].shadow_wrong) : Json();
        j["self_reflect_rays_" + label] = self ? Json(r.self[i].reflect_rays) : Json();
        j["self_reflect_hits_" + label] = self ? Json(r.self[i].reflect_self) : Json();
        const bool placed = i < r.placed_image.size();
        j["placed_psnr_db_" + label] = placed ? number_or_null(true, r.placed_image[i].psnr_db) : Json();
        j["placed_differing_fraction_" + label] = placed ? Json(r.placed_image[i].differing_fraction) : Json();
    }
    const bool image = r.image.has_value();
    j["image_scene"] = image ? Json(r.image_scene) : Json();
    j["image_width"] = image ? Json(r.image_width) : Json();
    j["image_height"] = image ? Json(r.image_height) : Json();
    // JSON has no infinity: identical images give psnr_db null and differing_fraction 0.
    j["psnr_db"] = image ? number_or_null(true, r.image->psnr_db) : Json();
    j["differing_fraction"] = image ? Json(r.image->differing_fraction) : Json();
    // Added after the first schema: at the end, so that column positions hold.
    j["structure"] = r.structure;
    j["builder"] = r.builder;
    j["kernels"] = r.kernels;
    j["build_ms"] = number_or_null(r.build_ms.has_value(), r.build_ms.value_or(0));
    j["sah_cost"] = number_or_null(r.sah_cost.has_value(), r.sah_cost.value_or(0));
    return j;
}

std::vector<Json> all_json(const std::vector<TradeoffRow>& rows) {
    std::vector<Json> out;
    for (const TradeoffRow& r : rows) out.push_back(to_json(r));
    return out;
}

std::string fraction_text(std::uint64_t part, std::uint64_t whole) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%llu/%llu", (unsigned long long)part, (unsigned long long)whole);
    return buf;
}

}  // namespace

const std::vector<Placement>& self_intersection_placements() {
    static const std::vector<Placement> placements = {{1e-4f, 0}, {1e-2f, 0}, {1, 0}, {1e2f, 0},
                                                       {1e4f, 0}, {1e6f, 0}, {1, 1e6f}};
    return placements;
}

std::string placement_label(const Placement& where) {
    char buf[32];
    if (where.translation != 0) std::snprintf(buf, sizeof buf, "t%.0e", double(where.translation));
    else std::snprintf(buf, sizeof buf, "s%.0e", double(where.scale));
    return buf;
}

void print_tradeoff_table(std::FILE* out, const std::vector<TradeoffRow>& rows) {
    std::fprintf(out, "%-9s %-10s %-5s %9s %17s %12s %21s %14s %8s %9s %9s %8s\n", "family", "variant", "accel",
                 "Mrays/s", "(min - max)", "leak frac", "t ULPs med/p99/max", "self-isect", "PSNR dB", "differ",
                 "build ms", "SAH");
    for (const TradeoffRow& r : rows) {
        char spread[32], leak[24] = "-", ulps[40] = "-", psnr[16] = "-", differ[16] = "-", build[16] = "-",
                          sah[16] = "-";
        if (r.build_ms) std::snprintf(build, sizeof build, "%.2f", *r.build_ms);
        if (r.sah_cost) std::snprintf(sah, sizeof sah, "%.1f", *r.sah_cost);
        std::snprintf(spread, sizeof spread, "(%.2f - %.2f)", r.mrays_per_s_min, r.mrays_per_s_max);
        if (r.leaks && r.leaks->rays() > 0)
            std::snprintf(leak, sizeof leak, "%.3g", double(r.leaks->leaks()) / double(r.leaks->rays()));
        if (r.t_ulps) std::snprintf(ulps, sizeof ulps, "%.0f/%.0f/%.0f", r.t_ulps->median, r.t_ulps->p99, r.t_ulps->max);
        std::string self = "-";
        if (!r.self.empty()) {
            std::uint64_t rays = 0, hits = 0;
            for (const SelfIntersections& s : r.self) rays += s.rays(), hits += s.self();
            self = fraction_text(hits, rays);
        }
        if (r.image) {
            if (std::isfinite(r.image->psnr_db)) std::snprintf(psnr, sizeof psnr, "%.1f", r.image->psnr_db);
            else std::snprintf(psnr, sizeof psnr, "inf");
            std::snprintf(differ, sizeof differ, "%.4f", r.image->differing_fraction);
        }
        std::fprintf(out, "%-9s %-10s %-5s %9.2f %17s %12s %21s %14s %8s %9s %9s %8s\n", r.family.c_str(),
                     r.variant.c_str(), r.structure.c_str(), r.mrays_per_s_median, spread, leak, ulps, self.c_str(),
                     psnr, differ, build, sah);
    }
    // The per-placement self-intersections, for the offset rows.
    bool header = false;
    for (const TradeoffRow& r : rows) {
        if (r.self.empty()) continue;
        if (!header) {
            std::fprintf(out, "\nself-intersections (shadow + reflection rays that found the object they left), and shadow\n"
                         "rays whose answer differs from the reference traced from the hit point itself; for the offsets\n"
                         "also the image scene placed alike against itself unplaced (PSNR dB/fraction of pixels that differ):\n%-18s",
                         "");
            for (const Placement& p : self_intersection_placements()) std::fprintf(out, " %14s", placement_label(p).c_str());
            std::fprintf(out, "\n");
            header = true;
        }
        std::fprintf(out, "%-18s", (r.family + " " + r.variant).c_str());
        for (const SelfIntersections& s : r.self) std::fprintf(out, " %14s", fraction_text(s.self(), s.rays()).c_str());
        std::fprintf(out, "\n%-18s", "  wrong shadows");
        for (const SelfIntersections& s : r.self)
            std::fprintf(out, " %14s", fraction_text(s.shadow_wrong, s.shadow_rays).c_str());
        std::fprintf(out, "\n");
        if (r.placed_image.empty()) continue;
        // The image scene placed alike against itself unplaced: PSNR dB / fraction of pixels that differ.
        std::fprintf(out, "%-18s", "  placed image");
        for (const ImageError& e : r.placed_image) {
            char cell[24];
            std::snprintf(cell, sizeof cell, "%.1f/%.3f", std::isfinite(e.psnr_db) ? e.psnr_db : 99.0,
                          e.differing_fraction);
            std::fprintf(out, " %14s", cell);
        }
        std::fprintf(out, "\n");
    }
}

void write_tradeoff_json(const std::string& path, const std::vector<TradeoffRow>& rows) {
    write_json_rows(path, all_json(rows));
}

void write_tradeoff_csv(const std::string& path, const std::vector<TradeoffRow>& rows) {
    TradeoffRow columns;
    columns.self.resize(self_intersection_placements().size());
    write_csv_rows(path, to_json(columns), all_json(rows));
}

}  // namespace raypack::app
