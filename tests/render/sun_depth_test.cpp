// The sun depth map (render/light_grid.h, the march's light lookups) keeps only the
// samples of a column from its first to its last cloud sample. At every voxel centre of
// a sun straight overhead (columns are the voxel columns, no shear, no interpolation)
// its depth must equal the midpoint sum of the same density samples, computed here in
// the map's order: 0 above the cloud, the column's total below it, the running sum
// between, and 0 in columns without cloud. Given a distance that bounds the cloud from
// below, it skips the samples within it unread and keeps every depth.
#include "../../libatlas/src/render/light_grid.h" // internal

#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <vector>

namespace atlas::render::detail {
namespace {

TEST(SunDepthMap, KeptRangeAnswersEveryVoxelAsTheFullColumnSum) {
    const Box3d bounds{{{0, 0, 0}}, {{160, 120, 200}}};
    const Vec3d voxel{{10, 10, 10}};
    // Two blobs stacked in some columns (a gap of empty samples between them), one
    // elsewhere, most columns empty.
    auto blob = [](double x, double y, double z, double cx, double cy, double cz, double r) {
        const double d = std::sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz));
        return d < r ? 1.0 - d / r : 0.0;
    };
    const LightGrid::DensityFn density = [&](double x, double y, double z) {
        return static_cast<float>(blob(x, y, z, 45, 55, 40, 28) + blob(x, y, z, 45, 55, 150, 22) + 0.5 * blob(x, y, z, 125, 85, 95, 18));
    };
    const SunDepthMap map(bounds, voxel, Vec3d{{0, 0, 1}}, density);
    const int nx = 16, ny = 12, nz = 20;
    size_t cloud_columns = 0;
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            const double x = 5 + 10 * i, y = 5 + 10 * j;
            std::vector<float> want(static_cast<size_t>(nz));
            double acc = 0;
            bool any = false;
            for (int k = nz - 1; k >= 0; --k) { // from the sun's side, as the map sums
                const double dm = density(x, y, 5 + 10 * k);
                any = any || dm != 0;
                want[size_t(k)] = static_cast<float>(acc + 0.5 * dm * 10.0);
                acc += dm * 10.0;
            }
            cloud_columns += any;
            for (int k = 0; k < nz; ++k) EXPECT_EQ(map.sun(x, y, 5 + 10 * k), want[size_t(k)]) << i << " " << j << " " << k;
        }
    EXPECT_GT(cloud_columns, 10u);
    // Only the cloud's stretch of each column is stored: far fewer than the table's samples.
    EXPECT_EQ(map.columns(), size_t(nx) * size_t(ny));
    EXPECT_LT(map.cells(), size_t(nx) * size_t(ny) * size_t(nz) / 4);
    EXPECT_GT(map.cells(), 0u);

    // With a distance that bounds the cloud from below (here the exact distance to the
    // blobs' supports), the samples inside its balls are not read, and every depth is the same.
    auto dist = [](double x, double y, double z, double cx, double cy, double cz, double r) {
        return std::sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz)) - r;
    };
    const LightGrid::DensityFn distance = [&](double x, double y, double z) {
        return static_cast<float>(std::min({dist(x, y, z, 45, 55, 40, 28), dist(x, y, z, 45, 55, 150, 22), dist(x, y, z, 125, 85, 95, 18)}));
    };
    // The map reads columns from several threads: count atomically (a plain
    // counter lost increments, 3211 of 3840 once).
    std::atomic<size_t> reads{0}, reads_skipping{0};
    const LightGrid::DensityFn counted = [&](double x, double y, double z) { ++reads; return density(x, y, z); };
    const LightGrid::DensityFn counted_skipping = [&](double x, double y, double z) { ++reads_skipping; return density(x, y, z); };
    const SunDepthMap full(bounds, voxel, Vec3d{{0, 0, 1}}, counted, 1.0, nullptr);
    const SunDepthMap skipping(bounds, voxel, Vec3d{{0, 0, 1}}, counted_skipping, 1.0, &distance);
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                const double x = 5 + 10 * i, y = 5 + 10 * j, z = 5 + 10 * k;
                EXPECT_EQ(skipping.sun(x, y, z), full.sun(x, y, z)) << i << " " << j << " " << k;
            }
    EXPECT_EQ(reads.load(), size_t(nx) * size_t(ny) * size_t(nz));
    EXPECT_LT(reads_skipping.load(), reads.load() / 2);
}

} // namespace
} // namespace atlas::render::detail
