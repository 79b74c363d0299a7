// Density-height gradients per cloud type, their type blend, and the LUT.
#include "atlas/ndf/vertical_profile.h"
#include "atlas/ndf/ndf_set.h"

#include "atlas/core/error.h"

#include <cmath>

namespace atlas::ndf {

namespace {
const char* const kTypeNames[4] = {"stratus", "stratocumulus", "cumulus", "cumulonimbus"};

double clamp01(double v) { return std::isnan(v) ? 0.0 : std::clamp(v, 0.0, 1.0); }

// The two types bracketing `type` and the weight of the upper one.
void bracket(double type, int& i0, double& w) {
    const double s = clamp01(type) * 3.0;
    i0 = std::min(2, int(std::floor(s)));
    w = s - i0;
}
double rise(const TypeGradient& g, double f) { return smoothstep(g.b0, g.b1, f); }
double fall(const TypeGradient& g, double f) { return 1.0 - smoothstep(g.t0, g.t1, f); }
} // namespace

void VerticalProfile::validate() const {
    for (int i = 0; i < 4; ++i) {
        const auto& g = types[size_t(i)];
        const bool ok = std::isfinite(g.b0) && std::isfinite(g.t1) && 0 <= g.b0 && g.b0 <= g.b1 && g.b1 <= g.t0 && g.t0 <= g.t1 && g.t1 <= 1;
        if (!ok)
            throw Error(std::string("vertical profile: ") + kTypeNames[i] +
                        " gradient must satisfy 0 <= bottom_start <= bottom_end <= top_start <= top_end <= 1");
    }
}

namespace {
// Blends a per-type gradient `g(type_gradient, f)` between the two types that bracket `type`.
template <typename Gradient>
double blend_types(const std::array<TypeGradient, 4>& types, double type, double f, Gradient g) {
    int i;
    double w;
    bracket(type, i, w);
    const double ff = clamp01(f);
    return (1 - w) * g(types[size_t(i)], ff) + w * g(types[size_t(i + 1)], ff);
}
} // namespace

double VerticalProfile::bottom(double type, double f) const { return blend_types(types, type, f, rise); }

double VerticalProfile::top(double type, double f) const { return blend_types(types, type, f, fall); }

double VerticalProfile::density(double type, double f) const {
    return blend_types(types, type, f, [](const TypeGradient& g, double ff) { return rise(g, ff) * fall(g, ff); });
}

double VerticalProfile::split(double top_type, double bottom_type, double f) const { return bottom(bottom_type, f) * top(top_type, f); }

Field2D build_profile_lut(const VerticalProfile& profile, int types, int heights, const MemoryBudget* budget) {
    profile.validate();
    if (types < 2 || heights < 2) throw Error("profile LUT: 'resolution' must be at least 2 x 2 (types x heights)");
    Field2D lut({{types, heights}}, 3, Box2d{{{0, 0}}, {{1, 1}}}, {"bottom", "top", "density"}, budget);
    for (int j = 0; j < heights; ++j) {
        const double f = double(j) / (heights - 1);
        for (int i = 0; i < types; ++i) {
            const double t = double(i) / (types - 1);
            lut.at(0, i, j) = float(profile.bottom(t, f));
            lut.at(1, i, j) = float(profile.top(t, f));
            lut.at(2, i, j) = float(profile.density(t, f));
        }
    }
    return lut;
}

double sample_profile_lut(const Field2D& lut, int channel, double type, double f) {
    const double u = 0.5 + clamp01(type) * (lut.width() - 1);
    const double v = 0.5 + clamp01(f) * (lut.height() - 1);
    return lut.sample_texel(channel, u, v, WrapMode::Clamp);
}

double profile_lut_max_error(const Field2D& lut, const VerticalProfile& profile, int oversample) {
    if (lut.channels() != 3 || lut.width() < 2 || lut.height() < 2) throw Error("profile LUT error: not a profile LUT");
    const int nu = (lut.width() - 1) * std::max(1, oversample), nv = (lut.height() - 1) * std::max(1, oversample);
    double err = 0;
    for (int j = 0; j <= nv; ++j) {
        const double f = double(j) / nv;
        for (int i = 0; i <= nu; ++i) {
            const double t = double(i) / nu;
            err = std::max(err, std::abs(sample_profile_lut(lut, 0, t, f) - profile.bottom(t, f)));
            err = std::max(err, std::abs(sample_profile_lut(lut, 1, t, f) - profile.top(t, f)));
            err = std::max(err, std::abs(sample_profile_lut(lut, 2, t, f) - profile.density(t, f)));
        }
    }
    return err;
}

} // namespace atlas::ndf
