// The .rays / .hits exchange format (docs/rays.md): round trips, and every
// kind of bad file read_rays / read_hits promise to reject.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/ray_file.h"

// The suite is called RayFile, like raypack::RayFile: keep it out of namespace raypack.
namespace {

namespace fs = std::filesystem;
using raypack::Hitf;
using raypack::RayKind;
using raypack::Rayf;
using raypack::read_hits;
using raypack::read_rays;
using raypack::write_hits;
using raypack::write_rays;

class RayFile : public ::testing::Test {
protected:
    void SetUp() override {
        std::random_device rd;
        dir_ = fs::temp_directory_path() / ("raypack_rayfile_" + std::to_string(rd()) + std::to_string(rd()));
        fs::create_directories(dir_);
    }
    void TearDown() override {
        std::error_code ec;
        fs::remove_all(dir_, ec);
    }
    std::string path(const std::string& name) const { return (dir_ / name).string(); }

    static std::string slurp(const std::string& p) {
        std::ifstream in(p, std::ios::binary);
        return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    }
    static void spit(const std::string& p, const std::string& bytes) {
        std::ofstream out(p, std::ios::binary | std::ios::trunc);
        out.write(bytes.data(), std::streamsize(bytes.size()));
    }
    /// Runs f, which must throw std::runtime_error naming the file and containing `what`.
    template <class F>
    static void expect_error(F&& f, const std::string& file, const std::string& what) {
        try {
            f();
            ADD_FAILURE() << "no exception; expected one mentioning '" << what << "'";
        } catch (const std::runtime_error& e) {
            const std::string msg = e.what();
            EXPECT_NE(msg.find(file), std::string::npos) << msg;
            EXPECT_NE(msg.find(what), std::string::npos) << msg;
        }
    }

    static std::vector<Rayf> sample_rays() {
        const float inf = std::numeric_limits<float>::infinity();
        std::vector<Rayf> rays;
        Rayf r;
        r.org = {1.5f, -2.25f, 3.0f};
        r.dir = {0.0f, -0.0f, 1.0f};  // signed zero must survive
        r.tnear = 0.01f;
        r.tfar = inf;
        rays.push_back(r);
        r.org = {-1e30f, 1e-30f, std::numeric_limits<float>::denorm_min()};
        r.dir = {0.1f, 0.2f, 0.3f};
        r.tnear = -inf;
        r.tfar = 42.0f;
        rays.push_back(r);
        std::mt19937 rng(7);
        std::uniform_real_distribution<float> u(-100, 100);
        for (int i = 0; i < 100; ++i) {
            r.org = {u(rng), u(rng), u(rng)};
            r.dir = {u(rng), u(rng), u(rng)};
            r.tnear = std::fabs(u(rng));
            r.tfar = r.tnear + std::fabs(u(rng));
            rays.push_back(r);
        }
        return rays;
    }

    fs::path dir_;
};

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

TEST_F(RayFile, RaysRoundTripBitExact) {
    const std::vector<Rayf> rays = sample_rays();
    for (RayKind kind : {RayKind::ClosestHit, RayKind::AnyHit}) {
        const std::string p = path("a.rays");
        write_rays(p, kind, rays);
        EXPECT_EQ(fs::file_size(p), 24 + 32 * rays.size());
        const raypack::RayFile back = read_rays(p);
        EXPECT_EQ(back.kind, kind);
        ASSERT_EQ(back.rays.size(), rays.size());
        for (std::size_t i = 0; i < rays.size(); ++i) {
            const Rayf &a = rays[i], &b = back.rays[i];
            for (int k = 0; k < 3; ++k) {
                EXPECT_TRUE(same_bits(a.org[k], b.org[k])) << i;
                EXPECT_TRUE(same_bits(a.dir[k], b.dir[k])) << i;
            }
            EXPECT_TRUE(same_bits(a.tnear, b.tnear)) << i;
            EXPECT_TRUE(same_bits(a.tfar, b.tfar)) << i;
        }
    }
    // The documented layout: magic, count, kind, reserved, then ox oy oz tnear dx dy dz tfar.
    const std::string bytes = slurp(path("a.rays"));
    ASSERT_GE(bytes.size(), 56u);
    EXPECT_EQ(bytes.substr(0, 8), "RAYS0001");
    std::uint64_t count = 0;
    std::uint32_t kind = 7, reserved = 7;
    float rec[8];
    std::memcpy(&count, bytes.data() + 8, 8);
    std::memcpy(&kind, bytes.data() + 16, 4);
    std::memcpy(&reserved, bytes.data() + 20, 4);
    std::memcpy(rec, bytes.data() + 24, 32);
    EXPECT_EQ(count, rays.size());
    EXPECT_EQ(kind, 1u);
    EXPECT_EQ(reserved, 0u);
    EXPECT_EQ(rec[0], 1.5f);
    EXPECT_EQ(rec[3], 0.01f);
    EXPECT_TRUE(std::signbit(rec[5]));
    EXPECT_EQ(rec[6], 1.0f);
}

// Version 2 (motion blur): a time after each record; version 1 files still
// read, with no times; a non-finite time is refused.
TEST_F(RayFile, TimedRaysRoundTripAsVersion2) {
    const std::vector<Rayf> rays = sample_rays();
    std::vector<float> times(rays.size());
    for (std::size_t i = 0; i < times.size(); ++i) times[i] = 0.25f * float(i) - 3.0f;
    write_rays(path("t.rays"), RayKind::AnyHit, rays, times);
    EXPECT_EQ(fs::file_size(path("t.rays")), 24 + 36 * rays.size());
    const std::string bytes = slurp(path("t.rays"));
    EXPECT_EQ(bytes.substr(0, 8), "RAYS0002");
    float rec[9];
    std::memcpy(rec, bytes.data() + 24 + 36, 36);
    EXPECT_EQ(rec[0], rays[1].org.x);
    EXPECT_EQ(rec[8], times[1]);
    const raypack::RayFile back = read_rays(path("t.rays"));
    EXPECT_EQ(back.kind, RayKind::AnyHit);
    ASSERT_EQ(back.rays.size(), rays.size());
    EXPECT_EQ(back.times, times);
    for (std::size_t i = 0; i < rays.size(); ++i) EXPECT_TRUE(same_bits(back.rays[i].tfar, rays[i].tfar)) << i;
    write_rays(path("u.rays"), RayKind::ClosestHit, rays);
    EXPECT_TRUE(read_rays(path("u.rays")).times.empty());
    times[7] = std::numeric_limits<float>::quiet_NaN();
    write_rays(path("n.rays"), RayKind::ClosestHit, rays, times);
    expect_error([&] { read_rays(path("n.rays")); }, path("n.rays"), "ray 7 has a non-finite time");
    // A version 2 header over version 1 records does not add up.
    std::string v1 = slurp(path("u.rays"));
    v1[7] = '2';
    spit(path("m.rays"), v1);
    expect_error([&] { read_rays(path("m.rays")); }, path("m.rays"), "truncated");
}

TEST_F(RayFile, EmptyFilesRoundTrip) {
    write_rays(path("e.rays"), RayKind::AnyHit, {});
    const raypack::RayFile r = read_rays(path("e.rays"));
    EXPECT_TRUE(r.rays.empty());
    EXPECT_EQ(r.kind, RayKind::AnyHit);
    write_hits(path("e.hits"), {});
    EXPECT_TRUE(read_hits(path("e.hits")).empty());
}

TEST_F(RayFile, HitsRoundTripBitExact) {
    std::vector<Hitf> hits(3);
    hits[0].t = 2.5f;
    hits[0].prim = 17;
    hits[0].u = 0.25f;
    hits[0].v = 0.125f;
    // hits[1] is a miss: t = +inf, prim = kNoPrim.
    hits[2].t = 1e-20f;
    hits[2].prim = 0xFFFFFFFEu;
    hits[2].u = -0.0f;
    hits[2].v = std::numeric_limits<float>::quiet_NaN();  // unspecified values pass through
    const std::string p = path("h.hits");
    write_hits(p, hits);
    EXPECT_EQ(fs::file_size(p), 16 + 16 * hits.size());
    EXPECT_EQ(slurp(p).substr(0, 8), "HITS0001");
    const std::vector<Hitf> back = read_hits(p);
    ASSERT_EQ(back.size(), hits.size());
    for (std::size_t i = 0; i < hits.size(); ++i) {
        EXPECT_TRUE(same_bits(back[i].t, hits[i].t)) << i;
        EXPECT_EQ(back[i].prim, hits[i].prim) << i;
        EXPECT_TRUE(same_bits(back[i].u, hits[i].u)) << i;
        EXPECT_TRUE(same_bits(back[i].v, hits[i].v)) << i;
    }
    EXPECT_FALSE(back[1].found());
    EXPECT_EQ(back[1].t, std::numeric_limits<float>::infinity());
}

TEST_F(RayFile, BadMagicRejected) {
    write_rays(path("a.rays"), RayKind::ClosestHit, sample_rays());
    std::string bytes = slurp(path("a.rays"));
    bytes[7] = '3';  // RAYS0003: no such version (RAYS0002 is the timed one)
    spit(path("b.rays"), bytes);
    expect_error([&] { read_rays(path("b.rays")); }, path("b.rays"), "bad magic");
    // A hits file is not a rays file and vice versa.
    write_hits(path("a.hits"), std::vector<Hitf>(4));
    expect_error([&] { read_rays(path("a.hits")); }, path("a.hits"), "bad magic");
    expect_error([&] { read_hits(path("a.rays")); }, path("a.rays"), "bad magic");
    // Shorter than the magic, and empty.
    spit(path("c.rays"), "RAY");
    expect_error([&] { read_rays(path("c.rays")); }, path("c.rays"), "bad magic");
    spit(path("d.hits"), "");
    expect_error([&] { read_hits(path("d.hits")); }, path("d.hits"), "bad magic");
    expect_error([&] { read_rays(path("missing.rays")); }, path("missing.rays"), "cannot open");
}

TEST_F(RayFile, TruncatedFilesRejected) {
    const std::vector<Rayf> rays = sample_rays();
    write_rays(path("a.rays"), RayKind::ClosestHit, rays);
    const std::string bytes = slurp(path("a.rays"));
    // Cut inside the last record, inside the first, and inside the header.
    for (std::size_t keep : {bytes.size() - 4, std::size_t(24 + 16), std::size_t(12)}) {
        SCOPED_TRACE(keep);
        spit(path("t.rays"), bytes.substr(0, keep));
        expect_error([&] { read_rays(path("t.rays")); }, path("t.rays"), "truncated");
    }
    // A count so large that count * 32 would overflow must not allocate.
    std::string huge = bytes;
    const std::uint64_t absurd = std::numeric_limits<std::uint64_t>::max() / 8;
    std::memcpy(huge.data() + 8, &absurd, 8);
    spit(path("h.rays"), huge);
    expect_error([&] { read_rays(path("h.rays")); }, path("h.rays"), "truncated");
    // Trailing bytes after the last record are not silently ignored either.
    spit(path("x.rays"), bytes + "junk");
    EXPECT_THROW(read_rays(path("x.rays")), std::runtime_error);

    write_hits(path("a.hits"), std::vector<Hitf>(5));
    const std::string hbytes = slurp(path("a.hits"));
    spit(path("t.hits"), hbytes.substr(0, hbytes.size() - 1));
    expect_error([&] { read_hits(path("t.hits")); }, path("t.hits"), "truncated");
}

TEST_F(RayFile, NonFiniteRayRejected) {
    const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
    struct Case {
        const char* what;
        void (*spoil)(Rayf&, float, float);
    };
    const Case cases[] = {
        {"nan origin", [](Rayf& r, float n, float) { r.org.y = n; }},
        {"inf origin", [](Rayf& r, float, float i) { r.org.x = -i; }},
        {"nan direction", [](Rayf& r, float n, float) { r.dir.z = n; }},
        {"inf direction", [](Rayf& r, float, float i) { r.dir.x = i; }},
        {"nan tnear", [](Rayf& r, float n, float) { r.tnear = n; }},
        {"nan tfar", [](Rayf& r, float n, float) { r.tfar = n; }},
    };
    for (const Case& c : cases) {
        SCOPED_TRACE(c.what);
        std::vector<Rayf> rays = sample_rays();
        c.spoil(rays[5], nan, inf);
        write_rays(path("n.rays"), RayKind::ClosestHit, rays);
        expect_error([&] { read_rays(path("n.rays")); }, path("n.rays"), "ray 5 ");
    }
    // Infinite interval ends are legitimate.
    std::vector<Rayf> rays = sample_rays();
    rays[5].tnear = -inf;
    rays[5].tfar = inf;
    write_rays(path("ok.rays"), RayKind::AnyHit, rays);
    EXPECT_EQ(read_rays(path("ok.rays")).rays.size(), rays.size());
}

// The fuzz targets read bytes in memory (fuzz/rays_fuzzer.cpp): the same
// answers and the same errors as the file readers, naming the given name.
TEST_F(RayFile, BytesInMemoryReadAsTheFile) {
    const std::vector<Rayf> rays = sample_rays();
    write_rays(path("m.rays"), RayKind::AnyHit, rays);
    const std::string bytes = slurp(path("m.rays"));
    const raypack::RayFile from_file = read_rays(path("m.rays"));
    const raypack::RayFile from_bytes = raypack::parse_rays(bytes, "memory.rays");
    EXPECT_EQ(from_bytes.kind, RayKind::AnyHit);
    ASSERT_EQ(from_bytes.rays.size(), from_file.rays.size());
    for (std::size_t i = 0; i < rays.size(); ++i) {
        EXPECT_TRUE(same_bits(from_bytes.rays[i].org.x, from_file.rays[i].org.x)) << i;
        EXPECT_TRUE(same_bits(from_bytes.rays[i].dir.z, from_file.rays[i].dir.z)) << i;
        EXPECT_TRUE(same_bits(from_bytes.rays[i].tfar, from_file.rays[i].tfar)) << i;
    }
    expect_error([&] { raypack::parse_rays(bytes.substr(0, bytes.size() - 1), "memory.rays"); }, "memory.rays",
                 "truncated");
    expect_error([&] { raypack::parse_rays(bytes.substr(0, 5), "memory.rays"); }, "memory.rays", "bad magic");
    expect_error([&] { raypack::parse_hits(bytes, "memory.hits"); }, "memory.hits", "bad magic");

    std::vector<Hitf> hits(3);
    hits[1] = Hitf{2.5f, 7, 0.25f, 0.5f};
    write_hits(path("m.hits"), hits);
    const std::vector<Hitf> back = raypack::parse_hits(slurp(path("m.hits")), "memory.hits");
    ASSERT_EQ(back.size(), 3u);
    EXPECT_EQ(back[1].prim, 7u);
    EXPECT_EQ(back[1].v, 0.5f);
    EXPECT_FALSE(back[0].found());
}

TEST_F(RayFile, UnknownKindRejected) {
    write_rays(path("a.rays"), RayKind::AnyHit, sample_rays());
    std::string bytes = slurp(path("a.rays"));
    for (std::uint32_t kind : {2u, 0x80000000u}) {
        std::memcpy(bytes.data() + 16, &kind, 4);
        spit(path("k.rays"), bytes);
        expect_error([&] { read_rays(path("k.rays")); }, path("k.rays"), "kind");
    }
}

TEST_F(RayFile, FailedWriteLeavesExistingFileUntouched) {
    // An existing, valid file...
    const std::string p = path("keep.rays");
    const std::vector<Rayf> small(2, sample_rays()[0]);
    write_rays(p, RayKind::AnyHit, small);
    const std::string before = slurp(p);
    const auto before_time = fs::last_write_time(p);

    // ... then a write that fails half way: the file size limit makes write(2)
    // fail with EFBIG once 4 KiB are written (SIGXFSZ ignored so that the
    // process survives), long before the 3.2 MB of rays are out.
    rlimit old{};
    ASSERT_EQ(getrlimit(RLIMIT_FSIZE, &old), 0);
    const auto old_handler = std::signal(SIGXFSZ, SIG_IGN);
    rlimit lim = old;
    lim.rlim_cur = 4096;
    ASSERT_EQ(setrlimit(RLIMIT_FSIZE, &lim), 0);
    const std::vector<Rayf> big(100000, sample_rays()[1]);
    bool threw = false;
    try {
        write_rays(p, RayKind::ClosestHit, big);
    } catch (const std::runtime_error&) {
        threw = true;
    }
    bool threw_hits = false;
    try {
        write_hits(path("keep.rays"), std::vector<Hitf>(100000));
    } catch (const std::runtime_error&) {
        threw_hits = true;
    }
    setrlimit(RLIMIT_FSIZE, &old);
    std::signal(SIGXFSZ, old_handler);

    EXPECT_TRUE(threw);
    EXPECT_TRUE(threw_hits);
    EXPECT_EQ(slurp(p), before);
    EXPECT_EQ(fs::last_write_time(p), before_time);
    EXPECT_EQ(read_rays(p).rays.size(), 2u);
    // No temporary left behind.
    std::size_t entries = 0;
    for (const auto& e : fs::directory_iterator(dir_)) {
        ++entries;
        EXPECT_EQ(e.path().filename(), "keep.rays");
    }
    EXPECT_EQ(entries, 1u);

    // A target that cannot be replaced (a non-empty directory) is reported, too.
    fs::create_directories(dir_ / "adir" / "inner");
    EXPECT_THROW(write_rays(path("adir"), RayKind::ClosestHit, small), std::runtime_error);
    EXPECT_TRUE(fs::is_directory(dir_ / "adir" / "inner"));
}

}  // namespace
