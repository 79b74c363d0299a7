#include "atlas/noise/fill.h"

#include "atlas/core/error.h"
#include "atlas/core/parallel.h"
#include "engine.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>

namespace atlas::noise {
namespace {

using detail::Plan;
using detail::Scratch;

void check_channels(int channels, int channel, int comps) {
    if (channel < 0 || channel + comps > channels)
        throw Error("noise: channel " + std::to_string(channel) + " needs " + std::to_string(comps) +
                    " channel(s) but the field has " + std::to_string(channels));
}

// Base lattice coordinate of voxel i of n, wrapped into [0, period).
inline double voxel_coord(const NoiseSpec& s, int axis, int i, int n) {
    const double p = double(s.period[axis]);
    return detail::wrap_coord(s.offset[axis] + s.frequency * (double(i) + 0.5) / double(n) * p, p);
}

// Stretches the measured min..max of v to out_min..out_max (exact min/max:
// the same for any thread split).
void normalize_channel(std::span<float> v, const OutputParams& o) {
    if (v.empty()) return;
    const auto [mn, mx] = std::minmax_element(v.begin(), v.end());
    const double lo = *mn, hi = *mx;
    const double span = hi - lo;
    parallel_for_each(v.size(), size_t(1) << 16, [&](size_t i) {
        const double t = span > 0 ? (double(v[i]) - lo) / span : 0.0;
        v[i] = float(o.out_min + t * (o.out_max - o.out_min));
    });
}

void check_window(const FillWindow& w, int nx, int ny, const NoiseSpec& spec) {
    if (w.x0 < 0 || w.y0 < 0 || w.x0 + nx > w.full_nx || w.y0 + ny > w.full_ny)
        throw Error("noise: the window does not fit its grid");
    if (spec.output.normalize && (nx != w.full_nx || ny != w.full_ny))
        throw Error("noise: 'normalize' needs the whole field, not a window of it");
}

void report(const ProgressSink* progress, std::atomic<int>& done, int total) {
    if (!progress) return;
    const int d = ++done;
    if (progress->on_progress) progress->on_progress({"noise", double(d) / total, d, total});
}

} // namespace

void fill_noise(Field3D& out, int channel, const NoiseSpec& spec, const ProgressSink* progress, const FillWindow* window) {
    spec.validate(3);
    const int comps = noise_components(spec.kernel, 3);
    check_channels(out.channels(), channel, comps);
    const int nx = out.nx(), ny = out.ny(), nz = out.nz();
    const FillWindow w = window ? *window : FillWindow{0, 0, nx, ny};
    check_window(w, nx, ny, spec);
    // The whole grid's voxel count: a window tabulates what the whole grid does.
    const Plan<3> plan(spec, int64_t(w.full_nx) * w.full_ny * nz);
    std::vector<double> xs(size_t(nx), 0.0);
    for (int i = 0; i < nx; ++i) xs[size_t(i)] = voxel_coord(spec, 0, w.x0 + i, w.full_nx);
    std::atomic<int> done{0};
    // One z-slice per task: fixed work units, results independent of the split.
    parallel_blocks(size_t(nz), 1, [&](size_t z0, size_t z1) {
        Scratch sc;
        std::vector<double> ys(static_cast<size_t>(nx), 0.0), zs(static_cast<size_t>(nx), 0.0);
        for (int z = int(z0); z != int(z1); ++z) {
            if (progress) progress->poll();
            std::fill(zs.begin(), zs.end(), voxel_coord(spec, 2, z, nz));
            for (int y = 0; y < ny; ++y) {
                std::fill(ys.begin(), ys.end(), voxel_coord(spec, 1, w.y0 + y, w.full_ny));
                float* dst[3];
                for (int c = 0; c < comps; ++c) dst[c] = out.channel(channel + c).data() + out.index(0, y, z);
                detail::evaluate<3>(plan, {xs.data(), ys.data(), zs.data()}, size_t(nx), dst, sc);
            }
            report(progress, done, nz);
        }
    });
    if (spec.output.normalize)
        for (int c = 0; c < comps; ++c) normalize_channel(out.channel(channel + c), spec.output);
}

void fill_noise(Field2D& out, int channel, const NoiseSpec& spec, const ProgressSink* progress, const FillWindow* window) {
    spec.validate(2);
    const int comps = noise_components(spec.kernel, 2);
    check_channels(out.channels(), channel, comps);
    const int nx = out.width(), ny = out.height();
    const FillWindow w = window ? *window : FillWindow{0, 0, nx, ny};
    check_window(w, nx, ny, spec);
    const Plan<2> plan(spec, int64_t(w.full_nx) * w.full_ny);
    std::vector<double> xs(size_t(nx), 0.0);
    for (int i = 0; i < nx; ++i) xs[size_t(i)] = voxel_coord(spec, 0, w.x0 + i, w.full_nx);
    std::atomic<int> done{0};
    parallel_blocks(size_t(ny), 1, [&](size_t y0, size_t y1) {
        Scratch sc;
        std::vector<double> ys(static_cast<size_t>(nx), 0.0);
        for (int y = int(y0); y != int(y1); ++y) {
            if (progress) progress->poll();
            std::fill(ys.begin(), ys.end(), voxel_coord(spec, 1, w.y0 + y, w.full_ny));
            float* dst[2];
            for (int c = 0; c < comps; ++c) dst[c] = out.channel(channel + c).data() + out.index(0, y);
            detail::evaluate<2>(plan, {xs.data(), ys.data()}, size_t(nx), dst, sc);
            report(progress, done, ny);
        }
    });
    if (spec.output.normalize)
        for (int c = 0; c < comps; ++c) normalize_channel(out.channel(channel + c), spec.output);
}

namespace {
template <int D, typename P>
std::vector<float> sample_points(const NoiseSpec& spec, std::span<const P> points) {
    spec.validate(D);
    const int comps = noise_components(spec.kernel, D);
    const Plan<D> plan(spec, 0);
    const size_t n = points.size();
    std::array<std::vector<double>, D> u;
    for (int a = 0; a < D; ++a) u[size_t(a)].resize(n);
    for (size_t i = 0; i < n; ++i)
        for (int a = 0; a < D; ++a) {
            const double p = points[i][a];
            if (!std::isfinite(p)) throw Error("noise: sample point " + std::to_string(i) + " is not finite");
            const double per = double(spec.period[a]);
            u[size_t(a)][i] = detail::wrap_coord(spec.offset[a] + spec.frequency * p * per, per);
        }
    std::vector<float> planar(n * size_t(comps));
    float* dst[3] = {planar.data(), planar.data() + n, planar.data() + 2 * n};
    std::array<const double*, D> up;
    for (int a = 0; a < D; ++a) up[size_t(a)] = u[size_t(a)].data();
    Scratch sc;
    detail::evaluate<D>(plan, up, n, dst, sc);
    std::vector<float> r(n * size_t(comps));
    for (size_t i = 0; i < n; ++i)
        for (int c = 0; c < comps; ++c) r[i * size_t(comps) + size_t(c)] = planar[size_t(c) * n + i];
    return r;
}
} // namespace

std::vector<float> sample_noise(const NoiseSpec& spec, std::span<const Vec3d> points) { return sample_points<3>(spec, points); }
std::vector<float> sample_noise(const NoiseSpec& spec, std::span<const Vec2d> points) { return sample_points<2>(spec, points); }

} // namespace atlas::noise
