// Fields resampled onto the solver's grid (atlas/sim/resample.h).
#include "atlas/sim/resample.h"

#include "atlas/core/error.h"

#include <array>
#include <cmath>

namespace atlas::sim {

namespace {

// Whether the field's cells are the grid's, offset by whole cells (`off`):
// then values are copied, not interpolated.
struct Alignment {
    bool aligned = true;
    std::array<long, 3> off{};
};
Alignment alignment(const Field3D& e, const GridSpec& s, const Vec3d& origin) {
    Alignment r;
    for (int a = 0; a < 3; ++a) {
        const double vs = e.voxel_size()[a], o = (e.bounds().min[a] - origin[a]) / s.dx;
        r.off[size_t(a)] = std::lround(o);
        r.aligned = r.aligned && std::fabs(vs - s.dx) <= 1e-9 * s.dx && std::fabs(o - double(r.off[size_t(a)])) <= 1e-6;
    }
    return r;
}

std::vector<float> on_grid_periodic(const Field3D& e, int c, const GridSpec& s, const Vec3d& origin);

} // namespace

std::vector<float> resample_to_grid(const Field3D& e, int c, const GridSpec& s, const Vec3d& origin) {
    for (float v : e.channel(c))
        if (!std::isfinite(v)) throw Error("channel '" + e.channel_name(c) + "' holds NaN/Inf; values must be finite");
    if (s.periodic(0) || s.periodic(1)) return on_grid_periodic(e, c, s, origin);
    std::vector<float> out(s.cells(), 0.f);
    const Box3d& b = e.bounds();
    const auto [aligned, off] = alignment(e, s, origin);
    const Vec3i er = e.resolution();
    size_t n = 0;
    for (int k = 0; k < s.nz; ++k)
        for (int j = 0; j < s.ny; ++j)
            for (int i = 0; i < s.nx; ++i, ++n) {
                if (aligned) {
                    const long x = i - off[0], y = j - off[1], z = k - off[2];
                    if (x < 0 || y < 0 || z < 0 || x >= er[0] || y >= er[1] || z >= er[2]) continue;
                    out[n] = e.at(c, int(x), int(y), int(z));
                    continue;
                }
                const Vec3d p{{origin[0] + (i + 0.5) * s.dx, origin[1] + (j + 0.5) * s.dx, origin[2] + (k + 0.5) * s.dx}};
                bool inside = true;
                for (int a = 0; a < 3; ++a) inside = inside && p[a] >= b.min[a] && p[a] <= b.max[a];
                if (inside) out[n] = e.sample_world(c, p, WrapMode::Clamp);
            }
    return out;
}

namespace {

// resample_to_grid for a grid with periodic x and/or y (resample.h).
std::vector<float> on_grid_periodic(const Field3D& e, int c, const GridSpec& s, const Vec3d& origin) {
    std::vector<float> out(s.cells(), 0.f);
    const Box3d& b = e.bounds();
    const double L[3] = {s.nx * s.dx, s.ny * s.dx, s.nz * s.dx};
    int lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0};
    for (int a = 0; a < 2; ++a)
        if (s.periodic(a)) {
            // Images whose domain copy [origin + m L, origin + (m + 1) L] meets the field's box.
            lo[a] = int(std::floor((b.min[a] - origin[a]) / L[a])) - 1;
            hi[a] = int(std::ceil((b.max[a] - origin[a]) / L[a])) + 1;
        }
    const auto [aligned, off] = alignment(e, s, origin);
    const Vec3i er = e.resolution();
    const int n3[3] = {s.nx, s.ny, s.nz};
    size_t n = 0;
    for (int k = 0; k < s.nz; ++k)
        for (int j = 0; j < s.ny; ++j)
            for (int i = 0; i < s.nx; ++i, ++n) {
                double sum = 0;
                for (int my = lo[1]; my <= hi[1]; ++my)
                    for (int mx = lo[0]; mx <= hi[0]; ++mx) {
                        const int idx[3] = {i + mx * n3[0], j + my * n3[1], k};
                        if (aligned) {
                            const long x = idx[0] - off[0], y = idx[1] - off[1], z = idx[2] - off[2];
                            if (x < 0 || y < 0 || z < 0 || x >= er[0] || y >= er[1] || z >= er[2]) continue;
                            sum += e.at(c, int(x), int(y), int(z));
                            continue;
                        }
                        const Vec3d p{{origin[0] + (idx[0] + 0.5) * s.dx, origin[1] + (idx[1] + 0.5) * s.dx, origin[2] + (k + 0.5) * s.dx}};
                        bool inside = true;
                        for (int a = 0; a < 3; ++a) inside = inside && p[a] >= b.min[a] && p[a] < b.max[a];
                        if (inside) sum += e.sample_world(c, p, WrapMode::Clamp);
                    }
                out[n] = float(sum);
            }
    return out;
}

} // namespace

} // namespace atlas::sim
