// sim::sequence_frame: the solver's 'NNNN:GRID' frames read one at a time
// (whole frames copied, fractional frames crossfaded), against values built
// by hand; bad frames and grids are refused by name.
#include "atlas/core/error.h"
#include "atlas/sim/sequence.h"

#include <gtest/gtest.h>

using namespace atlas;

namespace {
// Three frames of density and vel on a 3x2x2 grid: frame f holds f * 10 + voxel
// in density and -f, 2f, 3f + voxel in vel; the channels out of frame order.
Field3D three_frames() {
    std::vector<std::string> names;
    for (int f : {2, 1, 3}) {
        names.push_back("000" + std::to_string(f) + ":density");
        for (const char* a : {"vel.x", "vel.y", "vel.z"}) names.push_back("000" + std::to_string(f) + ":" + a);
    }
    Field3D s({{3, 2, 2}}, int(names.size()), Box3d{{{0, 0, 0}}, {{3, 2, 2}}}, names);
    for (int c = 0; c < s.channels(); ++c) {
        const int f = names[size_t(c)][3] - '0';
        const std::string g = names[size_t(c)].substr(5);
        auto v = s.channel(c);
        for (size_t i = 0; i < v.size(); ++i)
            v[i] = g == "density" ? float(f * 10 + int(i)) : g == "vel.x" ? float(-f) : g == "vel.y" ? float(2 * f) : float(3 * f + int(i));
    }
    return s;
}
} // namespace

TEST(SimSequence, ListsFramesAndCopiesWholeFrames) {
    const Field3D s = three_frames();
    EXPECT_EQ(sim::sequence_frames(s, "density"), (std::vector<int>{1, 2, 3}));
    EXPECT_EQ(sim::sequence_frames(s, "vel"), (std::vector<int>{1, 2, 3}));
    EXPECT_TRUE(sim::sequence_frames(s, "temperature").empty());
    const Field3D d2 = sim::sequence_frame(s, "density", 2);
    ASSERT_EQ(d2.channels(), 1);
    EXPECT_EQ(d2.channel_names()[0], "density");
    EXPECT_EQ(d2.resolution(), s.resolution());
    for (size_t i = 0; i < d2.channel(0).size(); ++i) EXPECT_EQ(d2.channel(0)[i], float(20 + int(i)));
    const Field3D v3 = sim::sequence_frame(s, "vel", 3);
    ASSERT_EQ(v3.channels(), 3);
    EXPECT_EQ(v3.channel(0)[5], -3.0f);
    EXPECT_EQ(v3.channel(1)[5], 6.0f);
    EXPECT_EQ(v3.channel(2)[5], 14.0f);
}

TEST(SimSequence, FractionalFramesCrossfadeTheTwoAroundThem) {
    const Field3D s = three_frames();
    const Field3D d = sim::sequence_frame(s, "density", 1.25);
    for (size_t i = 0; i < d.channel(0).size(); ++i) EXPECT_FLOAT_EQ(d.channel(0)[i], 12.5f + float(i)); // 10 + 0.25 * 10
    const Field3D last = sim::sequence_frame(s, "density", 3.0); // the last frame has no next
    EXPECT_EQ(last.channel(0)[0], 30.0f);
}

TEST(SimSequence, RefusesFramesOutsideTheSequenceGapsAndUnknownGrids) {
    const Field3D s = three_frames();
    for (double f : {0.0, 0.999, 3.001, -1.0, std::nan("")}) {
        try {
            sim::sequence_frame(s, "density", f);
            ADD_FAILURE() << "frame " << f << " was accepted";
        } catch (const Error& e) {
            EXPECT_NE(std::string(e.what()).find("3 frames of 'density' (1 .. 3)"), std::string::npos) << e.what();
        }
    }
    EXPECT_THROW(sim::sequence_frame(s, "temperature", 1), Error);
    EXPECT_THROW(sim::sequence_frame(s, "pressure", 1), Error);
    Field3D gap({{1, 1, 1}}, 2, Box3d{{{0, 0, 0}}, {{1, 1, 1}}}, {"0001:density", "0003:density"});
    try {
        sim::sequence_frame(gap, "density", 1);
        ADD_FAILURE() << "a gap was accepted";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("frame 2 is missing"), std::string::npos) << e.what();
    }
}
