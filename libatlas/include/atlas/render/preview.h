// atlas/render/preview.h - one preview for any graph: the pieces `atlas
// preview` and the render/preview node share, so both draw the same picture
// from the same fields (docs/render.md, "One preview for any graph"):
// the 2.5D scene assembled from what a graph writes, the preview's daylight
// look and its sun, and the point-light syntax.
//
// Pure functions, thread-safe, deterministic; errors are atlas::Error.
#pragma once

#include "atlas/core/field.h"
#include "atlas/render/layer.h"
#include "atlas/render/lights.h"
#include "atlas/render/preview_options.h"
#include "atlas/render/renderer.h"

#include <optional>
#include <string>
#include <vector>

namespace atlas::render {

// The preview's sun: kPreviewSunAzimuthDeg / kPreviewSunElevationDeg
// (renderer.h, beside preview_settings).

// What a 2.5D preview is drawn from: the fields a graph writes.
struct LayerPreviewInputs {
    // An NDF set (coverage, min_height, max_height [, type, top_type,
    // bottom_type, precipitation, superstorm_coverage]) or a weather map
    // (coverage [, type, precipitation]: heights 1500..4000 m, type 0.5).
    // Null: an empty cloud layer (sky layers only).
    Field2DPtr ndf;
    Field2DPtr profile_lut;            // ndf/profile_lut; null: the default profile (97 x 128)
    Field3DPtr base_noise, detail_noise; // noise/hzd_set low, high (null: smooth shapes)
    Field2DPtr curl;                   // noise/hzd_set curl
    Field2DPtr anvil;                  // ndf/superstorm_anvil
    Field2DPtr vortex_table;           // ndf/vortex_rings table
    Field2DPtr cone_map;               // ndf/cone_map (robust)
    Field3DPtr distance_map;           // ndf/distance_map
    Field2DPtr cirrus;                 // a field with a 'cirrus' channel: a sky layer at 8 km, opacity 0.8
    Field2DPtr sky_texture;            // a 1-channel texture: a sky layer at 6 km, opacity 0.9 (channel 0)
    Field2DPtr horizon_strip;          // ndf/cirrus_horizon: on a cylinder around the camera (SkyMapping::Cylinder), opacity 0.8
};

// The field's role in a 2.5D preview, by its channels.
bool is_ndf_set(const Field2D& f);     // coverage, min_height, max_height
bool is_weather_map(const Field2D& f); // coverage (and not an NDF set, not a cumulus map)

// A weather map as a layer set: channels coverage, type (else 0.5),
// precipitation (else 0), min_height 1500, max_height 4000 (Far Cry 6's
// preset heights).
Field2DPtr weather_map_as_set(const Field2D& map);

// A sky layer whose opacity ramps from the texture's mean (clear) to two
// standard deviations above it (opaque), drifting at 3, 1 m/s.
SkyLayer sky_layer_from(Field2DPtr texture, int channel, double altitude, double tile, double opacity);

// The 2.5D scene of a preview: the set (a weather map converted), the LUT
// (default when null), noises, anvil, vortex table, envelope maps, sky
// layers (texture tiles: its bounds' width, or 20 km for unit-box
// textures); edge Empty when some superstorm_coverage > 0 (a storm is one
// feature), else Wrap. Validated (throws as validate_layer_scene).
LayerScene layer_preview_scene(const LayerPreviewInputs& in);

// The envelope's cone-step map over the cloud tops (ndf::cone_map, robust):
// heights = max_height where coverage > 0, else 0, max-pooled to at most 128
// texels a side and dilated by one pooled texel (the set is read bilinearly).
Field2DPtr cloud_top_cone_map(const Field2D& set);

// The preview's 2.5D daylight: a w x h image, the layer camera preset (layer_camera
// with azimuth/elevation for Orbit), a blue sky gradient, the preview sun
// with radiance 2.6, 2.45, 2.25 (kilometre clouds are optically thick: lit
// sides stay brighter than the sky), multiple scattering 0.8.
RenderSettings layer_preview_settings(const LayerScene& scene, int width, int height, LayerView view, double azimuth_deg = 30,
                                      double elevation_deg = 20);

// The daylight look of a graph's voxel clouds: the same sky gradient, sun
// and sun radiance as the 2.5D look, multiple scattering 0.3 and ambient 0.7
// (shadowed bases fall to grey under the lit tops).
void apply_voxel_daylight(RenderSettings& s);

// Point lights as text, the one syntax of `atlas preview --light` and the
// render/preview node's `lights`: lights separated by ';', each 7 or 8
// finite numbers "X Y Z R G B INTENSITY [RADIUS]" (metres, linear colour,
// inverse-square intensity, reach; 0 or absent = unlimited) separated by
// commas and/or spaces. Empty items are skipped. Throws atlas::Error quoting
// the bad item (syntax only: the renderer checks the values, validate_light).
std::vector<PointLight> parse_point_lights(const std::string& text);

// ---------------------------------------------------------------------------
// The one library entry of a preview, for `atlas preview` and the render/preview
// node alike: options (PreviewOptions, atlas/render/preview_options.h) in, the
// render calls' settings out, then the picture.

// Whose clouds: a graph's (`atlas preview GRAPH`: voxel clouds get the 2.5D
// daylight look, the auto view is the ground view) or given fields (`atlas preview
// FILES`, the render/preview node: the plain look, the auto view orbits, framing the
// whole volume).
enum class PreviewLook { Fields, Graph };

// A preview ready to render: the scenes with the options applied and the settings
// of every render call.
struct PreviewJob {
    std::optional<CloudScene> voxel; // voxel clouds (over the layer when both are set)
    std::optional<LayerScene> layer; // the 2.5D layer
    RenderSettings settings;
    double exposure = 1.5;           // PNG tone map (tone_map)
    int pixel_size = 1;              // PreviewOptions::pixel_size: settings hold the picture's size
    std::vector<std::string> notes;  // work done on the way, for a log ("envelope: cone map ...")
};

// Applies the options to the scenes (noise_tile; time, wind, earth_radius, edge and
// the envelope of the layer) and builds the settings, in this order: the view preset
// (layer_preview_settings for a layer; the voxel presets of PreviewView), the look,
// the manual camera, the layer's envelope (auto: on when the camera is above the lowest
// cloud base), fov, sun, sky, march, lights, the physical model (artistic off,
// ms_octaves, ms_diffusion, light_grid), flash lights
// (from `flash_probability`, else with `lightning` placed over the layer's set).
// threads: RenderSettings::threads. Throws atlas::Error on invalid options or
// scenes, or when neither scene is given.
PreviewJob prepare_preview(std::optional<CloudScene> voxel, std::optional<LayerScene> layer, const PreviewOptions& options, PreviewLook look,
                           Field3DPtr flash_probability = nullptr, int threads = 0);

// One picture of the job: the layer, the voxel clouds, or the clouds composited
// over the layer (composite_over); the reports of the calls that ran.
struct PreviewFrame {
    Field2D image; // r, g, b linear radiance, transmittance
    std::optional<LayerReport> layer_report;
    std::optional<RenderReport> voxel_report;
};
PreviewFrame render_preview(const PreviewJob& job, const ProgressSink* progress = nullptr);

// The box around the voxels that hold cloud (SDF < 0), or the whole bounds when none
// does: what the voxel view presets frame.
Box3d cloud_bounds(const CloudScene& scene);

} // namespace atlas::render
