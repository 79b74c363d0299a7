#include "atlas/core/field.h"
#include <gtest/gtest.h>
TEST(Field, Smoke) { atlas::Field3D f({{2,2,2}}, 1, {{{0,0,0}},{{1,1,1}}}); EXPECT_EQ(f.voxel_count(), 8u); }
