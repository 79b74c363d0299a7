#include "atlas/render/image_out.h"

#include "atlas/core/error.h"

#include <cmath>
#include <string>

namespace atlas::render {

namespace {
float srgb(float x) { return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f; }
} // namespace

Field2D tone_map(const Field2D& linear, double exposure) {
    if (!(exposure > 0) || !std::isfinite(exposure)) throw Error("render: exposure must be finite and > 0, got " + std::to_string(exposure));
    if (linear.channels() < 3) throw Error("render: tone_map needs 3 colour channels, got " + std::to_string(linear.channels()));
    Field2D out(linear.resolution(), 3, linear.bounds(), {"r", "g", "b"});
    for (int c = 0; c < 3; ++c) {
        auto src = linear.channel(c);
        auto dst = out.channel(c);
        for (size_t i = 0; i < src.size(); ++i) {
            float x = src[i];
            x = std::isfinite(x) && x > 0 ? x * static_cast<float>(exposure) : 0.0f;
            dst[i] = srgb(x / (1.0f + x));
        }
    }
    return out;
}

} // namespace atlas::render
