// Density projection along z for previews.
#include "atlas/volume/projection.h"

#include "atlas/core/error.h"

#include <cmath>
#include <string>

namespace atlas::volume {

Field2D project_density(const Field3D& f, double k, int channel) {
    if (channel < 0 || channel >= f.channels()) throw Error("project_density: channel " + std::to_string(channel) + " does not exist");
    if (!(k > 0) || !std::isfinite(k)) throw Error("project_density: extinction must be finite and > 0 (1/m)");
    const Box3d& b = f.bounds();
    Field2D out({{f.nx(), f.ny()}}, 1, {{{b.min[0], b.min[1]}}, {{b.max[0], b.max[1]}}}, {"opacity"});
    const double dz = f.voxel_size()[2];
    for (int y = 0; y < f.ny(); ++y)
        for (int x = 0; x < f.nx(); ++x) {
            double sum = 0;
            for (int z = 0; z < f.nz(); ++z) sum += std::max(0.0f, f.at(channel, x, y, z));
            out.at(0, x, y) = float(1 - std::exp(-k * sum * dz));
        }
    return out;
}

} // namespace atlas::volume
