// Readers on bad input: missing, empty, random, truncated and mislabelled
// files must throw atlas::Error naming the file - never crash.
#include "atlas/io/exr.h"
#include "atlas/io/image.h"
#include "atlas/io/tga_slices.h"
#include "atlas/io/vdb.h"

#include "io_test_util.h"

#include <functional>

using namespace atlas;
using namespace atlas::io;
using namespace atlas::io::test;

namespace {

using Reader = std::function<void(const fs::path&)>;

struct Format {
    std::string ext;
    std::function<void(const fs::path&)> write_valid;
    Reader read;
    // Listing VDB grid names reads only the grid descriptors, so a file cut
    // inside the last grid's voxel data may still list: no crash is required.
    bool must_fail_when_truncated = true;
    // KNOWN LIMITATION: a VDB whose metadata string lengths are corrupted makes
    // OpenVDB itself allocate up to gigabytes and take minutes before it fails
    // (seen with single-byte changes near offset 400). It does fail with an
    // error, but that is too slow and too large for a unit test, so VDB is
    // left out of the mutation test until Atlas pre-validates VDB headers.
    bool mutation_test = true;
};

std::vector<Format> formats() {
    auto f3 = std::make_shared<Field3D>(make_field3d({{16, 12, 6}}, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {"a", "b"},
                                                     [](int x, int y, int z, int c) { return unit_float(41, x, y, z, c); }));
    auto f2 = std::make_shared<Field2D>(make_field2d({{32, 24}}, Box2d{{{0, 0}}, {{1, 1}}}, {"r", "g", "b", "a"},
                                                     [](int x, int y, int z, int c) { return unit_float(42, x, y, z, c); }));
    return {
        {".exr", [=](const fs::path& p) { write_exr(*f3, p); }, [](const fs::path& p) { read_exr(p); }},
        {".png", [=](const fs::path& p) { write_image(*f2, p); }, [](const fs::path& p) { read_image(p); }},
        {".tga", [=](const fs::path& p) { write_image(*f2, p); }, [](const fs::path& p) { read_image(p); }},
        {".vdb", [=](const fs::path& p) { write_vdb(*f3, p); }, [](const fs::path& p) { read_vdb(p); }, true, false},
        {".vdb", [=](const fs::path& p) { write_vdb(*f3, p); }, [](const fs::path& p) { list_vdb_grids(p); }, false, false},
    };
}

std::string random_bytes(uint32_t seed, size_t n) {
    std::string s(n, '\0');
    for (size_t i = 0; i < n; ++i) s[i] = char(hash_coords(seed, int(i)) & 0xff);
    return s;
}

} // namespace

TEST(BadInput, MissingFileNamesTheFile) {
    TempDir dir;
    for (const auto& f : formats()) {
        const fs::path p = dir / ("missing" + f.ext);
        expect_error_containing([&] { f.read(p); }, {p.string(), "no such file"});
    }
    expect_error_containing([&] { read_tga_slices(dir / "missing.001.tga", Box3d{{{0, 0, 0}}, {{1, 1, 1}}}); }, {"missing.001.tga"});
}

TEST(BadInput, EmptyAndRandomFilesAreErrors) {
    TempDir dir;
    int n = 0;
    for (const auto& f : formats()) {
        for (size_t size : {size_t(0), size_t(1), size_t(7), size_t(64), size_t(4096)}) {
            const fs::path p = dir / ("junk" + std::to_string(n++) + f.ext);
            write_bytes(p, random_bytes(uint32_t(n), size));
            expect_error_containing([&] { f.read(p); }, {p.filename().string()});
        }
    }
}

// Valid magic number, garbage after it.
TEST(BadInput, ValidHeaderFollowedByGarbage) {
    TempDir dir;
    int n = 0;
    for (const auto& f : formats()) {
        const fs::path good = dir / ("good" + std::to_string(n) + f.ext);
        f.write_valid(good);
        std::string bytes = read_bytes(good);
        for (size_t keep : {size_t(4), size_t(16), size_t(40)}) {
            if (keep >= bytes.size()) continue;
            const fs::path p = dir / ("hdr" + std::to_string(n++) + f.ext);
            write_bytes(p, bytes.substr(0, keep) + random_bytes(uint32_t(n + 100), bytes.size() - keep));
            // Garbage may still decode to *something* for a few formats; what matters
            // is no crash and, on failure, a message that names the file.
            try {
                f.read(p);
            } catch (const Error& e) {
                EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos) << e.what();
            }
        }
    }
}

TEST(BadInput, TruncatedFilesAreErrors) {
    TempDir dir;
    int n = 0;
    for (const auto& f : formats()) {
        const fs::path good = dir / ("good" + std::to_string(n) + f.ext);
        f.write_valid(good);
        ASSERT_NO_THROW(f.read(good)) << good;
        const std::string bytes = read_bytes(good);
        // Strictly shorter than the pixel data needs: must fail.
        for (double frac : {0.1, 0.5, 0.8}) {
            const fs::path p = dir / ("cut" + std::to_string(n++) + f.ext);
            write_bytes(p, bytes.substr(0, size_t(double(bytes.size()) * frac)));
            SCOPED_TRACE(p.filename().string() + " truncated to " + std::to_string(frac));
            if (f.must_fail_when_truncated) {
                expect_error_containing([&] { f.read(p); }, {p.filename().string()});
            } else {
                try {
                    f.read(p);
                } catch (const Error& e) {
                    EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos) << e.what();
                }
            }
        }
    }
}

// Valid files with a few bytes changed (deterministic positions and values):
// any outcome but a crash or a foreign exception type is acceptable; errors
// name the file.
TEST(BadInput, MutatedFilesNeverCrash) {
    TempDir dir;
    int n = 0;
    for (const auto& f : formats()) {
        if (!f.mutation_test) continue;
        const fs::path good = dir / ("good" + std::to_string(n) + f.ext);
        f.write_valid(good);
        const std::string bytes = read_bytes(good);
        for (uint32_t m = 0; m < 40; ++m) {
            std::string b = bytes;
            const int flips = 1 + int(hash_coords(77, n, int(m)) % 4);
            for (int k = 0; k < flips; ++k) {
                const uint32_t h = hash_coords(78, n, int(m), k);
                // Half the mutations hit the first 512 bytes, where the headers are.
                const size_t span = (h & 1) ? std::min<size_t>(512, b.size()) : b.size();
                b[size_t(h >> 8) % span] = char(hash_coords(79, n, int(m), k) & 0xff);
            }
            const fs::path p = dir / ("mut" + std::to_string(n) + "_" + std::to_string(m) + f.ext);
            write_bytes(p, b);
            try {
                f.read(p);
            } catch (const Error& e) {
                EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos) << e.what();
            }
        }
        ++n;
    }
}

TEST(BadInput, WrongFormatBehindTheExtension) {
    TempDir dir;
    Field2D f({{4, 4}}, 1, Box2d{{{0, 0}}, {{1, 1}}});
    write_image(f, dir / "real.png");
    fs::copy_file(dir / "real.png", dir / "fake.exr");
    fs::copy_file(dir / "real.png", dir / "fake.vdb");
    expect_error_containing([&] { read_exr(dir / "fake.exr"); }, {"fake.exr", "EXR"});
    expect_error_containing([&] { read_vdb(dir / "fake.vdb"); }, {"fake.vdb", "VDB"});
    // A directory is not a file.
    fs::create_directories(dir / "adir.exr");
    expect_error_containing([&] { read_exr(dir / "adir.exr"); }, {"adir.exr"});
    fs::create_directories(dir / "adir.png");
    expect_error_containing([&] { read_image(dir / "adir.png"); }, {"adir.png"});
}

TEST(BadInput, ImageWithTooManyChannelsForSlicesIsNamed) {
    TempDir dir;
    // A 2x2 RGBA slice stack where one slice is a 1-channel image: still read
    // (missing channels fill), but a different size is an error naming it.
    Field2D one({{2, 2}}, 1, Box2d{{{0, 0}}, {{1, 1}}});
    Field2D big({{4, 2}}, 1, Box2d{{{0, 0}}, {{1, 1}}});
    write_image(one, dir / "s.001.tga");
    write_image(big, dir / "s.002.tga");
    expect_error_containing([&] { read_tga_slices(dir / "s.001.tga", Box3d{{{0, 0, 0}}, {{1, 1, 1}}}); }, {"s.002.tga", "4x2"});
}

namespace {
// A small EXR whose header claims `height` rows of one float channel: only the
// header and a few bytes, nowhere near the line-offset table it implies.
std::string exr_claiming(int32_t height) {
    std::string b;
    auto i32 = [&](int32_t v) { b.append(reinterpret_cast<const char*>(&v), 4); };
    auto f32 = [&](float v) { b.append(reinterpret_cast<const char*>(&v), 4); };
    auto attr = [&](const char* name, const char* type, int32_t size) {
        b += name;
        b += '\0';
        b += type;
        b += '\0';
        i32(size);
    };
    i32(20000630);
    i32(2);
    attr("channels", "chlist", 18 + 1);
    b += "R";
    b += '\0';
    i32(2); // FLOAT
    b += std::string(4, '\0'); // pLinear, reserved
    i32(1);
    i32(1);
    b += '\0';
    attr("compression", "compression", 1);
    b += '\0';
    attr("dataWindow", "box2i", 16);
    i32(0), i32(0), i32(0), i32(height - 1);
    attr("displayWindow", "box2i", 16);
    i32(0), i32(0), i32(0), i32(height - 1);
    attr("lineOrder", "lineOrder", 1);
    b += '\0';
    attr("pixelAspectRatio", "float", 4);
    f32(1);
    attr("screenWindowCenter", "v2f", 8);
    f32(0), f32(0);
    attr("screenWindowWidth", "float", 4);
    f32(1);
    b += '\0';
    b += std::string(16, '\0'); // the start of an offset table
    return b;
}
} // namespace

// Issue 48: a 274-byte EXR made every read allocate about 2 GB whatever the
// budget (OpenEXR sizes its offset table by the header's claim). The claim is
// now held against the file's size before OpenEXR sees the file.
TEST(BadInput, ExrHeaderClaimingMoreThanTheFileHoldsIsRefusedBeforeAllocating) {
    TempDir dir;
    const fs::path p = dir / "claims.exr";
    const std::string bytes = exr_claiming(1 << 28);
    { std::ofstream(p, std::ios::binary) << bytes; }
    const MemoryBudget budget(64ull << 20);
    try {
        read_exr(p, &budget);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("larger than the file"), std::string::npos) << e.what();
        EXPECT_NE(std::string(e.what()).find(p.string()), std::string::npos) << e.what();
    }
    // The same header with a claim the file can hold passes the check and
    // reaches OpenEXR (which reconstructs the one missing line).
    { std::ofstream(p, std::ios::binary | std::ios::trunc) << exr_claiming(1); }
    try {
        read_exr(p, &budget);
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()).find("larger than the file"), std::string::npos) << e.what();
    }
    // An opaque attribute claiming 2 GB in a tiny file.
    std::string opaque = bytes.substr(0, 8) + std::string("junk\0mytype\0", 12);
    const int32_t huge = 0x7fff0000;
    opaque.append(reinterpret_cast<const char*>(&huge), 4);
    { std::ofstream(p, std::ios::binary | std::ios::trunc) << opaque << std::string(64, 'x'); }
    try {
        read_exr(p, &budget);
        FAIL();
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("more than the file holds"), std::string::npos) << e.what();
    }
}
