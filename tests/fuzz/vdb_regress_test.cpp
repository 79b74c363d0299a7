// The VDB reader's own check of everything OpenVDB parses (issue 17 items 5/7):
// the fuzzer's crash inputs are refused with a clear error, every truncation
// and every single-byte corruption of real files either reads or is refused
// (never a crash: run under ASan+UBSan in CI), and files OpenVDB writes with
// every compression, half floats and vec3s grids still read, value for value
// against OpenVDB's own reader.
#include "atlas/core/error.h"
#include "atlas/io/vdb.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace atlas;

namespace {

struct Scratch {
    fs::path dir = fs::temp_directory_path() / ("atlas_vdb_regress_" + std::to_string(::getpid()));
    Scratch() { fs::create_directories(dir); }
    ~Scratch() {
        std::error_code ec;
        fs::remove_all(dir, ec);
    }
};

std::string slurp(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), {}};
}
void spill(const fs::path& p, const std::string& bytes) {
    std::ofstream out(p, std::ios::binary | std::ios::trunc);
    out.write(bytes.data(), std::streamsize(bytes.size()));
}

// A small grid with leaves, a tile, inactive values and two distinct inactive
// values (so mask compression writes selection masks).
openvdb::FloatGrid::Ptr sample_grid(const std::string& name) {
    auto g = openvdb::FloatGrid::create(0.25f);
    g->setName(name);
    auto acc = g->getAccessor();
    for (int i = 0; i < 40; ++i) acc.setValue(openvdb::Coord(i % 11, (i * 7) % 13, (i * 3) % 9), 0.5f + float(i) * 0.125f);
    acc.setValueOff(openvdb::Coord(2, 2, 2), -0.25f);
    acc.setValueOff(openvdb::Coord(3, 2, 2), 7.0f);
    g->tree().addTile(1, openvdb::Coord(64, 0, 0), 2.0f, true); // a level-1 tile of 8^3 voxels
    g->setTransform(openvdb::math::Transform::createLinearTransform(0.5));
    return g;
}

void write_file(const fs::path& p, const openvdb::GridPtrVec& grids, uint32_t compression) {
    openvdb::io::File f(p.string());
    f.setCompression(compression);
    f.write(grids);
    f.close();
}

// Reads and checks that only atlas::Error leaves.
void read_or_refuse(const fs::path& p) {
    try {
        io::read_vdb(p);
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find(p.filename().string()), std::string::npos) << e.what();
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not an atlas::Error: " << e.what();
    }
}

} // namespace

TEST(VdbRegress, FuzzerInputsAreRefusedByName) {
    int n = 0;
    for (const auto& e : fs::directory_iterator(fs::path(ATLAS_SOURCE_DIR) / "tests/fuzz/corpus/vdb_fuzz")) {
        if (e.path().filename().string().rfind("regress", 0) != 0) continue;
        ++n;
        try {
            io::read_vdb(e.path());
            ADD_FAILURE() << e.path() << " was read";
        } catch (const Error& err) {
            const std::string m = err.what();
            EXPECT_NE(m.find(e.path().string()), std::string::npos) << m;
            EXPECT_NE(m.find("VDB"), std::string::npos) << m;
        }
    }
    EXPECT_GE(n, 4);
}

TEST(VdbRegress, OpenVdbFilesOfEveryCompressionReadLikeOpenVdbReadsThem) {
    openvdb::initialize();
    Scratch s;
    const uint32_t modes[] = {openvdb::io::COMPRESS_NONE, openvdb::io::COMPRESS_ZIP, openvdb::io::COMPRESS_BLOSC,
                              openvdb::io::COMPRESS_ACTIVE_MASK, openvdb::io::COMPRESS_ACTIVE_MASK | openvdb::io::COMPRESS_ZIP,
                              openvdb::io::COMPRESS_ACTIVE_MASK | openvdb::io::COMPRESS_BLOSC};
    for (bool half : {false, true})
        for (uint32_t mode : modes) {
            SCOPED_TRACE("compression " + std::to_string(mode) + (half ? " half" : ""));
            auto a = sample_grid("a");
            a->setSaveFloatAsHalf(half);
            auto v = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
            v->setName("v");
            v->setTransform(a->transform().copy());
            v->getAccessor().setValue(openvdb::Coord(1, 2, 3), openvdb::Vec3s(1, -2, 3));
            v->setSaveFloatAsHalf(half);
            const fs::path p = s.dir / "mode.vdb";
            write_file(p, {a, v}, mode);
            const Field3D f = io::read_vdb(p);
            // OpenVDB's own reader is the reference.
            openvdb::io::File file(p.string());
            file.open(false);
            auto ra = openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("a"));
            auto rv = openvdb::gridPtrCast<openvdb::Vec3SGrid>(file.readGrid("v"));
            file.close();
            ASSERT_TRUE(ra && rv);
            openvdb::CoordBBox box = ra->evalActiveVoxelBoundingBox();
            box.expand(rv->evalActiveVoxelBoundingBox());
            ASSERT_EQ(f.resolution(), (Vec3i{{box.dim().x(), box.dim().y(), box.dim().z()}}));
            ASSERT_EQ(f.channels(), 4);
            for (int z = 0; z < f.nz(); ++z)
                for (int y = 0; y < f.ny(); ++y)
                    for (int x = 0; x < f.nx(); ++x) {
                        const openvdb::Coord c = box.min().offsetBy(x, y, z);
                        ASSERT_EQ(f.at(0, x, y, z), ra->tree().getValue(c));
                        for (int k = 0; k < 3; ++k) ASSERT_EQ(f.at(1 + k, x, y, z), rv->tree().getValue(c)[k]);
                    }
        }
}

TEST(VdbRegress, EveryTruncationAndEveryByteFlipReadsOrIsRefused) {
    openvdb::initialize();
    Scratch s;
    const fs::path good = s.dir / "good.vdb";
    write_file(good, {sample_grid("density")}, openvdb::io::COMPRESS_ACTIVE_MASK | openvdb::io::COMPRESS_BLOSC);
    const std::string bytes = slurp(good);
    ASSERT_GT(bytes.size(), 500u);
    const fs::path bad = s.dir / "bad.vdb";
    for (size_t n = 0; n < bytes.size(); ++n) {
        spill(bad, bytes.substr(0, n));
        EXPECT_THROW(io::read_vdb(bad), Error) << "truncated to " << n << " bytes";
    }
    // Flipping every byte of the grid's data (the tree OpenVDB would parse), one at a time.
    for (size_t i = 0; i < bytes.size(); ++i) {
        std::string b = bytes;
        b[i] = char(~b[i]);
        spill(bad, b);
        read_or_refuse(bad);
    }
}
