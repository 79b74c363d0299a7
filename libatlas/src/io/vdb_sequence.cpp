// The 'vdb-sequence' output format: a Field3D whose channels are named
// "NNNN:GRID" (as sim/cloud_growth's 'sequence' output makes) becomes one VDB
// file per frame, DIR/STEM.NNNN.vdb, the numbered layout Houdini and Blender
// load as a sequence. Within a frame, channels GRID.x/.y/.z (consecutive)
// become one vec3s grid GRID; others are float fog-volume grids. Grids carry
// the same transform and atlas_* bounds metadata as write_vdb (vdb.h), so
// io::read_vdb reads each file back exactly. Bytes are deterministic.
#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/io/output_options.h"
#include "format_table.h"
#include "vdb_internal.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <cstdio>
#include <limits>

namespace atlas::io::detail {

namespace {

struct FrameGrid {
    std::string name;
    std::vector<int> channels; // 1 (float) or 3 (vector)
};

struct Frame {
    int number = 0;
    std::vector<FrameGrid> grids;
};

// "0007:vel.x" -> frame 7, grid "vel.x"; the frame part is 1..6 decimal digits.
bool split_channel(const std::string& name, int& frame, std::string& grid) {
    const size_t colon = name.find(':');
    if (colon == std::string::npos || colon == 0 || colon > 6 || colon + 1 >= name.size()) return false;
    frame = 0;
    for (size_t i = 0; i < colon; ++i) {
        if (name[i] < '0' || name[i] > '9') return false;
        frame = frame * 10 + (name[i] - '0');
    }
    grid = name.substr(colon + 1);
    return true;
}

bool ends_with(const std::string& s, const char* tail) {
    const size_t n = std::char_traits<char>::length(tail);
    return s.size() > n && s.compare(s.size() - n, n, tail) == 0;
}

std::vector<Frame> frames_of(const Field3D& f, const OptionReader& o) {
    std::vector<int> numbers;
    std::vector<std::string> names;
    for (int c = 0; c < f.channels(); ++c) {
        int number = 0;
        std::string grid;
        if (!split_channel(f.channel_name(c), number, grid))
            throw Error(o.prefix() + "format 'vdb-sequence' needs channels named FRAME:GRID (e.g. '0001:density', as "
                                     "sim/cloud_growth's 'sequence' output makes); channel " +
                        std::to_string(c) + " is '" + f.channel_name(c) + "'");
        numbers.push_back(number);
        names.push_back(grid);
    }
    std::vector<Frame> frames;
    for (int c = 0; c < f.channels();) {
        if (frames.empty() || frames.back().number != numbers[size_t(c)]) {
            for (const Frame& fr : frames)
                if (fr.number == numbers[size_t(c)])
                    throw Error(o.prefix() + "frame " + std::to_string(fr.number) + "'s channels are not consecutive");
            frames.push_back({numbers[size_t(c)], {}});
        }
        Frame& fr = frames.back();
        const std::string& n = names[size_t(c)];
        FrameGrid g{n, {c}};
        // NAME.x, NAME.y, NAME.z in a row (same frame) make one vector grid NAME.
        if (ends_with(n, ".x") && c + 2 < f.channels() && numbers[size_t(c) + 2] == fr.number && numbers[size_t(c) + 1] == fr.number) {
            const std::string base = n.substr(0, n.size() - 2);
            if (names[size_t(c) + 1] == base + ".y" && names[size_t(c) + 2] == base + ".z") g = FrameGrid{base, {c, c + 1, c + 2}};
        }
        for (const FrameGrid& h : fr.grids)
            if (h.name == g.name) throw Error(o.prefix() + "frame " + std::to_string(fr.number) + ": grid '" + g.name + "' appears twice");
        c += int(g.channels.size());
        fr.grids.push_back(std::move(g));
    }
    return frames;
}

void write_frame(const Field3D& f, const Frame& fr, const fs::path& path, float tolerance, const OptionReader& o) {
    openvdb::math::Transform::Ptr xf;
    try {
        xf = field_transform(f);
    } catch (const std::exception& e) {
        throw Error(o.prefix() + "OpenVDB cannot represent the voxel size (" + e.what() + ")");
    }
    const openvdb::CoordBBox bbox(openvdb::Coord(0, 0, 0), openvdb::Coord(f.nx() - 1, f.ny() - 1, f.nz() - 1));
    openvdb::GridPtrVec grids;
    Hasher h;
    h.add(tolerance);
    for (const FrameGrid& g : fr.grids) {
        h.add(g.name);
        for (int c : g.channels) h.add_bytes(f.channel(c).data(), f.channel(c).size_bytes());
        openvdb::GridBase::Ptr base;
        if (g.channels.size() == 3) {
            auto grid = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
            auto acc = grid->getAccessor();
            for (int z = 0; z < f.nz(); ++z)
                for (int y = 0; y < f.ny(); ++y)
                    for (int x = 0; x < f.nx(); ++x) {
                        const openvdb::Vec3s a(f.at(g.channels[0], x, y, z), f.at(g.channels[1], x, y, z), f.at(g.channels[2], x, y, z));
                        if (!(std::fabs(a[0]) <= tolerance && std::fabs(a[1]) <= tolerance && std::fabs(a[2]) <= tolerance))
                            acc.setValue(openvdb::Coord(x, y, z), a);
                    }
            grid->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
            base = grid;
        } else {
            auto grid = openvdb::FloatGrid::create(0.0f);
            openvdb::tools::Dense<const float, openvdb::tools::LayoutXYZ> dense(bbox, f.channel(g.channels[0]).data());
            openvdb::tools::copyFromDense(dense, *grid, tolerance);
            base = grid;
        }
        base->setName(g.name);
        base->setTransform(xf->copy());
        base->setGridClass(openvdb::GRID_FOG_VOLUME);
        add_atlas_meta(*base, f);
        grids.push_back(base);
    }
    try {
        write_vdb_grids(path, grids);
    } catch (const std::exception& e) {
        throw Error(o.prefix() + "cannot write " + path.filename().string() + ": " + e.what());
    }
    make_uuid_deterministic(path, h.finish());
}

} // namespace

std::vector<fs::path> write_vdb_sequence_output(const Value& v, const fs::path& p, const OutputOptions& opts, OutputMetrics& metrics) {
    const OptionReader o(opts, p);
    if (p.extension() == ".vdb" || p.extension() == ".VDB")
        throw Error(o.prefix() + "format 'vdb-sequence' takes DIR/STEM (it writes STEM.0001.vdb, STEM.0002.vdb, ...), not a .vdb file name");
    const float tolerance = o.number("tolerance", 0.0f, 0.0f, std::numeric_limits<float>::infinity());
    init_openvdb();
    const Field3D& f = *std::get<Field3DPtr>(v);
    const std::vector<Frame> frames = frames_of(f, o);
    std::vector<fs::path> written;
    for (size_t i = 0; i < frames.size(); ++i) {
        char num[16];
        std::snprintf(num, sizeof num, ".%04d.vdb", frames[i].number);
        const fs::path file = p.parent_path() / (p.filename().string() + num);
        write_frame(f, frames[i], file, tolerance, o);
        written.push_back(file);
    }
    metrics["frames"] = double(frames.size());
    return written;
}

} // namespace atlas::io::detail
