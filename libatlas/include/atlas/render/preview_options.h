// atlas/render/preview_options.h - the one schema of the preview's options
// (atlas/core/option_schema.h): `atlas preview`'s render flags and the
// render/preview node's parameters are both built from it, parse through it and
// fill the same PreviewOptions, which the library entry of atlas/render/preview.h
// (prepare_preview) turns into render calls. docs/options.md shows it
// (`atlas options --markdown`); docs/architecture.md, "Option schemas".
#pragma once

#include "atlas/core/math.h"
#include "atlas/core/option_schema.h"
#include "atlas/render/layer.h"
#include "atlas/render/lights.h"
#include "atlas/render/renderer.h"

#include <optional>
#include <span>
#include <string>
#include <utility>
#include <vector>

namespace atlas::render {

// The camera preset of a preview. Auto: for a graph's clouds (PreviewLook::Graph)
// the ground view, for given fields (PreviewLook::Fields) the orbit framing the
// whole volume (voxels) or the layer orbit (2.5D).
enum class PreviewView { Auto, Orbit, Ground, Aerial };
enum class PreviewEnvelope { Auto, On, Off };
// What a plain density grid's values are (a file previewed as it is, not an NVDF).
// Auto: density, unless the densest voxel is under 0.02, which no density grid
// has and cloud water does (a solver's mixing ratio peaks near 0.003 kg/kg).
enum class DensityUnits { Auto, Density, KgPerKg };

// Every option of a preview; the member initializers are the schema's default_text
// (a test checks they agree).
struct PreviewOptions {
    Vec2i size{{960, 540}}; // pixels
    double exposure = 1.5;  // PNG tone map
    PreviewView view = PreviewView::Auto;
    double azimuth = 30, elevation = 20; // orbit: degrees
    bool manual_camera = false;          // camera: manual (position, look_at)
    Vec3d position{{0, -1000, 100}}, look_at{{0, 0, 100}};
    double fov = 0; // degrees; 0 = the view's
    double sun_azimuth = kPreviewSunAzimuthDeg, sun_elevation = kPreviewSunElevationDeg;
    // Unset: the look's (plain: RenderSettings' defaults; daylight: the 2.5D sky and sun).
    std::optional<Vec3f> sun_colour, sky_colour, sky_horizon;
    std::vector<PointLight> lights;
    // Flash lights: from the node's flash_probability field, or (lightning) placed
    // over the 2.5D set's storm, rain or coverage.
    bool lightning = false;
    // A graph's ndf/lightning table (atlas/preview/graph_preview.h): its flashes as lights.
    bool flash_schedule = true;
    int64_t flash_seed = 1, flash_index = 0, flash_count = 1;
    Vec3f flash_colour{{0.75f, 0.8f, 1.0f}};
    double flash_intensity = 1e5, flash_radius = 0;
    RenderMode mode = RenderMode::Fast;
    double quality = 1, extinction = 0.04, noise_tile = 256;
    double sky_occlusion = kPreviewSkyOcclusion; // artistic ambient: share of the optical depth above (RenderSettings)
    // The physical model (docs/render.md, "Reference: Cycles"): artistic false turns
    // it on, with kPhysicalMsOctaves octaves and the diffusion term unless given.
    bool artistic = true;
    std::vector<double> ms_octaves;   // empty, or N [, energy, extinction, anisotropy [, scatter power]]
    std::optional<bool> ms_diffusion; // unset: on under artistic off
    std::optional<int> ms_diffusion_sweeps;
    Vec3i light_grid{{128, 128, 32}};
    // 2.5D
    double time = 0;
    Vec2d wind{{8, 0}};
    double earth_radius = 6360e3;
    std::optional<MapEdge> edge; // unset: layer_preview_scene's choice
    PreviewEnvelope envelope = PreviewEnvelope::Auto;
    DensityUnits density_units = DensityUnits::Auto;
    // Voxel accelerations (RenderSettings::skip_empty_space, use_light_grid).
    bool sdf_skipping = true;
    bool light_lookup_grid = true;
    // Rays per pixel block: 2 marches one ray per 2 x 2 pixels (a quarter of the
    // work) and scales the picture up bilinearly, for interaction.
    int pixel_size = 1;

    bool operator==(const PreviewOptions&) const;
};

// In help order. Thread-safe (a static table).
std::span<const TextOption<PreviewOptions>> preview_options();

// CLI spellings that set several options at once (`--sun AZ,EL` sets sun_azimuth and
// sun_elevation, `--camera X,Y,Z,LX,LY,LZ` camera, position and look_at, ...): each
// splits its text into (option name, text) pairs parsed by those options, so it
// accepts what they accept. Thread-safe (a static table).
struct OptionSpelling {
    const char* cli_flag;
    const char* metavar; // "" for a flag without a value
    std::string doc;
    // The (option, text) pairs of `text`; false when the text is not of the form `metavar`.
    bool (*expand)(std::string_view text, std::vector<std::pair<std::string, std::string>>& out);
};
std::span<const OptionSpelling> preview_cli_spellings();

// The render/preview node's defaults where they differ from the CLI's (option name,
// text): a smaller picture (480x270) beside a graph's textures.
std::span<const std::pair<const char*, const char*>> preview_node_defaults();

// The docs/options.md section of the preview options (`atlas options --markdown`
// appends it): every option with its node parameter, CLI flag (or the spelling that
// sets it), what it accepts, its defaults, unit and doc.
std::string preview_options_markdown();

// Throws atlas::Error for options that contradict each other (ms_octaves or
// ms_diffusion without artistic off) or that no front end lets through (a size
// below 1x1: a host filling PreviewOptions itself).
void check_preview_options(const PreviewOptions& o);

} // namespace atlas::render
