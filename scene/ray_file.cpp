#include "scene/ray_file.h"

#include <bit>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <stdexcept>

#include "scene/atomic_file.h"
#include "scene/memory_budget.h"

namespace raypack {
namespace {

static_assert(std::endian::native == std::endian::little, "the exchange format is little-endian");

constexpr char kRaysMagic[8] = {'R', 'A', 'Y', 'S', '0', '0', '0', '1'};
constexpr char kHitsMagic[8] = {'H', 'I', 'T', 'S', '0', '0', '0', '1'};
constexpr std::size_t kRayRecord = 32, kHitRecord = 16;

[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw std::runtime_error(path + ": " + what);
}

std::ifstream open_checked(const std::string& path, const char (&magic)[8], std::uint64_t& count,
                           std::size_t header, std::size_t record) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, "cannot open for reading");
    char m[8];
    if (!in.read(m, 8) || std::memcmp(m, magic, 8) != 0)
        fail(path, std::string("not a ") + (magic[0] == 'R' ? ".rays" : ".hits") + " file (bad magic)");
    if (!in.read(reinterpret_cast<char*>(&count), 8)) fail(path, "truncated header");
    const auto size = std::filesystem::file_size(path);
    if (size < header || count > (size - header) / record) fail(path, "truncated: header says " + std::to_string(count) + " records");
    if (size != header + count * record) fail(path, "size does not match the record count");
    return in;
}

}  // namespace

RayFile read_rays(const std::string& path) {
    std::uint64_t count = 0;
    std::ifstream in = open_checked(path, kRaysMagic, count, 24, kRayRecord);
    std::uint32_t kind = 0, reserved = 0;
    in.read(reinterpret_cast<char*>(&kind), 4);
    in.read(reinterpret_cast<char*>(&reserved), 4);
    if (kind > 1) fail(path, "unknown ray kind " + std::to_string(kind) + " (expected 0 or 1)");
    // The rays and the read buffer, 32 bytes each per ray.
    require_memory(count * 64, path + ": " + std::to_string(count) + " rays");
    RayFile file;
    file.kind = RayKind(kind);
    file.rays.resize(count);
    std::vector<float> buf(8 * count);
    if (!in.read(reinterpret_cast<char*>(buf.data()), std::streamsize(buf.size() * 4))) fail(path, "truncated records");
    for (std::uint64_t i = 0; i < count; ++i) {
        const float* r = &buf[8 * i];
        Rayf& ray = file.rays[i];
        ray.org = {r[0], r[1], r[2]};
        ray.tnear = r[3];
        ray.dir = {r[4], r[5], r[6]};
        ray.tfar = r[7];
        if (!all_finite(ray.org) || !all_finite(ray.dir) || std::isnan(ray.tnear) || std::isnan(ray.tfar))
            fail(path, "ray " + std::to_string(i) + " has a non-finite origin, direction or NaN interval");
    }
    return file;
}

std::vector<Hitf> read_hits(const std::string& path) {
    std::uint64_t count = 0;
    std::ifstream in = open_checked(path, kHitsMagic, count, 16, kHitRecord);
    require_memory(count * sizeof(Hitf), path + ": " + std::to_string(count) + " hits");
    std::vector<Hitf> hits(count);
    for (auto& h : hits) {
        char rec[16];
        in.read(rec, 16);
        std::memcpy(&h.t, rec, 4);
        std::memcpy(&h.prim, rec + 4, 4);
        std::memcpy(&h.u, rec + 8, 4);
        std::memcpy(&h.v, rec + 12, 4);
    }
    if (!in) fail(path, "truncated records");
    return hits;
}

void write_rays(const std::string& path, RayKind kind, std::span<const Rayf> rays) {
    write_atomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) fail(path, "cannot open for writing");
        const std::uint64_t count = rays.size();
        const std::uint32_t k = std::uint32_t(kind), reserved = 0;
        out.write(kRaysMagic, 8);
        out.write(reinterpret_cast<const char*>(&count), 8);
        out.write(reinterpret_cast<const char*>(&k), 4);
        out.write(reinterpret_cast<const char*>(&reserved), 4);
        for (const Rayf& r : rays) {
            const float rec[8] = {r.org.x, r.org.y, r.org.z, r.tnear, r.dir.x, r.dir.y, r.dir.z, r.tfar};
            out.write(reinterpret_cast<const char*>(rec), sizeof rec);
        }
        if (!out.flush()) fail(path, "write failed");
    });
}

void write_hits(const std::string& path, std::span<const Hitf> hits) {
    write_atomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) fail(path, "cannot open for writing");
        const std::uint64_t count = hits.size();
        out.write(kHitsMagic, 8);
        out.write(reinterpret_cast<const char*>(&count), 8);
        for (const Hitf& h : hits) {
            char rec[16];
            std::memcpy(rec, &h.t, 4);
            std::memcpy(rec + 4, &h.prim, 4);
            std::memcpy(rec + 8, &h.u, 4);
            std::memcpy(rec + 12, &h.v, 4);
            out.write(rec, 16);
        }
        if (!out.flush()) fail(path, "write failed");
    });
}

}  // namespace raypack
