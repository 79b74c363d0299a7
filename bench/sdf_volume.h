// Shared by the compression benches: an SDF-like field, the distance (metres) to a few
// spheres clamped to -256..4096 m like Nubis's field data, at 8 m voxels.
#pragma once

#include "atlas/core/field.h"

#include <algorithm>
#include <cmath>

namespace atlas::bench {

inline Field3D sdf_volume(int nx, int ny, int nz) {
    Field3D f(Vec3i{{nx, ny, nz}}, 1, Box3d{{{0, 0, 0}}, {{nx * 8.0, ny * 8.0, nz * 8.0}}}, {"distance"});
    for (int z = 0; z < nz; ++z)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                double d = 1e30;
                for (int k = 0; k < 4; ++k) {
                    const double cx = nx * (0.2 + 0.2 * k), cy = ny * (0.3 + 0.13 * k), cz = nz * 0.5;
                    d = std::min(d, std::sqrt((x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz)) * 8.0 - 120.0);
                }
                f.at(0, x, y, z) = float(std::clamp(d, -256.0, 4096.0));
            }
    return f;
}

} // namespace atlas::bench
