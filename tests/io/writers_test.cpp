#include "atlas/io/writers.h"

#include "atlas/io/exr.h"
#include "atlas/io/image.h"
#include "atlas/io/tga_slices.h"
#include "atlas/io/vdb.h"

#include "io_test_util.h"

#include <algorithm>
#include <set>

using namespace atlas;
using namespace atlas::io;
using namespace atlas::io::test;

namespace {
Field3DPtr volume(int nx = 4, int ny = 3, int nz = 5) {
    return std::make_shared<Field3D>(make_field3d({{nx, ny, nz}}, Box3d{{{0, 0, 0}}, {{double(nx), double(ny), double(nz)}}}, {"d", "t", "u"},
                                                  [](int x, int y, int z, int c) { return unit_float(31, x, y, z, c); }));
}
Field2DPtr image2d() {
    return std::make_shared<Field2D>(make_field2d({{4, 3}}, Box2d{{{0, 0}}, {{4, 3}}}, {"r", "g"},
                                                  [](int x, int y, int z, int c) { return unit_float(32, x, y, z, c); }));
}
const OutputFormat* find_format(const std::string& name) {
    for (const auto& f : output_formats())
        if (f.name == name) return &f;
    return nullptr;
}
} // namespace

TEST(Writers, TableListsTheFormatsWithDocsAndOptions) {
    std::vector<std::string> names;
    for (const auto& f : output_formats()) {
        names.push_back(f.name);
        EXPECT_FALSE(f.doc.empty()) << f.name;
        EXPECT_FALSE(f.accepts.empty()) << f.name;
        std::set<std::string> opts;
        for (const auto& [o, doc] : f.options) {
            EXPECT_FALSE(doc.empty()) << f.name << "." << o;
            EXPECT_TRUE(opts.insert(o).second) << "duplicate option " << o;
        }
    }
    for (const char* n : {"exr", "png", "tga", "vdb", "tga-slices"}) EXPECT_NE(std::find(names.begin(), names.end(), n), names.end()) << n;
    EXPECT_EQ(std::set<std::string>(names.begin(), names.end()).size(), names.size());
}

TEST(Writers, FormatFromExtension) {
    EXPECT_EQ(output_format_for_path("a/b.exr"), "exr");
    EXPECT_EQ(output_format_for_path("b.PNG"), "png");
    EXPECT_EQ(output_format_for_path("b.tga"), "tga");
    EXPECT_EQ(output_format_for_path("b.vdb"), "vdb");
    expect_error_containing([] { output_format_for_path("b.jpeg"); }, {".jpeg", ".exr", ".png", ".tga", ".vdb"});
    expect_error_containing([] { output_format_for_path("noext"); }, {"noext", ".exr"});
}

TEST(Writers, EveryFormatWritesWhatItAccepts) {
    TempDir dir;
    auto v = write_value(volume(), dir / "v.exr", "exr", {});
    EXPECT_EQ(v, (std::vector<fs::path>{dir / "v.exr"}));
    EXPECT_EQ(*std::get<Field3DPtr>(read_exr(dir / "v.exr")), *volume());
    write_value(image2d(), dir / "i.exr", "exr", {{"half", "true"}});
    EXPECT_EQ(std::get<Field2DPtr>(read_exr(dir / "i.exr"))->resolution(), image2d()->resolution());
    EXPECT_EQ(write_value(volume(), dir / "v.vdb", "vdb", {}).size(), 1u);
    EXPECT_EQ(read_vdb(dir / "v.vdb"), *volume());
    EXPECT_EQ(write_value(image2d(), dir / "i.png", "png", {{"bits", "16"}}).size(), 1u);
    EXPECT_EQ(read_image(dir / "i.png").channels(), 2);
    EXPECT_EQ(write_value(image2d(), dir / "i.tga", "tga", {{"channels", "g"}}).size(), 1u);
    fs::create_directories(dir / "sub");
    auto slices = write_value(volume(), dir / "sub" / "stack", "tga-slices", {});
    ASSERT_EQ(slices.size(), 5u);
    EXPECT_EQ(slices[0], dir / "sub" / "stack.001.tga");
    EXPECT_EQ(slices[4], dir / "sub" / "stack.005.tga");
    for (const auto& p : slices) EXPECT_TRUE(fs::exists(p));
}

TEST(Writers, VolumeToImageWritesTheMiddleSliceOrTheChosenOne) {
    TempDir dir;
    auto f = volume(4, 3, 5);
    write_value(f, dir / "mid.png", "png", {{"channels", "d"}});
    write_value(f, dir / "s1.png", "png", {{"slice", "1"}, {"channels", "d"}});
    Field2D mid = read_image(dir / "mid.png"), s1 = read_image(dir / "s1.png");
    ASSERT_EQ(mid.resolution(), (Vec2i{{4, 3}}));
    for (int y = 0; y < 3; ++y)
        for (int x = 0; x < 4; ++x) {
            EXPECT_NEAR(mid.at(0, x, y), f->at(0, x, y, 2), 0.5f / 255.0f + 1e-6f);
            EXPECT_NEAR(s1.at(0, x, y), f->at(0, x, y, 1), 0.5f / 255.0f + 1e-6f);
        }
    expect_error_containing([&] { write_value(f, dir / "x.png", "png", {{"slice", "5"}}); }, {"x.png", "slice", "5"});
    expect_error_containing([&] { write_value(f, dir / "x.png", "png", {{"slice", "-1"}}); }, {"x.png", "slice"});
}

TEST(Writers, MontageTilesAllSlices) {
    TempDir dir;
    auto f = volume(4, 3, 5); // 5 slices -> 3 columns x 2 rows
    write_value(f, dir / "m.png", "png", {{"montage", "1"}, {"channels", "t"}, {"bits", "16"}});
    Field2D m = read_image(dir / "m.png");
    ASSERT_EQ(m.resolution(), (Vec2i{{12, 6}}));
    // Slice z sits in column z % 3, row z / 3 counted from the top of the picture.
    for (int z = 0; z < 5; ++z) {
        const int ox = (z % 3) * 4, oy = (1 - z / 3) * 3;
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 4; ++x) EXPECT_NEAR(m.at(0, ox + x, oy + y), f->at(1, x, y, z), 0.5f / 65535.0f + 1e-6f);
    }
    // The unused tile is zero.
    EXPECT_EQ(m.at(0, 8, 0), 0.0f);
    expect_error_containing([&] { write_value(f, dir / "x.png", "png", {{"montage", "1"}, {"slice", "2"}}); }, {"x.png", "montage", "slice"});
}

TEST(Writers, ChannelsSelectAndReorder) {
    TempDir dir;
    auto f = volume();
    write_value(f, dir / "c.exr", "exr", {{"channels", "u, d"}});
    const Field3DPtr g_ptr = std::get<Field3DPtr>(read_exr(dir / "c.exr"));
    const Field3D& g = *g_ptr;
    ASSERT_EQ(g.channel_names(), (std::vector<std::string>{"u", "d"}));
    for (size_t i = 0; i < g.voxel_count(); ++i) {
        EXPECT_EQ(g.channel(0)[i], f->channel(2)[i]);
        EXPECT_EQ(g.channel(1)[i], f->channel(0)[i]);
    }
    expect_error_containing([&] { write_value(f, dir / "c.exr", "exr", {{"channels", "d,nope"}}); }, {"c.exr", "'nope'", "d, t, u"});
}

TEST(Writers, RangeBitsToleranceVector3) {
    TempDir dir;
    auto f = volume();
    write_value(f, dir / "r.png", "png", {{"range", "0,2"}, {"channels", "d"}, {"slice", "0"}});
    Field2D r = read_image(dir / "r.png");
    for (int y = 0; y < f->ny(); ++y)
        for (int x = 0; x < f->nx(); ++x) EXPECT_NEAR(2.0f * r.at(0, x, y), f->at(0, x, y, 0), 1.0f / 255.0f + 1e-6f);
    write_value(f, dir / "t.vdb", "vdb", {{"tolerance", "0.5"}});
    Field3D t = read_vdb(dir / "t.vdb");
    for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < t.voxel_count(); ++i) EXPECT_EQ(t.channel(c)[i], f->channel(c)[i] > 0.5f ? f->channel(c)[i] : 0.0f);
    write_value(f, dir / "v.vdb", "vdb", {{"vector3", "true"}});
    EXPECT_EQ(list_vdb_grids(dir / "v.vdb").size(), 1u);
    EXPECT_EQ(read_vdb(dir / "v.vdb").channels(), 3);
}

TEST(Writers, UnknownOptionNamesTheOutputAndTheKnownOnes) {
    TempDir dir;
    expect_error_containing([&] { write_value(image2d(), dir / "x.png", "png", {{"bitz", "8"}}); },
                            {"output 'x.png': unknown option 'bitz' (known: bits, range, slice, montage, channels)"});
    expect_error_containing([&] { write_value(volume(), dir / "x.vdb", "vdb", {{"half", "1"}}); }, {"x.vdb", "'half'", "tolerance"});
    EXPECT_FALSE(fs::exists(dir / "x.png"));
}

TEST(Writers, BadOptionValuesNameOptionAndExpectation) {
    TempDir dir;
    auto img = image2d();
    auto vol = volume();
    const std::vector<std::tuple<Value, std::string, OutputOptions, std::string>> cases = {
        {img, "png", {{"bits", "12"}}, "bits"},
        {img, "png", {{"bits", "8x"}}, "bits"},
        {img, "tga", {{"bits", "16"}}, "bits"},
        {img, "png", {{"range", "1"}}, "range"},
        {img, "png", {{"range", "1,0"}}, "range"},
        {img, "png", {{"range", "0,1,2"}}, "range"},
        {img, "png", {{"range", "a,b"}}, "range"},
        {img, "png", {{"range", "0,inf"}}, "range"},
        {vol, "png", {{"montage", "maybe"}}, "montage"},
        {img, "png", {{"slice", "0"}}, "slice"},
        {img, "exr", {{"half", "2"}}, "half"},
        {vol, "vdb", {{"tolerance", "-1"}}, "tolerance"},
        {vol, "vdb", {{"tolerance", "nan"}}, "tolerance"},
        {vol, "vdb", {{"vector3", "yes please"}}, "vector3"},
        {img, "png", {{"channels", ""}}, "channels"},
        {img, "png", {{"channels", "r,g,r,g,r"}}, "channels"},
    };
    for (const auto& [value, format, opts, name] : cases) {
        const fs::path p = dir / ("out." + format);
        SCOPED_TRACE(format + " " + opts.begin()->first + "=" + opts.begin()->second);
        // The lambda captures plain references: clang 14 cannot capture structured bindings.
        const Value& v = value;
        const std::string& f = format;
        const OutputOptions& o = opts;
        expect_error_containing([&] { write_value(v, p, f, o); }, {"output 'out." + format + "'", "'" + name + "'"});
    }
}

TEST(Writers, WrongValueKindNamesFormatAndWhatItAccepts) {
    TempDir dir;
    expect_error_containing([&] { write_value(image2d(), dir / "x.vdb", "vdb", {}); }, {"x.vdb", "vdb", "field2d", "field3d"});
    expect_error_containing([&] { write_value(image2d(), dir / "x", "tga-slices", {}); }, {"tga-slices", "field2d", "field3d"});
    expect_error_containing([&] { write_value(MeshPtr(std::make_shared<Mesh>()), dir / "x.exr", "exr", {}); }, {"x.exr", "exr", "mesh"});
    expect_error_containing([&] { write_value(Value{}, dir / "x.exr", "exr", {}); }, {"x.exr", "empty"});
    expect_error_containing([&] { write_value(image2d(), dir / "x.exr", "jpeg", {}); }, {"x.exr", "'jpeg'", "exr", "tga-slices"});
    // tga-slices takes DIR/STEM, not a file name.
    expect_error_containing([&] { write_value(volume(), dir / "x.tga", "tga-slices", {}); }, {"x.tga", "DIR/STEM"});
    EXPECT_FALSE(fs::exists(dir / "x.tga.001.tga"));
}

TEST(Writers, OptionMessagesAreReadable) {
    TempDir dir;
    try {
        write_value(volume(), dir / "x.vdb", "vdb", {{"tolerance", "-0.5"}});
        ADD_FAILURE() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "output 'x.vdb': option 'tolerance': expected a finite number >= 0, got '-0.5'");
    }
    try {
        write_value(image2d(), dir / "x.png", "png", {{"bits", "12"}});
        ADD_FAILURE() << "expected an error";
    } catch (const Error& e) {
        EXPECT_EQ(std::string(e.what()), "output 'x.png': option 'bits': expected 8 or 16, got '12'");
    }
}

TEST(Writers, FormatForPathAgreesWithTheTable) {
    for (const auto& f : output_formats())
        for (const auto& ext : f.extensions) EXPECT_EQ(output_format_for_path("file" + ext), f.name);
    ASSERT_NE(find_format("tga-slices"), nullptr);
    EXPECT_TRUE(find_format("tga-slices")->extensions.empty());
}
