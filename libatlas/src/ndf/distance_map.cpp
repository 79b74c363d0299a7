// Exact 3D Euclidean distance map above a heightfield by separable sweeps.
#include "atlas/ndf/distance_map.h"

#include "atlas/core/error.h"

#include "atlas/core/parallel.h"

#include <cmath>

namespace atlas::ndf {

namespace {
constexpr double kFar = 1e300;

void check(const Field2D& heights, int channel, int layers, double z0, double z1, double max_distance) {
    if (channel < 0 || channel >= heights.channels()) throw Error("distance map: 'channel' out of range for the height input");
    if (layers < 1 || layers > 65536) throw Error("distance map: 'layers' must be in [1, 65536]");
    if (!std::isfinite(z0) || !std::isfinite(z1) || !(z1 > z0)) throw Error("distance map: 'z_max' must be greater than 'z_min' (finite)");
    if (!(max_distance > 0) || !std::isfinite(max_distance)) throw Error("distance map: 'max_distance' must be > 0 and finite");
}

Box3d box_of(const Field2D& h, double z0, double z1) {
    return {{{h.bounds().min[0], h.bounds().min[1], z0}}, {{h.bounds().max[0], h.bounds().max[1], z1}}};
}

// Felzenszwalb-Huttenlocher: d[q] = min_p f[p] + ((q - p) s)^2 over the
// lower envelope of parabolas; `kFar` entries take no part.
void edt1d(const double* f, double* d, int n, double s, std::vector<int>& v, std::vector<double>& z) {
    int k = -1;
    for (int q = 0; q < n; ++q) {
        if (f[q] >= kFar) continue;
        if (k < 0) {
            k = 0;
            v[0] = q;
            z[0] = -INFINITY;
            z[1] = INFINITY;
            continue;
        }
        double sq;
        for (;;) {
            const int p = v[size_t(k)];
            const double qs = q * s, ps = p * s;
            sq = ((f[q] + qs * qs) - (f[p] + ps * ps)) / (2.0 * (qs - ps));
            if (sq <= z[size_t(k)] && k > 0) { --k; continue; }
            break;
        }
        if (sq <= z[size_t(k)]) { // k == 0 and the new parabola dominates everywhere
            v[0] = q;
            z[0] = -INFINITY;
            z[1] = INFINITY;
            continue;
        }
        ++k;
        v[size_t(k)] = q;
        z[size_t(k)] = sq;
        z[size_t(k) + 1] = INFINITY;
    }
    if (k < 0) {
        for (int q = 0; q < n; ++q) d[q] = kFar;
        return;
    }
    k = 0;
    for (int q = 0; q < n; ++q) {
        while (z[size_t(k) + 1] < q * s) ++k;
        const double dq = (q - v[size_t(k)]) * s;
        d[q] = dq * dq + f[v[size_t(k)]];
    }
}
} // namespace

Field3D distance_map(const Field2D& heights, int channel, int layers, double z0, double z1, double max_distance, const MemoryBudget* budget) {
    check(heights, channel, layers, z0, z1, max_distance);
    const int nx = heights.width(), ny = heights.height(), nz = layers;
    Field3D out({{nx, ny, nz}}, 1, box_of(heights, z0, z1), {"distance"}, budget);
    const Vec3d vs = out.voxel_size();
    if (budget) budget->check(uint64_t(nx) * ny * nz * sizeof(double), "distance map scratch");
    std::vector<double> g(size_t(nx) * size_t(ny) * size_t(nz));
    auto idx = [&](int x, int y, int k) { return (size_t(k) * size_t(ny) + size_t(y)) * size_t(nx) + size_t(x); };
    // Along z first: the solid is a column, so the 1D result is exact per column.
    parallel_for_index(ny, [&](int y) {
        const size_t n = size_t(nz);
        std::vector<double> f(n), d(n);
        std::vector<int> v(n);
        std::vector<double> zz(n + 1);
        for (int x = 0; x < nx; ++x) {
            const double h = heights.at(channel, x, y);
            for (int k = 0; k < nz; ++k) f[size_t(k)] = (out.voxel_center(x, y, k)[2] <= h) ? 0.0 : kFar;
            edt1d(f.data(), d.data(), nz, vs[2], v, zz);
            for (int k = 0; k < nz; ++k) g[idx(x, y, k)] = d[size_t(k)];
        }
    });
    // Along y, then x.
    parallel_for_index(nz, [&](int k) {
        const size_t n = size_t(std::max(nx, ny));
        std::vector<double> f(n), d(n);
        std::vector<int> v(f.size());
        std::vector<double> zz(f.size() + 1);
        for (int x = 0; x < nx; ++x) {
            for (int y = 0; y < ny; ++y) f[size_t(y)] = g[idx(x, y, k)];
            edt1d(f.data(), d.data(), ny, vs[1], v, zz);
            for (int y = 0; y < ny; ++y) g[idx(x, y, k)] = d[size_t(y)];
        }
        for (int y = 0; y < ny; ++y) {
            for (int x = 0; x < nx; ++x) f[size_t(x)] = g[idx(x, y, k)];
            edt1d(f.data(), d.data(), nx, vs[0], v, zz);
            auto dst = out.channel(0);
            for (int x = 0; x < nx; ++x) dst[idx(x, y, k)] = float(std::min(std::sqrt(d[size_t(x)]), max_distance));
        }
    });
    return out;
}

Field3D distance_map_brute_force(const Field2D& heights, int channel, int layers, double z0, double z1, double max_distance) {
    check(heights, channel, layers, z0, z1, max_distance);
    const int nx = heights.width(), ny = heights.height(), nz = layers;
    Field3D out({{nx, ny, nz}}, 1, box_of(heights, z0, z1), {"distance"});
    std::vector<Vec3d> solid;
    for (int k = 0; k < nz; ++k)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x)
                if (out.voxel_center(x, y, k)[2] <= heights.at(channel, x, y)) solid.push_back(out.voxel_center(x, y, k));
    for (int k = 0; k < nz; ++k)
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                double best = max_distance;
                const Vec3d p = out.voxel_center(x, y, k);
                for (const Vec3d& s : solid) best = std::min(best, length(p - s));
                out.at(0, x, y, k) = float(best);
            }
    return out;
}

} // namespace atlas::ndf
