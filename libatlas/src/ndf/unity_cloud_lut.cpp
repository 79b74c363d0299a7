// Unity HDRP volumetric clouds (manual mode): the cloud LUT (density,
// erosion, ambient) from the vertical profile, and the gradients parser.
#include "atlas/ndf/exporters.h"

#include "atlas/core/error.h"

#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace atlas::ndf {

namespace {
double clamp01(double v) { return std::isnan(v) ? 0.0 : std::clamp(v, 0.0, 1.0); }

// Composite Simpson of the density over [a, b] with n (even) intervals.
double simpson(const VerticalProfile& p, double type, double a, double b, int n) {
    if (!(b > a)) return 0.0;
    const double h = (b - a) / n;
    double s = p.density(type, a) + p.density(type, b);
    for (int k = 1; k < n; ++k) s += (k % 2 ? 4.0 : 2.0) * p.density(type, a + k * h);
    return s * h / 3.0;
}

// Fraction of the column's mass above each of the ascending heights `f`
// (Simpson with `sub` intervals between neighbours), 0 for an empty column.
std::vector<double> mass_above(const VerticalProfile& p, double type, const std::vector<double>& f, int sub) {
    const size_t n = f.size();
    std::vector<double> above(n);
    double acc = simpson(p, type, f[n - 1], 1.0, sub);
    above[n - 1] = acc;
    for (size_t j = n - 1; j-- > 0;) {
        acc += simpson(p, type, f[j], f[j + 1], sub);
        above[j] = acc;
    }
    const double total = acc + simpson(p, type, 0.0, f[0], sub);
    for (double& a : above) a = total > 0 ? std::clamp(a / total, 0.0, 1.0) : 0.0;
    return above;
}

void check_options(const UnityCloudLutOptions& o) {
    if (o.types < 2 || o.heights < 2 || o.types > 8192 || o.heights > 8192)
        throw Error("unity cloud LUT: 'resolution' must be in [2, 8192] x [2, 8192] (types x heights)");
    if (!(o.erosion_core >= 0 && o.erosion_core <= 1)) throw Error("unity cloud LUT: 'erosion_core' must be in [0, 1]");
    if (!(o.ao_strength >= 0 && o.ao_strength <= 1)) throw Error("unity cloud LUT: 'ao_strength' must be in [0, 1]");
}
} // namespace

double unity_lut_erosion(const VerticalProfile& profile, double erosion_core, double type, double f) {
    return 1.0 - erosion_core * profile.density(type, f);
}

double unity_lut_ambient(const VerticalProfile& profile, double ao_strength, double type, double f, int steps) {
    const double ff = clamp01(f);
    const int n = std::max(2, 2 * int(std::ceil(0.5 * steps * (1.0 - ff))));
    const double total = simpson(profile, type, 0.0, 1.0, std::max(2, steps + steps % 2));
    if (!(total > 0)) return 1.0; // an empty column occludes nothing
    const double above = simpson(profile, type, ff, 1.0, n);
    return 1.0 - ao_strength * std::clamp(above / total, 0.0, 1.0);
}

Field2D unity_cloud_lut(const VerticalProfile& profile, const UnityCloudLutOptions& o, const MemoryBudget* budget) {
    profile.validate();
    check_options(o);
    const int W = o.types, H = o.heights;
    Field2D lut({{W, H}}, 3, Box2d{{{0, 0}}, {{1, 1}}}, {"density", "erosion", "ambient"}, budget);
    std::vector<double> fs(static_cast<size_t>(H));
    for (int j = 0; j < H; ++j) fs[size_t(j)] = (j + 0.5) / H;
    parallel_for_index(W, [&](int i) {
        const double t = (i + 0.5) / W;
        const std::vector<double> m = mass_above(profile, t, fs, 32);
        for (int j = 0; j < H; ++j) {
            const double d = profile.density(t, fs[size_t(j)]);
            lut.at(0, i, j) = float(d);
            lut.at(1, i, j) = float(1.0 - o.erosion_core * d);
            lut.at(2, i, j) = float(1.0 - o.ao_strength * m[size_t(j)]);
        }
    });
    return lut;
}

double unity_cloud_lut_max_error(const Field2D& lut, const VerticalProfile& profile, const UnityCloudLutOptions& o, int oversample) {
    if (lut.channels() != 3 || lut.width() < 2 || lut.height() < 2) throw Error("unity cloud LUT error: not a unity cloud LUT");
    const int nu = lut.width() * std::max(1, oversample), nv = lut.height() * std::max(1, oversample);
    std::vector<double> worst(size_t(nu + 1), 0.0);
    std::vector<double> fs(static_cast<size_t>(nv + 1));
    for (int b = 0; b <= nv; ++b) fs[size_t(b)] = double(b) / nv;
    parallel_for_index(nu + 1, [&](int a) {
        const double t = double(a) / nu;
        const std::vector<double> m = mass_above(profile, t, fs, 8);
        for (int b = 0; b <= nv; ++b) {
            const double f = fs[size_t(b)];
            const Vec2d uv{{t, f}};
            const double d = profile.density(t, f);
            double e = std::abs(lut.sample_world(0, uv, WrapMode::Clamp) - d);
            e = std::max(e, std::abs(lut.sample_world(1, uv, WrapMode::Clamp) - (1.0 - o.erosion_core * d)));
            e = std::max(e, std::abs(lut.sample_world(2, uv, WrapMode::Clamp) - (1.0 - o.ao_strength * m[size_t(b)])));
            worst[size_t(a)] = std::max(worst[size_t(a)], e);
        }
    });
    return *std::max_element(worst.begin(), worst.end());
}

VerticalProfile parse_profile_gradients(const std::string& text) {
    VerticalProfile p;
    std::stringstream all(text);
    std::string entry;
    size_t i = 0;
    while (std::getline(all, entry, ';')) {
        std::istringstream in(entry);
        TypeGradient g{};
        std::string rest;
        if (!(in >> g.b0 >> g.b1 >> g.t0 >> g.t1) || (in >> rest))
            throw Error("'gradients' entry " + std::to_string(i + 1) + " must be 4 numbers");
        if (i >= 4) throw Error("'gradients' has more than 4 entries");
        p.types[i++] = g;
    }
    if (i != 4) throw Error("'gradients' needs 4 entries (stratus; stratocumulus; cumulus; cumulonimbus)");
    p.validate();
    return p;
}

} // namespace atlas::ndf
