// Brute-force SDF reference, error comparison and eikonal residual.
#include "atlas/volume/sdf.h"
#include "surface_crossings.h"

#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace atlas::volume {

Field3D sdf_brute_force(const Field3D& density, const SdfOptions& o) {
    detail::check_density(density, o, "sdf (brute force)");
    const Vec3i res = density.resolution();
    const Vec3d h = density.voxel_size();
    const float iso = float(o.iso);
    // Crossing points in index space (fractional along one axis).
    std::vector<Vec3d> seeds;
    const int step[3] = {1, res[0], res[0] * res[1]};
    auto dens = density.channel(o.channel);
    for (int z = 0; z < res[2]; ++z)
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                const size_t i = density.index(x, y, z);
                const int c[3] = {x, y, z};
                for (int a = 0; a < 3; ++a) {
                    const bool in = detail::is_inside(dens[i], iso);
                    if (o.border_is_outside && in && c[a] == 0) {
                        Vec3d p{{double(x), double(y), double(z)}};
                        p[a] -= 0.5;
                        seeds.push_back(p);
                    }
                    if (o.border_is_outside && in && c[a] == res[a] - 1) {
                        Vec3d p{{double(x), double(y), double(z)}};
                        p[a] += 0.5;
                        seeds.push_back(p);
                    }
                    if (c[a] + 1 >= res[a]) continue;
                    const size_t j = i + size_t(step[a]);
                    if (in == detail::is_inside(dens[j], iso)) continue;
                    Vec3d p{{double(x), double(y), double(z)}};
                    p[a] += detail::crossing_t(dens[i], dens[j], iso);
                    seeds.push_back(p);
                }
            }
    if (double(seeds.size()) * double(density.voxel_count()) > 4e9)
        throw Error("sdf (brute force): " + std::to_string(density.voxel_count()) + " voxels x " + std::to_string(seeds.size()) +
                    " crossings is too large for the brute-force reference (limit 4e9 pairs)");
    Field3D out(res, 1, density.bounds(), {"sdf"});
    const double far = detail::far_value(density, o);
    auto sdf = out.channel(0);
    parallel_for_index(res[2], [&](int z) {
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                double best = std::numeric_limits<double>::infinity();
                for (const Vec3d& s : seeds) {
                    const double dx = (x - s[0]) * h[0], dy = (y - s[1]) * h[1], dz = (z - s[2]) * h[2];
                    best = std::min(best, dx * dx + dy * dy + dz * dz);
                }
                const size_t i = density.index(x, y, z);
                const double d = seeds.empty() ? far : std::sqrt(best);
                sdf[i] = float(detail::is_inside(dens[i], iso) ? -d : d);
            }
    });
    return out;
}

SdfError compare_sdf(const Field3D& sdf, const Field3D& ref, int channel) {
    if (sdf.resolution() != ref.resolution()) throw Error("compare_sdf: the two fields differ in resolution");
    if (channel < 0 || channel >= sdf.channels() || channel >= ref.channels())
        throw Error("compare_sdf: channel " + std::to_string(channel) + " does not exist");
    const Vec3d h = sdf.voxel_size();
    const double vox = std::min({h[0], h[1], h[2]});
    auto a = sdf.channel(channel);
    auto b = ref.channel(channel);
    SdfError e;
    double sum = 0;
    for (size_t i = 0; i < a.size(); ++i) {
        const double d = std::abs(double(a[i]) - double(b[i]));
        e.max_abs_m = std::max(e.max_abs_m, d);
        sum += d * d;
        e.sign_mismatches += (a[i] < 0) != (b[i] < 0);
    }
    e.rms_m = a.empty() ? 0 : std::sqrt(sum / double(a.size()));
    e.max_abs_voxels = e.max_abs_m / vox;
    e.rms_voxels = e.rms_m / vox;
    return e;
}

EikonalResidual eikonal_residual(const Field3D& sdf, int channel, const std::function<bool(int, int, int)>& mask) {
    if (channel < 0 || channel >= sdf.channels()) throw Error("eikonal_residual: channel " + std::to_string(channel) + " does not exist");
    const Vec3d h = sdf.voxel_size();
    EikonalResidual r;
    double sum = 0;
    for (int z = 1; z + 1 < sdf.nz(); ++z)
        for (int y = 1; y + 1 < sdf.ny(); ++y)
            for (int x = 1; x + 1 < sdf.nx(); ++x) {
                if (mask && !mask(x, y, z)) continue;
                const double gx = (sdf.at(channel, x + 1, y, z) - sdf.at(channel, x - 1, y, z)) / (2 * h[0]);
                const double gy = (sdf.at(channel, x, y + 1, z) - sdf.at(channel, x, y - 1, z)) / (2 * h[1]);
                const double gz = (sdf.at(channel, x, y, z + 1) - sdf.at(channel, x, y, z - 1)) / (2 * h[2]);
                const double res = std::abs(std::sqrt(gx * gx + gy * gy + gz * gz) - 1.0);
                sum += res;
                r.max = std::max(r.max, res);
                ++r.voxels;
            }
    r.mean = r.voxels ? sum / double(r.voxels) : 0;
    return r;
}

} // namespace atlas::volume
