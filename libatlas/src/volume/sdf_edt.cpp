// Exact EDT to sub-voxel crossing points.
//
// The crossing points lie on grid edges, so each has exactly one fractional
// coordinate. Points whose fractional coordinate is along axis a ("family a")
// are handled by an exact separable transform: a 1D nearest-point pass along
// a (fractional positions), then Felzenszwalb-Huttenlocher lower envelopes of
// parabolas along the two other axes (integer sites). The squared distance to
// all crossings is the minimum over the three families.
#include "atlas/core/memory.h"
#include "atlas/core/parallel.h"
#include "atlas/core/progress.h"
#include "atlas/volume/sdf.h"
#include "line_passes.h"
#include "edt_core.h"
#include "surface_crossings.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <chrono>
#include <limits>
#include <vector>

namespace atlas::volume {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Lower envelope of parabolas (p - q)^2 * h2 + f(q) over integer sites q.
// f may be +inf (no site). Scratch: v (sites), z (boundaries).
void envelope(const float* f, float* out, int n, double h2, std::vector<int>& v, std::vector<double>& z) {
    v.resize(size_t(n));
    z.resize(size_t(n) + 1);
    int k = -1;
    for (int q = 0; q < n; ++q) {
        if (f[q] == kInf) continue;
        const double fq = double(f[q]) / h2 + double(q) * q;
        double s = 0;
        while (k >= 0) {
            const int p = v[size_t(k)];
            s = (fq - (double(f[p]) / h2 + double(p) * p)) / (2.0 * (q - p));
            if (s <= z[size_t(k)]) --k;
            else break;
        }
        ++k;
        v[size_t(k)] = q;
        z[size_t(k)] = k == 0 ? -std::numeric_limits<double>::infinity() : s;
        z[size_t(k) + 1] = std::numeric_limits<double>::infinity();
    }
    if (k < 0) {
        std::fill(out, out + n, kInf);
        return;
    }
    int j = 0;
    for (int q = 0; q < n; ++q) {
        while (z[size_t(j) + 1] < q) ++j;
        const int p = v[size_t(j)];
        const double e = double(q - p);
        out[q] = float(e * e * h2 + double(f[p]));
    }
}

} // namespace

namespace detail {

std::vector<float> squared_distance_to_line_seeds(Vec3i res, Vec3d h, const LineSeedFn& seed_fn, unsigned long long* seed_count) {
    const size_t count = size_t(res[0]) * size_t(res[1]) * size_t(res[2]);
    std::vector<float> work(count), best(count, kInf);
    std::atomic<unsigned long long> crossings{0};
    for (int a = 0; a < 3; ++a) {
        const double ha2 = h[a] * h[a];
        // 1D pass along the family axis: nearest seed on the line.
        detail::for_each_line(res, a, work.data(), work.data(), [&](const float*, float* w, int n, size_t base) {
            thread_local std::vector<double> seeds;
            seeds.clear();
            seed_fn(a, base, n, seeds);
            if (seeds.empty()) {
                std::fill(w, w + n, kInf);
                return;
            }
            crossings.fetch_add(seeds.size(), std::memory_order_relaxed);
            size_t j = 0;
            for (int i = 0; i < n; ++i) {
                while (j + 1 < seeds.size() && std::abs(i - seeds[j + 1]) <= std::abs(i - seeds[j])) ++j;
                const double e = i - seeds[j];
                w[i] = float(e * e * ha2);
            }
        });
        for (int b = 0; b < 3; ++b) {
            if (b == a) continue;
            const double hb2 = h[b] * h[b];
            detail::for_each_line(res, b, work.data(), work.data(), [&](const float* f, float* w, int n, size_t) {
                thread_local std::vector<int> v;
                thread_local std::vector<double> z;
                envelope(f, w, n, hb2, v, z);
            });
        }
        parallel_blocks(count, size_t(1) << 16, [&](size_t i0, size_t i1) {
            for (size_t i = i0; i < i1; ++i) best[i] = std::min(best[i], work[i]);
        });
    }
    if (seed_count) *seed_count = crossings.load();
    return best;
}

} // namespace detail

Field3D sdf_from_density_edt(const Field3D& density, const SdfOptions& o, const MemoryBudget* budget, SdfStats* stats,
                             const ProgressSink* progress) {
    const auto t0 = std::chrono::steady_clock::now();
    detail::check_density(density, o, "sdf (edt)");
    if (!std::isfinite(o.max_distance) || o.max_distance < 0)
        throw Error("sdf (edt): max_distance must be finite and >= 0, got " + std::to_string(o.max_distance));
    const Vec3i res = density.resolution();
    const size_t count = density.voxel_count();
    if (budget) budget->check(field_bytes(count, 3), "sdf (edt): output and two scratch grids");
    if (progress) progress->poll();
    Field3D out(res, 1, density.bounds(), {"sdf"}, budget);
    const float iso = float(o.iso);
    const float* dens = density.channel(o.channel).data();
    const size_t stride[3] = {1, size_t(res[0]), size_t(res[0]) * size_t(res[1])};
    const bool border = o.border_is_outside;
    auto seeds = [&](int a, size_t base, int n, std::vector<double>& out_seeds) {
        const size_t st = stride[a];
        auto d = [&](int i) { return dens[base + size_t(i) * st]; };
        // The grid's faces only: a crop's inner faces have the rest of the grid beyond them.
        if (border && o.grid_faces[size_t(2 * a)] && detail::is_inside(d(0), iso)) out_seeds.push_back(-0.5);
        bool prev = detail::is_inside(d(0), iso);
        for (int i = 0; i + 1 < n; ++i) {
            const bool next = detail::is_inside(d(i + 1), iso);
            if (prev != next) out_seeds.push_back(i + detail::crossing_t(d(i), d(i + 1), iso));
            prev = next;
        }
        if (border && o.grid_faces[size_t(2 * a + 1)] && detail::is_inside(d(n - 1), iso)) out_seeds.push_back(n - 0.5);
    };
    unsigned long long crossings = 0;
    // A crop of a larger grid uses the whole grid's voxel edge: its own bounds
    // (TileWindow::edge) may differ from the grid's arithmetic in the last bit.
    const Vec3d h = o.grid_voxel_size[0] > 0 ? o.grid_voxel_size : density.voxel_size();
    std::vector<float> best = detail::squared_distance_to_line_seeds(res, h, seeds, &crossings);
    if (progress) progress->poll();
    const bool clip = o.max_distance > 0;
    const float far = clip ? float(o.max_distance) : float(detail::far_value(density, o));
    auto sdf = out.channel(0);
    parallel_blocks(count, size_t(1) << 16, [&](size_t i0, size_t i1) {
        for (size_t i = i0; i < i1; ++i) {
            const bool in = detail::is_inside(dens[i], iso);
            float d = best[i] == kInf ? far : std::sqrt(best[i]);
            if (clip) d = std::min(d, far);
            sdf[i] = in ? -d : d;
        }
    });
    if (stats) {
        stats->crossings = crossings;
        stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    return out;
}

} // namespace atlas::volume
