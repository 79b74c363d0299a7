// Vorticity confinement (see confinement.h).
#include "atlas/sim/confinement.h"

#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>

namespace atlas::sim {

void confinement_force(const MacVelocity& vel, double eps, std::vector<float>& fx, std::vector<float>& fy,
                       std::vector<float>& fz) {
    const GridSpec& s = vel.spec;
    const int nx = s.nx, ny = s.ny, nz = s.nz;
    const double h = s.dx;
    const size_t n = s.cells();
    std::vector<float> cu(n), cv(n), cw(n), ox(n), oy(n), oz(n), mag(n);
    fx.assign(n, 0.f), fy.assign(n, 0.f), fz.assign(n, 0.f);
    parallel_for_index(nz, [&](int k) {
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                size_t c = vel.ic(i, j, k);
                cu[c] = 0.5f * (vel.u[vel.iu(i, j, k)] + vel.u[vel.iu(i + 1, j, k)]);
                cv[c] = 0.5f * (vel.v[vel.iv(i, j, k)] + vel.v[vel.iv(i, j + 1, k)]);
                cw[c] = 0.5f * (vel.w[vel.iw(i, j, k)] + vel.w[vel.iw(i, j, k + 1)]);
            }
    });
    // Central differences with clamped neighbours (one-sided at the edges;
    // across the wrap along a periodic axis).
    const bool wrap[3] = {s.periodic(0), s.periodic(1), false};
    auto d = [&](const std::vector<float>& a, int i, int j, int k, int axis) -> double {
        int lo[3] = {i, j, k}, hi[3] = {i, j, k};
        const int nn[3] = {nx, ny, nz};
        if (wrap[axis]) {
            lo[axis] = lo[axis] == 0 ? nn[axis] - 1 : lo[axis] - 1;
            hi[axis] = hi[axis] == nn[axis] - 1 ? 0 : hi[axis] + 1;
            return (double(a[vel.ic(hi[0], hi[1], hi[2])]) - a[vel.ic(lo[0], lo[1], lo[2])]) / (2 * h);
        }
        lo[axis] = std::max(lo[axis] - 1, 0);
        hi[axis] = std::min(hi[axis] + 1, nn[axis] - 1);
        int span = hi[axis] - lo[axis];
        if (span == 0) return 0.0;
        return (double(a[vel.ic(hi[0], hi[1], hi[2])]) - a[vel.ic(lo[0], lo[1], lo[2])]) / (span * h);
    };
    parallel_for_index(nz, [&](int k) {
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                size_t c = vel.ic(i, j, k);
                ox[c] = float(d(cw, i, j, k, 1) - d(cv, i, j, k, 2));
                oy[c] = float(d(cu, i, j, k, 2) - d(cw, i, j, k, 0));
                oz[c] = float(d(cv, i, j, k, 0) - d(cu, i, j, k, 1));
                mag[c] = std::sqrt(ox[c] * ox[c] + oy[c] * oy[c] + oz[c] * oz[c]);
            }
    });
    parallel_for_index(nz, [&](int k) {
        for (int j = 0; j < ny; ++j)
            for (int i = 0; i < nx; ++i) {
                size_t c = vel.ic(i, j, k);
                double gx = d(mag, i, j, k, 0), gy = d(mag, i, j, k, 1), gz = d(mag, i, j, k, 2);
                double gl = std::sqrt(gx * gx + gy * gy + gz * gz);
                if (!(gl * h > 1e-4 * mag[c])) continue; // flat |omega|: no vortex edge to push on
                // eps dx |omega| (N x omega): the extra |omega| is the local turnover
                // rate that makes eps dimensionless (see confinement.h).
                const double a = eps * h * mag[c] / gl;
                fx[c] = float(a * (gy * oz[c] - gz * oy[c]));
                fy[c] = float(a * (gz * ox[c] - gx * oz[c]));
                fz[c] = float(a * (gx * oy[c] - gy * ox[c]));
            }
    });
}

void add_confinement(MacVelocity& vel, double eps, double dt) {
    std::vector<float> fx, fy, fz;
    confinement_force(vel, eps, fx, fy, fz);
    const GridSpec& s = vel.spec;
    // Periodic axes: face 0 (= face n) lies between the last and the first cell.
    const bool wx = s.periodic(0), wy = s.periodic(1);
    parallel_for_index(s.nz, [&](int k) {
        for (int j = 0; j < s.ny; ++j) {
            for (int i = 1; i < s.nx; ++i)
                vel.u[vel.iu(i, j, k)] += float(dt * 0.5 * (fx[vel.ic(i - 1, j, k)] + fx[vel.ic(i, j, k)]));
            if (wx) {
                vel.u[vel.iu(0, j, k)] += float(dt * 0.5 * (fx[vel.ic(s.nx - 1, j, k)] + fx[vel.ic(0, j, k)]));
                vel.u[vel.iu(s.nx, j, k)] = vel.u[vel.iu(0, j, k)];
            }
            if (j > 0 || wy) {
                const int jm = j > 0 ? j - 1 : s.ny - 1;
                for (int i = 0; i < s.nx; ++i)
                    vel.v[vel.iv(i, j, k)] += float(dt * 0.5 * (fy[vel.ic(i, jm, k)] + fy[vel.ic(i, j, k)]));
            }
            if (k > 0)
                for (int i = 0; i < s.nx; ++i)
                    vel.w[vel.iw(i, j, k)] += float(dt * 0.5 * (fz[vel.ic(i, j, k - 1)] + fz[vel.ic(i, j, k)]));
        }
        if (wy)
            for (int i = 0; i < s.nx; ++i) vel.v[vel.iv(i, s.ny, k)] = vel.v[vel.iv(i, 0, k)];
    });
}

} // namespace atlas::sim
