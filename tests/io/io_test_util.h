// Helpers shared by the io tests: a fresh temp directory per test and fields
// filled with deterministic, awkward values.
#pragma once

#include "atlas/core/error.h"
#include "atlas/core/field.h"
#include "atlas/core/hash.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <unistd.h>

namespace atlas::io::test {

namespace fs = std::filesystem;

// A directory unique to the running test (and process), emptied on entry and
// removed on exit.
class TempDir {
public:
    TempDir() {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        std::string name = std::string("atlas_io_") + info->test_suite_name() + "_" + info->name() + "_" + std::to_string(::getpid());
        for (auto& ch : name)
            if (ch == '/') ch = '_';
        path_ = fs::temp_directory_path() / name;
        fs::remove_all(path_);
        fs::create_directories(path_);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(path_, ec);
    }
    TempDir(const TempDir&) = delete;
    TempDir& operator=(const TempDir&) = delete;
    const fs::path& path() const { return path_; }
    fs::path operator/(const std::string& name) const { return path_ / name; }

private:
    fs::path path_;
};

// Any float bit pattern that is finite (covers denormals, negatives, huge and
// tiny magnitudes): what a bit-exact format must keep.
inline float awkward_float(uint32_t seed, int x, int y, int z, int c) {
    for (uint32_t k = 0;; ++k) {
        uint32_t bits = hash_coords(seed + k * 7919u, x, y, z, uint32_t(c));
        float v;
        static_assert(sizeof(v) == sizeof(bits));
        std::memcpy(&v, &bits, sizeof(v));
        if (std::isfinite(v)) return v;
    }
}

// Uniform in [lo, hi).
inline float unit_float(uint32_t seed, int x, int y, int z, int c, float lo = 0.0f, float hi = 1.0f) {
    return lo + (hi - lo) * hash_to_unit(hash_coords(seed, x, y, z, uint32_t(c)));
}

template <typename Fn>
Field2D make_field2d(Vec2i res, Box2d b, std::vector<std::string> names, Fn fn) {
    Field2D f(res, int(names.size()), b, names);
    for (int c = 0; c < f.channels(); ++c)
        for (int y = 0; y < f.height(); ++y)
            for (int x = 0; x < f.width(); ++x) f.at(c, x, y) = fn(x, y, 0, c);
    return f;
}

template <typename Fn>
Field3D make_field3d(Vec3i res, Box3d b, std::vector<std::string> names, Fn fn) {
    Field3D f(res, int(names.size()), b, names);
    for (int c = 0; c < f.channels(); ++c)
        for (int z = 0; z < f.nz(); ++z)
            for (int y = 0; y < f.ny(); ++y)
                for (int x = 0; x < f.nx(); ++x) f.at(c, x, y, z) = fn(x, y, z, c);
    return f;
}

inline bool same_bits(float a, float b) {
    uint32_t ua, ub;
    std::memcpy(&ua, &a, 4);
    std::memcpy(&ub, &b, 4);
    return ua == ub;
}

inline void write_bytes(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

inline std::string read_bytes(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

// Expects `fn` to throw an atlas::Error whose message contains every string in `parts`.
template <typename Fn>
void expect_error_containing(Fn&& fn, std::initializer_list<std::string> parts) {
    try {
        fn();
        ADD_FAILURE() << "expected an atlas::Error";
    } catch (const atlas::Error& e) {
        const std::string msg = e.what();
        for (const auto& p : parts) EXPECT_NE(msg.find(p), std::string::npos) << "message '" << msg << "' lacks '" << p << "'";
    } catch (const std::exception& e) {
        ADD_FAILURE() << "expected an atlas::Error, got another exception: " << e.what();
    }
}

} // namespace atlas::io::test
