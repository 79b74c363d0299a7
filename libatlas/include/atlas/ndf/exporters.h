// atlas/ndf/exporters.h - NDF data in the layouts game engines read.
//
// Unity HDRP volumetric clouds (manual mode): a cloud map and a cloud LUT.
// Unity HDRP cloud layer: a lat-long RGBA opacity map over a sky dome.
// Unreal Engine volumetric cloud: a documented weather map (no published
// layout exists; docs/formats.md and docs/ndf.md give it and the HLSL).
// Every output is linear data (no sRGB, no premultiplication); texels are
// cell-centred. All functions are pure, thread-safe, and give the same bytes
// for any thread count (rows split over tasks, each texel written once).
//
// Implemented in unity_cloud_map.cpp, unity_cloud_lut.cpp, unity_cloud_layer.cpp, unreal_weather_map.cpp (src/ndf/).
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"
#include "atlas/ndf/vertical_profile.h"

#include <string>

namespace atlas::ndf {

// The engine's cloud layer: altitudes (m, same origin as the set's heights).
// Throws atlas::Error unless both are finite and top > bottom.
struct CloudLayer {
    double bottom = 0;
    double top = 10000;
};

// Unity HDRP manual-mode cloud map, channels r, g, b, a:
// R coverage, G rain (precipitation), B cloud type (copied from the set),
// A = (max_height - layer.bottom) / (layer.top - layer.bottom) clamped to
// [0, 1] (NaN -> 0): HDRP renders a texel only below this normalised height.
// Same resolution and bounds as the set. Throws on a non-NDF-set input.
Field2D unity_cloud_map(const Field2D& set, CloudLayer layer, const MemoryBudget* budget);

// Unity HDRP manual-mode cloud LUT. HDRP samples it bilinearly (clamped) at
// UV (cloud type, height) where height is the normalised height in the whole
// cloud layer, so texel (i, j) holds the analytic value at
// type = (i + 0.5) / types, f = (j + 0.5) / heights (cell-centred):
//   R density   = profile.density(type, f)                       [0,1]
//   G erosion   = 1 - erosion_core * density                     [0,1]
//   B ambient   = 1 - ao_strength * M(type, f)                   [0,1]
// where M(type, f) = integral_f^1 density ds / integral_0^1 density ds is
// the fraction of the column's cloud mass above f (0 for an empty column).
// HDRP multiplies its erosion and shape factors by G and its ambient light
// by B (1 = unoccluded), see docs/ndf.md. Throws on types or heights < 2,
// erosion_core or ao_strength outside [0, 1], or an invalid profile.
struct UnityCloudLutOptions {
    int types = 64;            // texels along u (cloud type)
    int heights = 128;         // texels along v (height in the layer)
    double erosion_core = 0.5; // erosion kept in the densest core: 1 - erosion_core
    double ao_strength = 0.6;  // ambient occlusion under the whole column's mass
};
Field2D unity_cloud_lut(const VerticalProfile& profile, const UnityCloudLutOptions& options, const MemoryBudget* budget);

// The analytic G and B of the LUT at one (type, f) (type, f clamped to [0,1]).
// The mass integral uses composite Simpson with `steps` intervals over [0,1].
double unity_lut_erosion(const VerticalProfile& profile, double erosion_core, double type, double f);
double unity_lut_ambient(const VerticalProfile& profile, double ao_strength, double type, double f, int steps = 4096);

// Max |bilinear LUT lookup - analytic| over all three channels on a grid
// `oversample` times denser than the LUT (cell-centred UV lookup, clamped,
// as HDRP samples it; includes the half-texel borders).
double unity_cloud_lut_max_error(const Field2D& lut, const VerticalProfile& profile, const UnityCloudLutOptions& options,
                                 int oversample = 4);

// Unity HDRP cloud layer (2D): an RGBA lat-long map of opacities
// R cumulus, G stratus, B cirrus, A wispy over a sky dome. The set's XY map
// lies on a flat cloud plane `altitude` metres above an eye at `eye` (world
// XY). Texel (x, y) looks along azimuth phi = 2 pi (x + 0.5) / W (from world
// +X toward +Y) and elevation theta = -pi/2 + pi (y + 0.5) / H, or
// theta = (pi/2) (y + 0.5) / H with upper_hemisphere_only (row 0 at the
// horizon / nadir, the last row at the zenith). Where theta > 0 the ray meets
// the plane at p = eye + (altitude / tan theta) (cos phi, sin phi); the
// channels there (bilinear; wrapped when `tileable`, else 0 outside the map):
//   cumulus = coverage * w, stratus = coverage * (1 - w), w = clamp(1.5 type, 0, 1)
//   (0 at stratus, 1/2 at stratocumulus, 1 from cumulus on),
//   cirrus = channel `cirrus_channel` of `cirrus` (any 2D map over the same
//   world XY, its own resolution; 0 when null), wispy likewise.
// Below the horizon (theta <= 0) every channel is 0. Output bounds are
// degrees: x azimuth [0, 360], y elevation [-90, 90] or [0, 90].
// Throws when altitude <= 0 or not finite, a channel index is out of range,
// or a resolution < 1.
struct UnityCloudLayerOptions {
    Vec2i resolution{{1024, 512}};
    bool upper_hemisphere_only = false;
    double altitude = 3000;   // m above the eye
    Vec2d eye{{0, 0}};        // world XY of the viewer
    bool tileable = false;    // wrap the map beyond its bounds
};
Field2D unity_cloud_layer(const Field2D& set, const Field2D* cirrus, int cirrus_channel, const Field2D* wispy, int wispy_channel,
                          const UnityCloudLayerOptions& options, const MemoryBudget* budget);

// Unreal Engine volumetric cloud weather map (Atlas layout), channels r, g, b, a:
// R coverage, G cloud type (the profile LUT's u), B min_height and A
// max_height normalised in the layer ((h - layer.bottom) / (layer.top -
// layer.bottom), clamped to [0,1], NaN -> 0). The material computes the
// envelope fraction f = (altitude_in_layer - B) / (A - B) and reads the
// profile LUT at (type, f) - docs/ndf.md has the HLSL.
Field2D unreal_weather_map(const Field2D& set, CloudLayer layer, const MemoryBudget* budget);

// Parses the `gradients` text of the profile nodes: 4 entries
// "bottom_start bottom_end top_start top_end" separated by ';' (stratus;
// stratocumulus; cumulus; cumulonimbus). Throws atlas::Error naming the entry.
VerticalProfile parse_profile_gradients(const std::string& text);

} // namespace atlas::ndf
