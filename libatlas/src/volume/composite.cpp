// Compositing clouds into a world grid, and cutouts.
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/volume/edit.h"

#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>

namespace atlas::volume {
namespace {

void check_channel(const Field3D& f, int c, const char* what) {
    if (c < 0 || c >= f.channels()) throw Error(std::string(what) + ": channel " + std::to_string(c) + " does not exist");
}


float saturate(double v) { return float(std::clamp(v, 0.0, 1.0)); }

} // namespace

CompositeOp parse_composite_op(const std::string& n) {
    if (n == "max") return CompositeOp::Max;
    if (n == "add") return CompositeOp::Add;
    if (n == "over") return CompositeOp::Over;
    if (n == "subtract") return CompositeOp::Subtract;
    throw Error("unknown composite operation '" + n + "' (expected max, add, over or subtract)");
}

Field3D composite(const Field3D& world, const Field3D& cloud, CompositeOp op, double opacity, int wc, int cc, const MemoryBudget* budget,
                  const GridFrame* frame) {
    const GridFrame fr = frame ? *frame : world.frame();
    check_channel(world, wc, "composite (world)");
    check_channel(cloud, cc, "composite (cloud)");
    if (!std::isfinite(opacity)) throw Error("composite: opacity must be finite");
    if (budget) budget->check(world.byte_size(), "composite: the world grid copy");
    Field3D out = world;
    const bool same = fr.same_grid(cloud);
    const float op_f = float(opacity);
    parallel_for_index(world.nz(), [&](int z) {
        for (int y = 0; y < world.ny(); ++y)
            for (int x = 0; x < world.nx(); ++x) {
                const float c = op_f * (same ? cloud.at(cc, x + fr.offset[0], y + fr.offset[1], z) : sample_or(cloud, cc, fr.voxel_center(x, y, z)));
                float& w = out.at(wc, x, y, z);
                switch (op) {
                case CompositeOp::Max: w = std::max(w, c); break;
                case CompositeOp::Add: w = w + c; break;
                case CompositeOp::Over: w = c + w * (1 - saturate(c)); break;
                case CompositeOp::Subtract: w = std::max(w - c, 0.0f); break;
                }
            }
    });
    return out;
}

Field3D cutout_density(const Field3D& density, const Shape& shape, double edge, const MemoryBudget* budget, const GridFrame* frame) {
    const GridFrame fr = frame ? *frame : density.frame();
    validate_shape(shape);
    if (!(edge >= 0) || !std::isfinite(edge)) throw Error("cutout: edge must be finite and >= 0");
    if (budget) budget->check(density.byte_size(), "cutout: the density copy");
    Field3D out = density;
    parallel_for_index(density.nz(), [&](int z) {
        for (int y = 0; y < density.ny(); ++y)
            for (int x = 0; x < density.nx(); ++x) {
                const double d = shape_distance(shape, fr.voxel_center(x, y, z));
                const float k = edge > 0 ? saturate(d / edge) : (d > 0 ? 1.0f : 0.0f);
                if (k == 1.0f) continue;
                for (int c = 0; c < out.channels(); ++c) out.at(c, x, y, z) *= k;
            }
    });
    return out;
}

Field3D subtract_shape_sdf(const Field3D& sdf, const Shape& shape, int channel, const MemoryBudget* budget) {
    validate_shape(shape);
    check_channel(sdf, channel, "subtract_shape_sdf");
    if (budget) budget->check(sdf.byte_size(), "subtract_shape_sdf: the SDF copy");
    Field3D out = sdf;
    parallel_for_index(sdf.nz(), [&](int z) {
        for (int y = 0; y < sdf.ny(); ++y)
            for (int x = 0; x < sdf.nx(); ++x) {
                float& d = out.at(channel, x, y, z);
                d = std::max(d, float(-shape_distance(shape, sdf.voxel_center(x, y, z))));
            }
    });
    return out;
}

Field3D cutout_density_by_sdf(const Field3D& density, const Field3D& cutter, double edge, const MemoryBudget* budget, const GridFrame* frame) {
    const GridFrame fr = frame ? *frame : density.frame();
    if (!(edge >= 0) || !std::isfinite(edge)) throw Error("cutout: edge must be finite and >= 0");
    if (budget) budget->check(density.byte_size(), "cutout: the density copy");
    Field3D out = density;
    const bool same = fr.same_grid(cutter);
    parallel_for_index(density.nz(), [&](int z) {
        for (int y = 0; y < density.ny(); ++y)
            for (int x = 0; x < density.nx(); ++x) {
                const double d = same ? cutter.at(0, x + fr.offset[0], y + fr.offset[1], z) : sample_or(cutter, 0, fr.voxel_center(x, y, z), 1e30f);
                const float k = edge > 0 ? saturate(d / edge) : (d > 0 ? 1.0f : 0.0f);
                if (k == 1.0f) continue;
                for (int c = 0; c < out.channels(); ++c) out.at(c, x, y, z) *= k;
            }
    });
    return out;
}

} // namespace atlas::volume
