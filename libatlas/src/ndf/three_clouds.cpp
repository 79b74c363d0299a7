// @takram/three-clouds layout of an NDF set and the preview's noises.
#include "atlas/ndf/three_clouds.h"

#include "atlas/core/error.h"
#include "atlas/core/parallel.h"
#include "atlas/ndf/hzd_shape.h"
#include "atlas/ndf/vertical_profile.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace atlas::ndf {

namespace {

constexpr std::array<const char*, 4> kTypeNames{"stratus", "stratocumulus", "cumulus", "cumulonimbus"};
constexpr std::array<char, 4> kChannels{'r', 'g', 'b', 'a'};

float saturate(double v) { return float(std::clamp(v, 0.0, 1.0)); }

// Where one type's profile bottom * top is at least half its largest value
// [lo, hi] (Atlas's clouds fill about that much of a covered column: its
// coverage threshold cuts the faded ends), and where it peaks (the middle of
// the values within 1 % of the largest).
struct Support {
    double lo = 0, hi = 1, peak = 0.5;
};

Support type_support(const Field2D& lut, int bottom, int top, double type) {
    constexpr int n = 1024;
    std::vector<double> p(n + 1);
    double best = 0;
    for (int i = 0; i <= n; ++i) {
        const double f = double(i) / n;
        p[size_t(i)] = sample_profile_lut(lut, bottom, type, f) * sample_profile_lut(lut, top, type, f);
        best = std::max(best, p[size_t(i)]);
    }
    Support s;
    if (!(best > 0.01)) return s;
    int lo = n, hi = 0, plo = n, phi = 0;
    for (int i = 0; i <= n; ++i) {
        if (p[size_t(i)] >= 0.5 * best) lo = std::min(lo, i), hi = std::max(hi, i);
        if (p[size_t(i)] >= 0.99 * best) plo = std::min(plo, i), phi = std::max(phi, i);
    }
    s.lo = double(lo) / n;
    s.hi = double(hi) / n;
    s.peak = 0.5 * double(plo + phi) / n;
    return s;
}

} // namespace

double three_clouds_bias_for_peak(double peak) {
    // x = eta^b, 1 - (2x - 1)^2 is largest at x = 1/2.
    const double eta = std::clamp(peak, 0.05, 0.95);
    return std::log(0.5) / std::log(eta);
}

ThreeCloudsWeather three_clouds_weather(const Field2D& set, const Field2D& profile_lut, const MemoryBudget* budget) {
    // Channels by name, as the 2.5D preview reads them: a weather map made a set
    // (render::weather_map_as_set) has no top/bottom types.
    const int ccov = set.find_channel("coverage"), clo = set.find_channel("min_height"), chi = set.find_channel("max_height"),
              ctype = set.find_channel("type");
    if (ccov < 0 || clo < 0 || chi < 0)
        throw Error("three-clouds weather: expected an NDF set or weather map with channels coverage, min_height and max_height "
                    "(type optional; ndf/set makes one)");
    const int cb = profile_lut.find_channel("bottom"), ct = profile_lut.find_channel("top");
    if (cb < 0 || ct < 0) throw Error("three-clouds weather: the profile LUT has no 'bottom' and 'top' channels (ndf/profile_lut)");
    std::array<ThreeCloudsLayer, 4> layers;
    double min_height = 0, max_height = 0, spread = 0;
    const auto cov = set.channel(ccov), lo = set.channel(clo), hi = set.channel(chi);
    const std::vector<float> no_type(ctype < 0 ? cov.size() : 0, 0.0f);
    const std::span<const float> type = ctype < 0 ? std::span<const float>(no_type) : set.channel(ctype);
    double w = 0, sum_lo = 0, sum_hi = 0;
    for (size_t i = 0; i < cov.size(); ++i) {
        if (!(cov[i] > 0) || !(hi[i] > lo[i])) continue;
        w += cov[i];
        sum_lo += double(cov[i]) * lo[i];
        sum_hi += double(cov[i]) * hi[i];
    }
    if (!(w > 0)) throw Error("three-clouds weather: the NDF set has no cloud (no texel with coverage > 0 and max_height > min_height)");
    min_height = sum_lo / w;
    max_height = sum_hi / w;
    for (size_t i = 0; i < cov.size(); ++i) {
        if (!(cov[i] > 0) || !(hi[i] > lo[i])) continue;
        spread = std::max({spread, std::abs(lo[i] - min_height), std::abs(hi[i] - max_height)});
    }
    const double envelope = max_height - min_height;
    for (int k = 0; k < 4; ++k) {
        ThreeCloudsLayer& l = layers[size_t(k)];
        l.channel = kChannels[size_t(k)];
        l.name = kTypeNames[size_t(k)];
        l.type = k / 3.0;
        const Support s = type_support(profile_lut, cb, ct, l.type);
        l.altitude = min_height + s.lo * envelope;
        l.height = (s.hi - s.lo) * envelope;
        l.shape_altering_bias = three_clouds_bias_for_peak(s.hi > s.lo ? (s.peak - s.lo) / (s.hi - s.lo) : 0.5);
    }

    ThreeCloudsWeather out{Field2D(set.resolution(), 4, set.bounds(), {"r", "g", "b", "a"}, budget), layers, min_height, max_height, spread};
    std::array<std::span<float>, 4> ch{out.weather.channel(0), out.weather.channel(1), out.weather.channel(2), out.weather.channel(3)};
    parallel_for_each(cov.size(), 4096, [&](size_t i) {
        const double c = std::isfinite(cov[i]) ? std::clamp(double(cov[i]), 0.0, 1.0) : 0.0;
        const double t = std::isfinite(type[i]) ? std::clamp(double(type[i]), 0.0, 1.0) : 0.0;
        for (int k = 0; k < 4; ++k) ch[size_t(k)][i] = float(c) * saturate(2.0 * (1.0 - std::abs(3.0 * t - k)));
    });
    for (int k = 0; k < 4; ++k)
        out.layers[size_t(k)].used = std::any_of(ch[size_t(k)].begin(), ch[size_t(k)].end(), [](float v) { return v > 0; });
    return out;
}

Field3D three_clouds_shape(const Field3D& base_noise, const MemoryBudget* budget) {
    if (base_noise.channels() < 4) throw Error("three-clouds shape: the base noise needs 4 channels (noise/hzd_set low), got " +
                                               std::to_string(base_noise.channels()));
    auto r = base_noise.channel(0), g = base_noise.channel(1), b = base_noise.channel(2), a = base_noise.channel(3);
    std::vector<float> base(r.size());
    parallel_for_each(r.size(), 4096, [&](size_t i) {
        base[i] = float(dilated_base(r[i], g[i], b[i], a[i])); // the 2.5D preview's base shape
    });
    std::vector<float> sorted = base;
    std::sort(sorted.begin(), sorted.end());
    Field3D out(base_noise.resolution(), 1, base_noise.bounds(), {"shape"}, budget);
    auto s = out.channel(0);
    const double n = double(sorted.size());
    parallel_for_each(base.size(), 4096, [&](size_t i) {
        // Mid-rank of the value: ties share one.
        const auto range = std::equal_range(sorted.begin(), sorted.end(), base[i]);
        s[i] = float((double(range.first - sorted.begin()) + double(range.second - sorted.begin())) * 0.5 / n);
    });
    return out;
}

Field3D three_clouds_shape_detail(const Field3D& detail_noise, const MemoryBudget* budget) {
    if (detail_noise.channels() < 3) throw Error("three-clouds detail: the detail noise needs 3 channels (noise/hzd_set high), got " +
                                                 std::to_string(detail_noise.channels()));
    Field3D out(detail_noise.resolution(), 1, detail_noise.bounds(), {"detail"}, budget);
    const auto r = detail_noise.channel(0), g = detail_noise.channel(1), b = detail_noise.channel(2);
    auto d = out.channel(0);
    parallel_for_each(d.size(), 4096, [&](size_t i) { d[i] = saturate(worley_fbm(r[i], g[i], b[i])); });
    return out;
}

Field2D three_clouds_turbulence(const Field2D& curl, const MemoryBudget* budget) {
    if (curl.channels() < 2) throw Error("three-clouds turbulence: the curl field needs 2 channels, got " + std::to_string(curl.channels()));
    Field2D out(curl.resolution(), 3, curl.bounds(), {"r", "g", "b"}, budget);
    const auto x = curl.channel(0), y = curl.channel(1);
    std::fill(out.channel(0).begin(), out.channel(0).end(), 0.5f);
    std::copy(x.begin(), x.end(), out.channel(1).begin());
    std::copy(y.begin(), y.end(), out.channel(2).begin());
    return out;
}

} // namespace atlas::ndf
