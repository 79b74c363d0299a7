#include "atlas/sim/mac_grid.h"

#include "atlas/core/error.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace atlas::sim {

void GridSpec::validate() const {
    auto dim = [](int n, const char* name) {
        if (n < 1 || n > 4096)
            throw Error(std::string("sim grid: ") + name + " = " + std::to_string(n) + ", expected 1..4096 cells");
    };
    dim(nx, "nx");
    dim(ny, "ny");
    dim(nz, "nz");
    int big = (nx >= 2) + (ny >= 2) + (nz >= 2);
    if (big < 2) throw Error("sim grid: at least two of nx, ny, nz must be >= 2");
    if (!(dx >= 1e-3 && dx <= 1e5)) throw Error("sim grid: dx = " + std::to_string(dx) + ", expected 1e-3..1e5 m");
    static const char* kFace[6] = {"x-", "x+", "y-", "y+", "z-", "z+"};
    for (int a = 0; a < 3; ++a) {
        const bool lo = boundary[size_t(2 * a)] == Boundary::Periodic, hi = boundary[size_t(2 * a + 1)] == Boundary::Periodic;
        if (!lo && !hi) continue;
        if (a == 2)
            throw Error(std::string("sim grid: boundary ") + kFace[lo ? 4 : 5] +
                        " is periodic; only the x and y face pairs can be (z carries gravity)");
        if (lo != hi)
            throw Error(std::string("sim grid: boundary ") + kFace[2 * a + (lo ? 0 : 1)] + " is periodic but " +
                        kFace[2 * a + (lo ? 1 : 0)] + " is not; both faces of a pair must be periodic");
        const int n = a == 0 ? nx : ny;
        if (n > 1 && n % 2 != 0)
            throw Error(std::string("sim grid: ") + (a == 0 ? "nx" : "ny") + " = " + std::to_string(n) +
                        " along a periodic axis; it must be even");
    }
}

Boundary GridSpec::face(int f) const {
    int n = f < 2 ? nx : f < 4 ? ny : nz;
    return n == 1 ? Boundary::Closed : boundary[size_t(f)];
}

uint64_t simulation_bytes(const GridSpec& spec) { return uint64_t(spec.cells()) * kSimBytesPerCell; }

MacVelocity::MacVelocity(const GridSpec& s, const MemoryBudget* budget) : spec(s) {
    spec.validate();
    size_t nu = size_t(s.nx + 1) * s.ny * s.nz, nv = size_t(s.nx) * (s.ny + 1) * s.nz, nw = size_t(s.nx) * s.ny * (s.nz + 1);
    if (budget) budget->check((nu + nv + nw) * sizeof(float), "sim: MAC velocity");
    u.assign(nu, 0.f);
    v.assign(nv, 0.f);
    w.assign(nw, 0.f);
}

void MacVelocity::enforce_walls() {
    const int nx = spec.nx, ny = spec.ny, nz = spec.nz;
    if (spec.periodic(0))
        for (int k = 0; k < nz; ++k)
            for (int j = 0; j < ny; ++j) u[iu(nx, j, k)] = u[iu(0, j, k)];
    if (spec.periodic(1))
        for (int k = 0; k < nz; ++k)
            for (int i = 0; i < nx; ++i) v[iv(i, ny, k)] = v[iv(i, 0, k)];
    for (int k = 0; k < nz; ++k)
        for (int j = 0; j < ny; ++j) {
            if (spec.face(0) == Boundary::Closed) u[iu(0, j, k)] = 0;
            if (spec.face(1) == Boundary::Closed) u[iu(nx, j, k)] = 0;
        }
    for (int k = 0; k < nz; ++k)
        for (int i = 0; i < nx; ++i) {
            if (spec.face(2) == Boundary::Closed) v[iv(i, 0, k)] = 0;
            if (spec.face(3) == Boundary::Closed) v[iv(i, ny, k)] = 0;
        }
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            if (spec.face(4) == Boundary::Closed) w[iw(i, j, 0)] = 0;
            if (spec.face(5) == Boundary::Closed) w[iw(i, j, nz)] = 0;
        }
}

double MacVelocity::max_abs() const {
    // Max over fixed blocks (order-independent, so any thread count gives the same value).
    const std::vector<float>* arrays[3] = {&u, &v, &w};
    constexpr size_t kBlock = 1 << 16;
    double m = 0;
    for (const auto* a : arrays) {
        std::vector<double> part(block_count(a->size(), kBlock), 0.0);
        parallel_blocks(a->size(), kBlock, [&](size_t n0, size_t n1) {
            double bm = 0;
            for (size_t n = n0; n < n1; ++n) {
                const float x = (*a)[n];
                if (std::isnan(x)) {
                    bm = std::numeric_limits<double>::quiet_NaN();
                    break;
                }
                bm = std::max(bm, double(std::fabs(x)));
            }
            part[n0 / kBlock] = bm;
        });
        for (double x : part) {
            if (std::isnan(x)) return x;
            m = std::max(m, x);
        }
    }
    return m;
}

DivergenceStats divergence_stats(const MacVelocity& vel, const std::vector<double>& rho_cell,
                                 const std::vector<double>& rho_face) {
    const auto& s = vel.spec;
    // Per-slice partial sums added in slice order: same bytes for any thread count.
    std::vector<double> part2(static_cast<size_t>(s.nz)), partmax(static_cast<size_t>(s.nz));
    parallel_for_index(s.nz, [&](int k) {
        const double rc = rho_cell.empty() ? 1.0 : rho_cell[size_t(k)];
        const double rlo = rho_face.empty() ? 1.0 : rho_face[size_t(k)], rhi = rho_face.empty() ? 1.0 : rho_face[size_t(k + 1)];
        double sum2 = 0, mx = 0;
        for (int j = 0; j < s.ny; ++j)
            for (int i = 0; i < s.nx; ++i) {
                double d = rc * (double(vel.u[vel.iu(i + 1, j, k)]) - vel.u[vel.iu(i, j, k)]) +
                           rc * (double(vel.v[vel.iv(i, j + 1, k)]) - vel.v[vel.iv(i, j, k)]) +
                           (rhi * vel.w[vel.iw(i, j, k + 1)] - rlo * double(vel.w[vel.iw(i, j, k)]));
                d /= rc * s.dx;
                sum2 += d * d;
                mx = std::max(mx, std::fabs(d));
            }
        part2[size_t(k)] = sum2;
        partmax[size_t(k)] = mx;
    });
    double sum2 = 0, mx = 0;
    for (int k = 0; k < s.nz; ++k) sum2 += part2[size_t(k)], mx = std::max(mx, partmax[size_t(k)]);
    return {std::sqrt(sum2 / double(s.cells())), mx};
}

DivergenceStats divergence_stats(const MacVelocity& vel) { return divergence_stats(vel, {}, {}); }

} // namespace atlas::sim
