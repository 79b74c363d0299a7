#include "atlas/noise/loop.h"

#include "atlas/core/error.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace atlas::noise {

void loop_crossfade(std::span<float> a, std::span<const float> b, double phase) {
    if (a.size() != b.size()) throw Error("noise loop: the two shifted fields differ in size");
    if (!(phase >= 0 && phase <= 1)) throw Error("noise loop: phase must be in [0, 1], got " + std::to_string(phase));
    if (a.empty() || phase == 0) return;
    if (phase == 1) {
        std::copy(b.begin(), b.end(), a.begin());
        return;
    }
    // The pair's mean and range, summed in a fixed order (deterministic).
    double sum = 0;
    float lo = a[0], hi = a[0];
    for (size_t i = 0; i < a.size(); ++i) {
        sum += double(a[i]) + double(b[i]);
        lo = std::min({lo, a[i], b[i]});
        hi = std::max({hi, a[i], b[i]});
    }
    const double mean = sum / (2.0 * double(a.size()));
    const double w = phase, k = 1.0 / std::sqrt((1 - w) * (1 - w) + w * w);
    for (size_t i = 0; i < a.size(); ++i) {
        const double v = mean + ((1 - w) * (double(a[i]) - mean) + w * (double(b[i]) - mean)) * k;
        a[i] = std::clamp(float(v), lo, hi);
    }
}

} // namespace atlas::noise
