// atlas info FILE...: what a file holds (size, format, channels, value statistics), on stdout.
#include "cli.h"

#include "atlas/compress/texture.h"
#include "atlas/core/error.h"
#include "atlas/core/field_math.h"
#include "atlas/io/dds_file.h"
#include "atlas/io/readers.h"
#include "atlas/io/vdb.h"

#include <algorithm>
#include <cstdio>

namespace atlas::cli {

namespace {
void print_channels(const detail::FieldStorage& f) {
    for (int c = 0; c < f.channels(); ++c) {
        ChannelStats s = channel_stats(f.channel(c));
        std::printf("  channel %-20s min %-12g max %-12g mean %-12g", f.channel_name(c).c_str(), s.min, s.max, s.mean);
        if (s.nan_count || s.inf_count) std::printf("  NaN %llu  Inf %llu", (unsigned long long)s.nan_count, (unsigned long long)s.inf_count);
        std::printf("\n");
    }
}

void describe(const Value& v) {
    if (auto f3 = std::get_if<Field3DPtr>(&v)) {
        const auto& f = **f3;
        std::printf("  3D field %dx%dx%d, %d channels, bounds [%g %g %g] - [%g %g %g] m, voxel %g x %g x %g m\n", f.nx(), f.ny(), f.nz(),
                    f.channels(), f.bounds().min[0], f.bounds().min[1], f.bounds().min[2], f.bounds().max[0], f.bounds().max[1],
                    f.bounds().max[2], f.voxel_size()[0], f.voxel_size()[1], f.voxel_size()[2]);
        print_channels(f);
    } else if (auto f2 = std::get_if<Field2DPtr>(&v)) {
        const auto& f = **f2;
        std::printf("  2D field %dx%d, %d channels, bounds [%g %g] - [%g %g]\n", f.width(), f.height(), f.channels(), f.bounds().min[0],
                    f.bounds().min[1], f.bounds().max[0], f.bounds().max[1]);
        print_channels(f);
    }
}
} // namespace

int run_info(const Args& a) {
    if (a.positional.empty()) throw UsageError{"expected at least one file", "info"};
    for (const auto& file : a.positional) {
        std::string ext = std::filesystem::path(file).extension().string();
        std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
        std::printf("%s\n", file.c_str());
        if (ext == ".dds") {
            const compress::DdsTexture t = io::read_dds_file(file);
            std::printf("  DDS %s %dx%dx%d%s, %d array element(s), %d mip level(s), %zu bytes of data\n",
                        compress::dxgi_format_name(t.format), t.width, t.height, t.depth, t.volume ? " (volume)" : "", t.array_size,
                        t.mip_levels, t.data.size());
            describe(Field3DPtr(std::make_shared<Field3D>(io::read_dds(file))));
            continue;
        }
        if (ext == ".vdb") {
            std::printf("  grids:");
            for (const auto& g : io::list_vdb_grids(file)) std::printf(" %s", g.c_str());
            std::printf("\n");
        }
        describe(io::read_field_file(file));
    }
    return 0;
}

} // namespace atlas::cli
