// Cirrus textures: three looks in one tileable texture, and the horizon strip.
#include "atlas/ndf/cirrus.h"

#include "atlas/core/error.h"
#include "atlas/ndf/ndf_set.h"
#include "atlas/noise/fill.h"

#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace atlas::ndf {

namespace {
using noise::NoiseSpec;

NoiseSpec make_spec(noise::Kernel k, Vec2i period, int octaves, noise::Combinator comb, uint32_t seed) {
    NoiseSpec s;
    s.kernel = k;
    s.period = Vec3i{{period[0], period[1], 1}};
    s.fractal.octaves = octaves;
    s.fractal.combinator = comb;
    s.seed = seed;
    return s;
}

// Gradient FBM (signed [-1, 1]) mapped to [0, 1].
float unsigned_gradient(float v) { return 0.5f * (v + 1.0f); }

void check_res(Vec2i r, const char* who) {
    if (r[0] < 1 || r[1] < 1 || r[0] > 16384 || r[1] > 16384)
        throw Error(std::string(who) + ": 'resolution' = " + std::to_string(r[0]) + "x" + std::to_string(r[1]) +
                    " is out of range [1, 16384] per axis");
}
void check_unit(double v, const char* who, const char* name) {
    if (!(v >= 0 && v <= 1)) throw Error(std::string(who) + ": '" + name + "' must be in [0, 1]");
}
} // namespace

const std::vector<std::string>& cirrus_channels() {
    static const std::vector<std::string> names = {"cirrostratus", "cirrus", "cirrocumulus"};
    return names;
}

Field2D cirrus_texture(const CirrusSpec& spec, const MemoryBudget* budget) {
    const char* who = "cirrus";
    check_res(spec.resolution, who);
    const int a = spec.streak_direction[0], b = spec.streak_direction[1];
    if ((a == 0 && b == 0) || std::abs(a) > 16 || std::abs(b) > 16)
        throw Error("cirrus: 'streak_direction' must be a non-zero integer vector with |components| <= 16");
    if (spec.period < 1 || spec.period > 256) throw Error("cirrus: 'period' must be in [1, 256]");
    if (spec.stretch < 1 || spec.stretch > 64) throw Error("cirrus: 'stretch' must be in [1, 64]");
    check_unit(spec.warp, who, "warp");

    const int P = spec.period, S = spec.stretch;
    // Rotated coordinates (u along the streaks, v across) are integer
    // combinations of x and y, so a lattice that tiles in (u, v) tiles in (x, y).
    // u spans |a| + |b| tile units per texture: divide the period to keep the feature size.
    const NoiseSpec warp = make_spec(noise::Kernel::Curl, {{P, P}}, 1, noise::Combinator::Fbm, spec.seed + 1);
    const NoiseSpec veil = make_spec(noise::Kernel::Gradient, {{P, P * S}}, 6, noise::Combinator::Fbm, spec.seed + 2);
    const NoiseSpec veil_large = make_spec(noise::Kernel::Value, {{P, P}}, 3, noise::Combinator::Fbm, spec.seed + 3);
    const NoiseSpec fibres = make_spec(noise::Kernel::Gradient, {{P, 2 * P * S}}, 5, noise::Combinator::Ridged, spec.seed + 4);
    const NoiseSpec patches = make_spec(noise::Kernel::Value, {{P, P}}, 3, noise::Combinator::Fbm, spec.seed + 5);
    NoiseSpec puffs = make_spec(noise::Kernel::Worley, {{8 * P, 8 * P}}, 2, noise::Combinator::Fbm, spec.seed + 6);
    puffs.worley.feature = noise::WorleyFeature::InvertedF1;
    puffs.fractal.gain = 0.35;
    const NoiseSpec puff_patches = make_spec(noise::Kernel::Value, {{2 * P, 2 * P}}, 2, noise::Combinator::Fbm, spec.seed + 7);

    const int W = spec.resolution[0], H = spec.resolution[1];
    if (!spec.bounds.valid() || !std::isfinite(spec.bounds.min[0] + spec.bounds.min[1] + spec.bounds.max[0] + spec.bounds.max[1]))
        throw Error("cirrus: 'bounds' must be finite with max > min in x and y");
    Field2D out(spec.resolution, 3, spec.bounds, cirrus_channels(), budget);
    parallel_for_index(H, [&](int y) {
        std::vector<Vec2d> p(static_cast<size_t>(W)), q(static_cast<size_t>(W));
        for (int x = 0; x < W; ++x) p[size_t(x)] = Vec2d{{(x + 0.5) / W, (y + 0.5) / H}};
        const std::vector<float> curl = noise::sample_noise(warp, std::span<const Vec2d>(p));
        // Curl components are O(1) per lattice cell (|c| <= 21, typically < 3): scale to texture widths.
        for (int x = 0; x < W; ++x) {
            const Vec2d w{
                {p[size_t(x)][0] + spec.warp * curl[2 * size_t(x)] / 3.0, p[size_t(x)][1] + spec.warp * curl[2 * size_t(x) + 1] / 3.0}};
            q[size_t(x)] = Vec2d{{a * w[0] + b * w[1], -b * w[0] + a * w[1]}};
        }
        const std::vector<float> v_veil = noise::sample_noise(veil, std::span<const Vec2d>(q));
        const std::vector<float> v_large = noise::sample_noise(veil_large, std::span<const Vec2d>(p));
        const std::vector<float> v_fib = noise::sample_noise(fibres, std::span<const Vec2d>(q));
        const std::vector<float> v_patch = noise::sample_noise(patches, std::span<const Vec2d>(q));
        const std::vector<float> v_puff = noise::sample_noise(puffs, std::span<const Vec2d>(p));
        const std::vector<float> v_pp = noise::sample_noise(puff_patches, std::span<const Vec2d>(p));
        for (int x = 0; x < W; ++x) {
            const size_t i = size_t(x);
            // Veil: broad soft cover with faint streaks.
            const double veil_v = 0.55 * smoothstep(0.2, 0.8, v_large[i]) + 0.45 * unsigned_gradient(v_veil[i]);
            out.at(0, x, y) = float(std::clamp(smoothstep(0.25, 0.85, veil_v), 0.0, 1.0));
            // Fibres: sharp ridges, thinned by patches.
            const double fib = std::pow(double(v_fib[i]), 3.0);
            out.at(1, x, y) = float(std::clamp(fib * smoothstep(0.35, 0.65, v_patch[i]) * 1.6, 0.0, 1.0));
            // Puffs: billowy cells in patches.
            const double puff = smoothstep(0.45, 0.95, v_puff[i]);
            out.at(2, x, y) = float(std::clamp(puff * smoothstep(0.35, 0.6, v_pp[i]), 0.0, 1.0));
        }
    });
    return out;
}

Field2D cirrus_horizon(const CirrusHorizonSpec& spec, const MemoryBudget* budget) {
    const char* who = "cirrus_horizon";
    check_res(spec.resolution, who);
    if (spec.cells_along < 1 || spec.cells_along > 4096) throw Error("cirrus_horizon: 'cells_along' must be in [1, 4096]");
    if (!(spec.cells_up > 0 && spec.cells_up <= 1024)) throw Error("cirrus_horizon: 'cells_up' must be in (0, 1024]");
    if (!(spec.fade_start >= 0 && spec.fade_start < 1)) throw Error("cirrus_horizon: 'fade_start' must be in [0, 1)");
    check_unit(spec.warp, who, "warp");
    const int W = spec.resolution[0], H = spec.resolution[1];
    // y never wraps: the lattice's y period (2048) is far beyond the cells used (<= 1024).
    constexpr int kYPeriod = 2048;
    const double y_scale = spec.cells_up / kYPeriod;
    const NoiseSpec layer = make_spec(noise::Kernel::Gradient, {{spec.cells_along, kYPeriod}}, 6, noise::Combinator::Fbm, spec.seed + 11);
    const NoiseSpec fine =
        make_spec(noise::Kernel::Gradient, {{4 * spec.cells_along, kYPeriod}}, 4, noise::Combinator::Ridged, spec.seed + 12);
    const NoiseSpec warp =
        make_spec(noise::Kernel::Gradient, {{std::max(1, spec.cells_along / 4), kYPeriod}}, 2, noise::Combinator::Fbm, spec.seed + 13);
    Field2D out(spec.resolution, 1, Box2d{{{0, 0}}, {{1, 1}}}, {"cirrus_horizon"}, budget);
    parallel_for_index(H, [&](int y) {
        const double v = (y + 0.5) / H;
        std::vector<Vec2d> p(static_cast<size_t>(W)), q(static_cast<size_t>(W));
        for (int x = 0; x < W; ++x) p[size_t(x)] = Vec2d{{(x + 0.5) / W, v * y_scale}};
        const std::vector<float> w = noise::sample_noise(warp, std::span<const Vec2d>(p));
        for (int x = 0; x < W; ++x) q[size_t(x)] = Vec2d{{p[size_t(x)][0] + spec.warp * w[size_t(x)], p[size_t(x)][1]}};
        const std::vector<float> l = noise::sample_noise(layer, std::span<const Vec2d>(q));
        const std::vector<float> f = noise::sample_noise(fine, std::span<const Vec2d>(q));
        // Denser toward the horizon, 0 at the top.
        const double fade = 1 - smoothstep(spec.fade_start, 1.0, v);
        const double density = 0.75 + 0.25 * (1 - v);
        for (int x = 0; x < W; ++x) {
            const double base = smoothstep(0.35, 0.8, unsigned_gradient(l[size_t(x)]));
            const double detail = 0.6 + 0.4 * f[size_t(x)];
            out.at(0, x, y) = float(std::clamp(base * detail * density * fade, 0.0, 1.0));
        }
    });
    return out;
}

} // namespace atlas::ndf
