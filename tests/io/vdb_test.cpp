#include "atlas/io/vdb.h"

#include "io_test_util.h"

#include <openvdb/openvdb.h>

using namespace atlas;
using namespace atlas::io;
using namespace atlas::io::test;

namespace {

openvdb::GridPtrVecPtr read_grids_directly(const fs::path& p) {
    openvdb::initialize();
    openvdb::io::File file(p.string());
    file.open(false);
    auto grids = file.getGrids();
    file.close();
    return grids;
}

void write_grids_directly(const fs::path& p, const openvdb::GridPtrVec& grids) {
    openvdb::initialize();
    openvdb::io::File file(p.string());
    file.write(grids);
    file.close();
}

// A sparse-ish field: zero in most voxels, awkward values elsewhere.
Field3D sparse_field(std::vector<std::string> names, Box3d b, Vec3i res = {{9, 7, 5}}) {
    return make_field3d(res, b, names, [](int x, int y, int z, int c) {
        if (hash_coords(5, x, y, z, uint32_t(c)) % 3 == 0) return 0.0f;
        return awkward_float(6, x, y, z, c);
    });
}

} // namespace

TEST(Vdb, FloatGridsRoundTripExactly) {
    TempDir dir;
    const Box3d b{{{-2048.0, -1000.0, 100.0}}, {{2048.0, 1800.0, 612.0}}}; // non-cubic voxels
    Field3D f = sparse_field({"density", "type"}, b);
    write_vdb(f, dir / "f.vdb");
    EXPECT_EQ(list_vdb_grids(dir / "f.vdb"), (std::vector<std::string>{"density", "type"}));
    Field3D g = read_vdb(dir / "f.vdb");
    EXPECT_EQ(g.resolution(), f.resolution());
    EXPECT_EQ(g.bounds(), f.bounds());
    EXPECT_EQ(g.channel_names(), f.channel_names());
    for (int c = 0; c < f.channels(); ++c)
        for (size_t i = 0; i < f.voxel_count(); ++i) ASSERT_TRUE(same_bits(f.channel(c)[i], g.channel(c)[i])) << c << " " << i;
    // Selecting and reordering grids.
    Field3D t = read_vdb(dir / "f.vdb", {"type"});
    ASSERT_EQ(t.channels(), 1);
    EXPECT_EQ(t.channel_name(0), "type");
    for (size_t i = 0; i < f.voxel_count(); ++i) ASSERT_TRUE(same_bits(f.channel(1)[i], t.channel(0)[i]));
}

// Voxel centres: field voxel (i,j,k) is VDB voxel (i,j,k), and the VDB
// transform maps it to the field's voxel centre. Grid class and bounds metadata.
TEST(Vdb, TransformPutsVoxelCentresWhereTheFieldDoes) {
    TempDir dir;
    const Box3d b{{{-10.0, 4.0, -3.0}}, {{22.0, 10.0, 5.0}}};
    Field3D f = make_field3d({{8, 3, 4}}, b, {"d"}, [](int x, int y, int z, int) { return float(1 + x + 10 * y + 100 * z); });
    write_vdb(f, dir / "t.vdb");
    auto grids = read_grids_directly(dir / "t.vdb");
    ASSERT_EQ(grids->size(), 1u);
    auto g = openvdb::gridPtrCast<openvdb::FloatGrid>((*grids)[0]);
    ASSERT_TRUE(g);
    EXPECT_EQ(g->getGridClass(), openvdb::GRID_FOG_VOLUME);
    EXPECT_EQ(g->background(), 0.0f);
    auto acc = g->getConstAccessor();
    for (int z = 0; z < 4; ++z)
        for (int y = 0; y < 3; ++y)
            for (int x = 0; x < 8; ++x) {
                const Vec3d c = f.voxel_center(x, y, z);
                const openvdb::Vec3d w = g->transform().indexToWorld(openvdb::Vec3d(x, y, z));
                for (int k = 0; k < 3; ++k) EXPECT_NEAR(w[k], c[k], 1e-9);
                EXPECT_EQ(acc.getValue(openvdb::Coord(x, y, z)), f.at(0, x, y, z));
            }
    auto bmin = g->getMetadata<openvdb::Vec3DMetadata>("atlas_bounds_min");
    auto bmax = g->getMetadata<openvdb::Vec3DMetadata>("atlas_bounds_max");
    ASSERT_TRUE(bmin && bmax);
    EXPECT_EQ(bmin->value(), openvdb::Vec3d(-10, 4, -3));
    EXPECT_EQ(bmax->value(), openvdb::Vec3d(22, 10, 5));
}

TEST(Vdb, SparseToleranceIsRespected) {
    TempDir dir;
    const float tol = 0.25f;
    Field3D f = make_field3d({{16, 12, 10}}, Box3d{{{0, 0, 0}}, {{16, 12, 10}}}, {"d"},
                             [](int x, int y, int z, int c) { return unit_float(8, x, y, z, c, -1.0f, 1.0f); });
    VdbOptions o;
    o.tolerance = tol;
    write_vdb(f, dir / "s.vdb", o);
    auto g = openvdb::gridPtrCast<openvdb::FloatGrid>((*read_grids_directly(dir / "s.vdb"))[0]);
    ASSERT_TRUE(g);
    size_t expect_active = 0;
    auto acc = g->getConstAccessor();
    for (int z = 0; z < f.nz(); ++z)
        for (int y = 0; y < f.ny(); ++y)
            for (int x = 0; x < f.nx(); ++x) {
                const float v = f.at(0, x, y, z);
                const bool active = std::fabs(v) > tol;
                expect_active += active;
                EXPECT_EQ(acc.isValueOn(openvdb::Coord(x, y, z)), active) << v;
                if (active) {
                    EXPECT_EQ(acc.getValue(openvdb::Coord(x, y, z)), v);
                }
            }
    EXPECT_EQ(g->activeVoxelCount(), openvdb::Index64(expect_active));
    // Reading back: inactive voxels are the background 0, active ones exact, bounds restored.
    Field3D r = read_vdb(dir / "s.vdb");
    EXPECT_EQ(r.bounds(), f.bounds());
    for (size_t i = 0; i < f.voxel_count(); ++i) {
        const float v = f.channel(0)[i];
        EXPECT_EQ(r.channel(0)[i], std::fabs(v) > tol ? v : 0.0f);
    }
}

TEST(Vdb, EmptyBorderStillRestoresBounds) {
    TempDir dir;
    const Box3d b{{{0, 0, 0}}, {{100, 50, 25}}};
    Field3D f({{10, 10, 10}}, 1, b, {"d"});
    f.at(0, 4, 5, 6) = 2.0f; // one active voxel, far from every edge
    write_vdb(f, dir / "e.vdb");
    Field3D g = read_vdb(dir / "e.vdb");
    EXPECT_EQ(g.resolution(), f.resolution());
    EXPECT_EQ(g.bounds(), b);
    EXPECT_EQ(g.at(0, 4, 5, 6), 2.0f);
    // All zero: still a valid round trip thanks to the metadata.
    Field3D z({{3, 3, 3}}, 1, b, {"d"});
    write_vdb(z, dir / "z.vdb");
    Field3D zr = read_vdb(dir / "z.vdb");
    EXPECT_EQ(zr.bounds(), b);
    EXPECT_EQ(zr.resolution(), z.resolution());
}

TEST(Vdb, Vector3RoundTrip) {
    TempDir dir;
    const Box3d b{{{-1, -2, -3}}, {{1, 2, 3}}};
    Field3D f = sparse_field({"vel.x", "vel.y", "vel.z"}, b, {{5, 6, 7}});
    VdbOptions o;
    o.vector3 = true;
    write_vdb(f, dir / "v.vdb", o);
    auto grids = read_grids_directly(dir / "v.vdb");
    ASSERT_EQ(grids->size(), 1u);
    EXPECT_TRUE((*grids)[0]->isType<openvdb::Vec3SGrid>());
    EXPECT_EQ((*grids)[0]->getName(), "vel");
    Field3D g = read_vdb(dir / "v.vdb");
    EXPECT_EQ(g.bounds(), b);
    EXPECT_EQ(g.channel_names(), f.channel_names());
    for (int c = 0; c < 3; ++c)
        for (size_t i = 0; i < f.voxel_count(); ++i) ASSERT_TRUE(same_bits(f.channel(c)[i], g.channel(c)[i]));
    // A vector field needs exactly 3 channels.
    Field3D two({{2, 2, 2}}, 2, b);
    expect_error_containing([&] { write_vdb(two, dir / "w.vdb", o); }, {"w.vdb", "vector3", "3"});
}

TEST(Vdb, GridNamesOption) {
    TempDir dir;
    Field3D f = sparse_field({"a", "b"}, Box3d{{{0, 0, 0}}, {{1, 1, 1}}});
    VdbOptions o;
    o.grid_names = {"density", "temperature"};
    write_vdb(f, dir / "n.vdb", o);
    EXPECT_EQ(list_vdb_grids(dir / "n.vdb"), (std::vector<std::string>{"density", "temperature"}));
    o.grid_names = {"one"};
    expect_error_containing([&] { write_vdb(f, dir / "m.vdb", o); }, {"m.vdb", "grid names"});
    o.grid_names = {"same", "same"};
    expect_error_containing([&] { write_vdb(f, dir / "m.vdb", o); }, {"m.vdb", "same"});
}

TEST(Vdb, OutputBytesAreDeterministic) {
    TempDir dir;
    Field3D f = sparse_field({"d"}, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {{20, 20, 20}});
    write_vdb(f, dir / "1.vdb");
    write_vdb(f, dir / "2.vdb");
    EXPECT_EQ(read_bytes(dir / "1.vdb"), read_bytes(dir / "2.vdb"));
    f.at(0, 3, 3, 3) += 1.0f;
    write_vdb(f, dir / "3.vdb");
    EXPECT_NE(read_bytes(dir / "1.vdb"), read_bytes(dir / "3.vdb"));
}

// Files from elsewhere (no atlas metadata): the union of active boxes.
TEST(Vdb, ForeignFileUsesActiveBoundingBoxUnion) {
    TempDir dir;
    openvdb::initialize();
    auto xf = openvdb::math::Transform::createLinearTransform(0.5);
    xf->postTranslate(openvdb::Vec3d(10, 20, 30));
    auto a = openvdb::FloatGrid::create(0.0f);
    a->setName("a");
    a->setTransform(xf);
    a->tree().setValue(openvdb::Coord(-2, 0, 1), 1.0f);
    a->tree().setValue(openvdb::Coord(3, 4, 1), 2.0f);
    auto b = openvdb::FloatGrid::create(0.0f);
    b->setName("b");
    b->setTransform(xf->copy());
    b->tree().setValue(openvdb::Coord(0, -1, 5), 3.0f);
    auto i = openvdb::Int32Grid::create(0);
    i->setName("labels");
    write_grids_directly(dir / "foreign.vdb", {a, b, i});

    Field3D f = read_vdb(dir / "foreign.vdb");
    ASSERT_EQ(f.channel_names(), (std::vector<std::string>{"a", "b"}));
    // Index box [-2,3] x [-1,4] x [1,5] -> 6 x 6 x 5.
    EXPECT_EQ(f.resolution(), (Vec3i{{6, 6, 5}}));
    const Box3d expect{{{10 + 0.5 * (-2 - 0.5), 20 + 0.5 * (-1 - 0.5), 30 + 0.5 * (1 - 0.5)}},
                       {{10 + 0.5 * (3 + 0.5), 20 + 0.5 * (4 + 0.5), 30 + 0.5 * (5 + 0.5)}}};
    for (int k = 0; k < 3; ++k) {
        EXPECT_DOUBLE_EQ(f.bounds().min[k], expect.min[k]);
        EXPECT_DOUBLE_EQ(f.bounds().max[k], expect.max[k]);
    }
    EXPECT_EQ(f.at(0, 0, 1, 0), 1.0f);  // (-2,0,1)
    EXPECT_EQ(f.at(0, 5, 5, 0), 2.0f);  // (3,4,1)
    EXPECT_EQ(f.at(1, 2, 0, 4), 3.0f);  // (0,-1,5)
    double total = 0;
    for (int c = 0; c < 2; ++c)
        for (float v : f.channel(c)) total += v;
    EXPECT_EQ(total, 6.0);
}

TEST(Vdb, ReadErrorsAreClear) {
    TempDir dir;
    openvdb::initialize();
    auto a = openvdb::FloatGrid::create(0.0f);
    a->setName("density");
    a->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    auto moved = openvdb::FloatGrid::create(0.0f);
    moved->setName("moved");
    moved->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    moved->setTransform(openvdb::math::Transform::createLinearTransform(2.0));
    auto empty = openvdb::FloatGrid::create(0.0f);
    empty->setName("empty");
    auto d = openvdb::DoubleGrid::create(0.0);
    d->setName("double");
    d->tree().setValue(openvdb::Coord(0, 0, 0), 1.0);
    write_grids_directly(dir / "mix.vdb", {a, moved, empty, d});

    expect_error_containing([&] { read_vdb(dir / "mix.vdb", {"densty"}); }, {"mix.vdb", "'densty'", "density", "moved", "empty", "double"});
    expect_error_containing([&] { read_vdb(dir / "mix.vdb", {"double"}); }, {"mix.vdb", "'double'", "double"});
    expect_error_containing([&] { read_vdb(dir / "mix.vdb", {"empty"}); }, {"mix.vdb", "'empty'", "no active voxels"});
    expect_error_containing([&] { read_vdb(dir / "mix.vdb", {"density", "moved"}); }, {"mix.vdb", "density", "moved", "transform"});
    expect_error_containing([&] { read_vdb(dir / "mix.vdb", {"density", "density"}); }, {"mix.vdb", "density", "twice"});
    // Only non-float grids.
    write_grids_directly(dir / "ints.vdb", {d});
    expect_error_containing([&] { read_vdb(dir / "ints.vdb"); }, {"ints.vdb", "double"});
}

TEST(Vdb, RotatedOrFlippedTransformsAreRejected) {
    TempDir dir;
    openvdb::initialize();
    auto a = openvdb::FloatGrid::create(0.0f);
    a->setName("a");
    a->tree().setValue(openvdb::Coord(0, 0, 0), 1.0f);
    auto xf = openvdb::math::Transform::createLinearTransform(1.0);
    xf->postRotate(0.3, openvdb::math::Z_AXIS);
    a->setTransform(xf);
    write_grids_directly(dir / "rot.vdb", {a});
    expect_error_containing([&] { read_vdb(dir / "rot.vdb"); }, {"rot.vdb", "axis-aligned"});
    auto flip = openvdb::math::Transform::createLinearTransform(1.0);
    flip->postScale(openvdb::Vec3d(1, -1, 1));
    a->setTransform(flip);
    write_grids_directly(dir / "flip.vdb", {a});
    expect_error_containing([&] { read_vdb(dir / "flip.vdb"); }, {"flip.vdb", "axis-aligned"});
}

// read_vdb densifies a float grid by visiting its tiles and leaves only; every
// voxel must be what OpenVDB's own copyToDense gives over the same box:
// leaf voxels active or not, tiles at both internal levels (active and
// inactive), a non-zero background, -0 values. A foreign file (no atlas box
// metadata): the box is the active voxels' union, which here cuts through a
// tile and a leaf.
#include <openvdb/tools/Dense.h>

TEST(Vdb, SparseDensifyMatchesCopyToDense) {
    TempDir dir;
    openvdb::initialize();
    auto g = openvdb::FloatGrid::create(0.25f);
    g->setName("density");
    auto& t = g->tree();
    t.setValue(openvdb::Coord(1, 2, 3), 1.5f);
    t.setValue(openvdb::Coord(2, 2, 3), -0.0f);
    t.setValueOff(openvdb::Coord(3, 2, 3), 7.0f);   // inactive voxel value in a leaf
    t.setValue(openvdb::Coord(300, -40, 17), 2.0f); // a far leaf: the box spans empty background
    t.addTile(1, openvdb::Coord(128, 0, 0), 3.0f, true);   // a 128^3 tile, active
    t.addTile(1, openvdb::Coord(0, 128, 0), 4.0f, false);  // inactive tile: its value still counts
    t.addTile(2, openvdb::Coord(-4096, -4096, -4096), -0.0f, false);
    t.setValue(openvdb::Coord(100, 200, -5), 0.5f);
    write_grids_directly(dir / "sparse.vdb", {g});
    const Field3D f = read_vdb(dir / "sparse.vdb");
    const openvdb::CoordBBox box = g->evalActiveVoxelBoundingBox();
    ASSERT_EQ(f.resolution(), (Vec3i{{box.dim().x(), box.dim().y(), box.dim().z()}}));
    std::vector<float> ref(size_t(box.volume()));
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, ref.data());
    openvdb::tools::copyToDense(*g, dense);
    size_t tile_voxels = 0, background = 0;
    for (size_t i = 0; i < ref.size(); ++i) {
        ASSERT_EQ(std::memcmp(&ref[i], &f.channel(0)[i], sizeof(float)), 0) << i << ": " << ref[i] << " vs " << f.channel(0)[i];
        tile_voxels += ref[i] == 3.0f || ref[i] == 4.0f;
        background += ref[i] == 0.25f;
    }
    EXPECT_GT(tile_voxels, 0u); // the box does reach the tiles ...
    EXPECT_GT(background, 0u);  // ... and the background
}
