// atlas/noise/loop.h - noise that loops in time as well as tiling in space
// (issue 43 item 3): a cross-faded loop, not a 4D-periodic noise.
//
// The field at loop phase p in [0, 1] crossfades the noise shifted by p * D
// (a) with the noise shifted by (p - 1) * D (b), weight p on b. Phase 0 is the
// unshifted noise, phase 1 again the unshifted noise (b at 0 shift), so a phase
// keyed from 0 to 1 over a loop's time plays a seamless loop; between, the
// pattern drifts by D and is replaced by the next one. Spatial tiling is kept
// (a shift of a periodic noise is periodic). A plain crossfade of two
// independent-looking fields has half the variance at p = 1/2 (the loop would
// pulse); the blend is rescaled about the pair's mean by 1 / sqrt((1-p)^2 + p^2)
// and clamped to the pair's range, so contrast holds through the loop.
#pragma once

#include <span>

namespace atlas::noise {

// a <- the loop's value at `phase` from a (shifted by phase * D) and b (by
// (phase - 1) * D), element by element; a and b the same size. Throws
// atlas::Error when the sizes differ or phase is outside [0, 1].
void loop_crossfade(std::span<float> a, std::span<const float> b, double phase);

} // namespace atlas::noise
