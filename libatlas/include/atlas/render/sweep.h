// atlas/render/sweep.h - how far the fast render is from the reference.
//
// Renders the reference once, then the fast mode at each quality setting,
// and reports the RMSE of the linear RGB radiance (over all pixels and the
// three channels) and the wall-clock seconds of each render. Deterministic
// images; the seconds naturally vary.
#pragma once

#include "atlas/render/renderer.h"

#include <vector>

namespace atlas::render {

struct SweepRow {
    double quality = 0;       // RenderSettings::quality of the fast render
    double rmse = 0;          // vs the reference, linear radiance
    double transmittance_rmse = 0;
    double seconds = 0;       // fast render time
};

struct SweepResult {
    double reference_seconds = 0;
    std::vector<SweepRow> rows;
    Field2D reference{{{1, 1}}, 1, Box2d{{{0, 0}}, {{1, 1}}}};
};

// RMSE of channels 0..channels-1 between two images of the same size
// (atlas::Error otherwise).
double image_rmse(const Field2D& a, const Field2D& b, int first_channel, int channel_count);

// `settings` gives the camera, size and lighting (its mode and quality are
// overridden); qualities must be non-empty, each in (0, 64].
SweepResult quality_sweep(const CloudScene& scene, const RenderSettings& settings, const std::vector<double>& qualities,
                          const ProgressSink* progress = nullptr);

} // namespace atlas::render
