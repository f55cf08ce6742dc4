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
/// Version 2: a ninth float per record, the ray's time.
constexpr char kTimedRaysMagic[8] = {'R', 'A', 'Y', 'S', '0', '0', '0', '2'};
constexpr char kHitsMagic[8] = {'H', 'I', 'T', 'S', '0', '0', '0', '1'};
constexpr std::size_t kRayRecord = 32, kTimedRayRecord = 36, kHitRecord = 16;

/// Whether a rays file's first bytes are version 2's magic.
bool timed_rays(std::string_view head) { return head.size() >= 8 && std::memcmp(head.data(), kTimedRaysMagic, 8) == 0; }

[[noreturn]] void fail(const std::string& path, const std::string& what) {
    throw std::runtime_error(path + ": " + what);
}

/// The record count of a file of `size` bytes whose first bytes are `head`
/// (at least the magic and the count if the file has them), checked against
/// the magic and the size.
std::uint64_t checked_count(std::string_view head, std::uint64_t size, const std::string& name,
                            const char (&magic)[8], std::size_t header, std::size_t record) {
    if (head.size() < 8 || std::memcmp(head.data(), magic, 8) != 0)
        fail(name, std::string("not a ") + (magic[0] == 'R' ? ".rays" : ".hits") + " file (bad magic)");
    if (head.size() < 16) fail(name, "truncated header");
    std::uint64_t count = 0;
    std::memcpy(&count, head.data() + 8, 8);
    if (size < header || count > (size - header) / record)
        fail(name, "truncated: header says " + std::to_string(count) + " records");
    if (size != header + count * record) fail(name, "size does not match the record count");
    return count;
}

/// A whole file, after its header was checked by `check` (given the file's
/// first bytes and its size), so that an absurd header is refused before
/// anything large is read.
template <class Check>
std::string read_checked(const std::string& path, Check&& check) {
    std::ifstream in(path, std::ios::binary);
    if (!in) fail(path, "cannot open for reading");
    std::error_code ec;
    const std::uint64_t size = std::filesystem::file_size(path, ec);
    if (ec) fail(path, "cannot open for reading");
    char head[24];
    in.read(head, sizeof head);
    check(std::string_view(head, std::size_t(in.gcount())), size);
    std::string bytes(std::size_t(size), '\0');
    in.clear();
    in.seekg(0);
    if (!in.read(bytes.data(), std::streamsize(size))) fail(path, "truncated records");
    return bytes;
}

}  // namespace

RayFile parse_rays(std::string_view bytes, const std::string& name) {
    const bool timed = timed_rays(bytes);
    const std::size_t record = timed ? kTimedRayRecord : kRayRecord;
    const std::uint64_t count =
        checked_count(bytes, bytes.size(), name, timed ? kTimedRaysMagic : kRaysMagic, 24, record);
    std::uint32_t kind = 0;
    std::memcpy(&kind, bytes.data() + 16, 4);
    if (kind > 1) fail(name, "unknown ray kind " + std::to_string(kind) + " (expected 0 or 1)");
    require_memory(count * sizeof(Rayf), name + ": " + std::to_string(count) + " rays");
    RayFile file;
    file.kind = RayKind(kind);
    file.rays.resize(count);
    if (timed) file.times.resize(count);
    const char* rec = bytes.data() + 24;
    for (std::uint64_t i = 0; i < count; ++i, rec += record) {
        float r[9];
        std::memcpy(r, rec, record);
        Rayf& ray = file.rays[i];
        ray.org = {r[0], r[1], r[2]};
        ray.tnear = r[3];
        ray.dir = {r[4], r[5], r[6]};
        ray.tfar = r[7];
        if (!all_finite(ray.org) || !all_finite(ray.dir) || std::isnan(ray.tnear) || std::isnan(ray.tfar))
            fail(name, "ray " + std::to_string(i) + " has a non-finite origin, direction or NaN interval");
        if (timed) {
            if (!std::isfinite(r[8])) fail(name, "ray " + std::to_string(i) + " has a non-finite time");
            file.times[i] = r[8];
        }
    }
    return file;
}

std::vector<Hitf> parse_hits(std::string_view bytes, const std::string& name) {
    const std::uint64_t count = checked_count(bytes, bytes.size(), name, kHitsMagic, 16, kHitRecord);
    require_memory(count * sizeof(Hitf), name + ": " + std::to_string(count) + " hits");
    std::vector<Hitf> hits(count);
    const char* rec = bytes.data() + 16;
    for (auto& h : hits) {
        std::memcpy(&h.t, rec, 4);
        std::memcpy(&h.prim, rec + 4, 4);
        std::memcpy(&h.u, rec + 8, 4);
        std::memcpy(&h.v, rec + 12, 4);
        rec += kHitRecord;
    }
    return hits;
}

RayFile read_rays(const std::string& path) {
    // The file's bytes and the rays, 32 bytes each per ray.
    const std::string bytes = read_checked(path, [&](std::string_view head, std::uint64_t size) {
        const bool timed = timed_rays(head);
        const std::uint64_t count = checked_count(head, size, path, timed ? kTimedRaysMagic : kRaysMagic, 24,
                                                  timed ? kTimedRayRecord : kRayRecord);
        require_memory(count * 72, path + ": " + std::to_string(count) + " rays");
    });
    return parse_rays(bytes, path);
}

std::vector<Hitf> read_hits(const std::string& path) {
    const std::string bytes = read_checked(path, [&](std::string_view head, std::uint64_t size) {
        const std::uint64_t count = checked_count(head, size, path, kHitsMagic, 16, kHitRecord);
        require_memory(count * (kHitRecord + sizeof(Hitf)), path + ": " + std::to_string(count) + " hits");
    });
    return parse_hits(bytes, path);
}

void write_rays(const std::string& path, RayKind kind, std::span<const Rayf> rays, std::span<const float> times) {
    if (!times.empty() && times.size() != rays.size())
        throw std::invalid_argument(path + ": " + std::to_string(times.size()) + " times for " +
                                    std::to_string(rays.size()) + " rays");
    write_atomically(path, [&](const std::string& tmp) {
        std::ofstream out(tmp, std::ios::binary);
        if (!out) fail(path, "cannot open for writing");
        const std::uint64_t count = rays.size();
        const std::uint32_t k = std::uint32_t(kind), reserved = 0;
        out.write(times.empty() ? kRaysMagic : kTimedRaysMagic, 8);
        out.write(reinterpret_cast<const char*>(&count), 8);
        out.write(reinterpret_cast<const char*>(&k), 4);
        out.write(reinterpret_cast<const char*>(&reserved), 4);
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Rayf& r = rays[i];
            const float rec[9] = {r.org.x, r.org.y, r.org.z, r.tnear, r.dir.x, r.dir.y, r.dir.z, r.tfar,
                                  times.empty() ? 0.0f : times[i]};
            out.write(reinterpret_cast<const char*>(rec), std::streamsize(times.empty() ? kRayRecord : kTimedRayRecord));
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
