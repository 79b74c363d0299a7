// Value erosion by fractal value noise (the Nubis remap erosion).
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/noise/value_fbm.h"
#include "atlas/volume/edit.h"

#include "atlas/core/parallel.h"
#include "occupied_span.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace atlas::volume {

Field3D erode_by_noise(const Field3D& density, const ErosionOptions& o, const MemoryBudget* budget, const GridFrame* frame) {
    if (o.channel < 0 || o.channel >= density.channels()) throw Error("erode_by_noise: channel " + std::to_string(o.channel) + " does not exist");
    if (!(o.amount >= 0 && o.amount <= 1)) throw Error("erode_by_noise: amount must be in [0, 1]");
    if (!(o.frequency > 0) || !std::isfinite(o.frequency)) throw Error("erode_by_noise: frequency must be finite and > 0 (cells per metre)");
    if (o.octaves < 1 || o.octaves > 12) throw Error("erode_by_noise: octaves must be in [1, 12]");
    if (budget) budget->check(density.byte_size(), "erode_by_noise: the density copy");
    // The noise is laid over the whole grid (a tiled cook's crop is a window of it).
    const GridFrame fr = frame ? *frame : density.frame();
    const Vec3d h = fr.voxel_size();
    const Vec3d ext = fr.bounds.size();
    for (int a = 0; a < 3; ++a)
        if (ext[a] * o.frequency * std::ldexp(1.0, o.octaves - 1) > 1e7)
            throw Error("erode_by_noise: frequency x extent is too large (over 1e7 noise cells per axis)");
    Field3D out = density;
    // Gain 0.5 (octave weights 2^-k / sum); octave k at frequency 2^k.
    const noise::ValueFbm fbm{.octaves = o.octaves, .gain = 0.5, .seed = o.seed, .seed_step = 0x9E3779B9u};
    const std::vector<float> weights = noise::fbm_weights(fbm);
    // A voxel whose density is +0 stays +0 whatever the noise ((0 - e) / (1 - e) clamps to
    // +0), and most of a cloudscape is empty: the noise is evaluated only over each row's
    // span from its first to its last other voxel (a window of the same row: same values).
    const std::span<const float> in = density.channel(o.channel);
    parallel_for_index(density.nz(), [&](int z) {
        std::vector<float> acc(size_t(density.nx())), scratch;
        for (int y = 0; y < density.ny(); ++y) {
            const float* row = in.data() + density.index(0, y, z);
            // Not a structured binding: clang 14 cannot capture one in the lambda below.
            const std::pair<int, int> occ = detail::occupied_span(row, density.nx());
            const int x_lo = occ.first, x_hi = occ.second;
            if (x_lo == x_hi) continue; // the copy holds the row already
            const std::span<float> span(acc.data(), size_t(x_hi - x_lo));
            noise::value_fbm_row(span, fbm, weights, [&](int k) {
                const double f = o.frequency * std::ldexp(1.0, k);
                // Period in cells: the extent, so the noise tiles on the bounds
                // when frequency * extent is an integer.
                noise::FbmRow r;
                r.period = {{std::max(1, int(std::lround(ext[0] * f))), std::max(1, int(std::lround(ext[1] * f))),
                             std::max(1, int(std::lround(ext[2] * f)))}};
                r.x0 = 0.5 * h[0] * f;
                r.dx = h[0] * f;
                r.first = fr.offset[0] + x_lo;
                r.y = ((y + fr.offset[1]) + 0.5) * h[1] * f;
                r.z = ((z + fr.offset[2]) + 0.5) * h[2] * f;
                return r;
            }, scratch);
            for (int x = x_lo; x < x_hi; ++x) {
                const double e = o.amount * std::clamp(double(acc[size_t(x - x_lo)]), 0.0, 1.0);
                float& d = out.at(o.channel, x, y, z);
                d = e >= 1 ? 0.0f : float(std::clamp((double(d) - e) / (1 - e), 0.0, 1.0));
            }
        }
    });
    return out;
}

} // namespace atlas::volume
