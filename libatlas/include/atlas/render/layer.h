// atlas/render/layer.h - the 2.5D cloudscape ray-marcher: an NDF set (2D
// weather maps) drawn as a cloud layer in a spherical shell over a curved
// Earth, the method of Schneider's GPU Pro 7 chapter "Real-Time Volumetric
// Cloudscapes" (Horizon Zero Dawn) and of his GDC 2022 superstorm talk.
//
// Density at a point p (docs/render.md, "2.5D mode", has the formulas):
// altitude h = |p - C| - R over an Earth of radius R centred below the map
// centre; the set read bilinearly at p's map position; the height fraction
// f = (h - min_height) / (max_height - min_height); the vertical profile
// bottom(bottom_type, f) * top(top_type, f) from the profile LUT; the HZD
// base noise (Perlin-Worley dilated by its Worley FBM) times the profile,
// remapped by coverage, eroded by the curl-distorted detail Worley FBM
// (wispy at the base, billowy above); wind skews the tops and scrolls the
// noise. Lighting is the voxel renderer's (renderer.h): Beer-powder, dual-lobe
// HG, ambient, multiple scattering, with six cone samples plus one long
// sample toward the sun, precipitation thickening the light path; a sky
// gradient, ground, distance haze and optional 2D layers (cirrus) above.
//
// Units: metres, z up; world x, y are the map's coordinates, z = 0 is the
// ground at the map centre. Threading and determinism: fixed 16x16 tiles,
// every pixel a function of its coordinates only: same bytes for any thread
// count.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/progress.h"
#include "atlas/render/renderer.h"

#include <optional>
#include <string>
#include <vector>

namespace atlas::render {

// How the NDF set continues beyond its bounds.
enum class MapEdge {
    Wrap,  // the map tiles (noise-made weather maps tile exactly)
    Clamp, // edge texels extend
    Empty, // no cloud outside the map
};

// A 2D cloud texture on a sphere `altitude` metres up (HZD's high-altitude
// clouds, Far Cry 6's cirrus, Quilez's sky layer), drawn behind the
// volumetric clouds. Opacity = opacity * saturate((v - value_min) /
// (value_max - value_min)), v = channel `channel` at the hit's map position
// (texture tiled every `tile` metres, scrolled by wind * time).
// Cylinder: Far Cry 6's cirrus horizon strip, mapped on a cylinder around the
// camera instead: x is the azimuth (from +x toward +y, the texture's width once
// around), row 0 the horizon, rows up at the width's texel size (v = tan(elevation)
// x width / 2 pi), nothing above the strip; altitude, tile and wind unused.
enum class SkyMapping { Sphere, Cylinder };
struct SkyLayer {
    SkyMapping mapping = SkyMapping::Sphere;
    Field2DPtr texture;
    int channel = 0;
    double altitude = 8000;  // metres above the ground, > 0
    double tile = 20000;     // metres per texture period, > 0
    double value_min = 0, value_max = 1;
    double opacity = 1;      // [0, 1]
    Vec2d wind{{0, 0}};      // m/s
};

// Optional data of the envelope method (Nubis³): empty-space skipping.
//   cone_map      ndf/cone_map robust output (apex_height, cone_ratio) over
//                 the set's bounds, for the cloud tops (max_height channel
//                 where coverage > 0): above the apex a step of
//                 c (z - apex) / (1 - c d_z) (|d_xy| = 1) cannot enter cloud
//   distance_map  ndf/distance_map output: Euclidean distance (metres) to the
//                 nearest solid voxel, over the set's bounds and [z0, z1]
// Either may be null. Both only skip: the image equals plain marching within
// the tolerance stated in docs/render.md.
struct LayerEnvelope {
    Field2DPtr cone_map;
    Field3DPtr distance_map;
};

struct LayerScene {
    // The NDF set: channels found by name, coverage, min_height and
    // max_height required; type (0), top_type / bottom_type (type),
    // precipitation (0) optional. Values must be finite.
    Field2DPtr ndf;
    // ndf/profile_lut: channels bottom, top, density over (type, f),
    // end-aligned texels. Required.
    Field2DPtr profile_lut;
    // noise/hzd_set: low RGBA (Perlin-Worley, 3 Worley FBMs), high RGB
    // (Worley FBMs), curl RG in [0, 1] ([-4, 4] remapped). Null low: the
    // profile and coverage alone (smooth shapes); null high/curl: no erosion
    // / no distortion.
    Field3DPtr base_noise;
    Field3DPtr detail_noise;
    Field2DPtr curl;
    double base_tile = 6000;     // metres per base-noise period
    double detail_tile = 1200;   // metres per detail-noise period
    double curl_tile = 4000;     // metres per curl period
    double curl_amount = 120;    // metres of distortion at the cloud base (1 - f at the top)
    double erosion = 0.2;        // HZD's detail erosion factor (final = remap(base, mod * erosion, 1, 0, 1))
    double density_scale = 1;    // multiplies the final density, >= 0
    double earth_radius = 6360e3; // metres, > 0
    MapEdge edge = MapEdge::Wrap;
    // Wind: direction and speed (m/s) of the flow; time (s) scrolls the map
    // and the noises (detail faster); cloud_top_offset skews the tops by
    // f * offset metres downwind.
    Vec2d wind{{8, 0}};
    double time = 0;
    double cloud_top_offset = 500;
    // Rain clouds: the light path's density is multiplied by
    // 1 + rain_absorption * precipitation (GPU Pro 7 "Rain Clouds").
    double rain_absorption = 2;
    // Ground albedo (linear RGB) lit by sun and sky, shadowed by no cloud.
    Vec3f ground_albedo{{0.05f, 0.075f, 0.1f}}; // a dark sea by default (GPU Pro 7 fig. 4.32)
    // Aerial perspective: clouds and ground fade to the horizon colour over
    // this distance (1 - exp(-t / haze_distance)); 0 = none.
    double haze_distance = 90000;
    LayerEnvelope envelope;
    std::vector<SkyLayer> sky_layers;
    // Optional anvil map (ndf/superstorm_anvil's output): channel
    // "anvil_bias" (else 0) in [0, 1] and optional "anvil_lift" (metres, >= 0)
    // over its own bounds (read bilinearly, clamped, with the map's wind
    // scroll). The anvil rises above the set: where bias > 0 a column's top is
    // max_height + lift (f is measured over the raised column, and the shell's
    // top is the set's highest top plus the map's largest lift), so cloud
    // exists above the set's max_height only where bias > 0 and at most `lift`
    // metres above it. HZD's anvil: in the top of a column coverage becomes
    // coverage^e, e = remap(f, 0.7, 0.8, 1, lerp(1, 0.5, bias)). With a lift,
    // the distance map is not used (it describes the unraised columns); the
    // cone map's apexes are raised by the largest lift.
    Field2DPtr anvil;
    // Optional vortex rings (ndf/vortex_rings' `table`: N x 1 texels with
    // channels inner, outer (m), speed (rad/s), overlap_end (m), optional skew
    // (rad); bounds = centre +- radius; the centre moves with the map's wind
    // scroll). 000's vortex: at `time` and altitude h the noises (base, detail,
    // curl) are read at positions turned by -(speed_i * time + skew_i * phi)
    // about the centre inside ring i, phi = saturate((h - bottom) / (top -
    // bottom)) over the shell of the set (anvil lift not counted): the ring's
    // tendrils tilt, its pattern turning by skew_i from the layer's base to its
    // top. The map (coverage, heights, types) does not turn: the storm keeps its
    // shape while its billows swirl. In ring i's overlap band [outer_i,
    // overlap_end_i] the noise is read at ring i's and ring i+1's turns (past
    // the last ring, at its turn and unturned) and the samples interpolated
    // linearly across the band, so the storm turns faster inside without seams.
    // The envelope stays valid: it bounds the map, which does not turn.
    Field2DPtr vortex_table;
};

// The layer's density model at world points: what render_layer marches (full
// samples: profile, coverage, base noise, detail erosion, wind, anvil, vortex
// rings), for tests and tools. Validates the scene (throws as
// validate_layer_scene). Thread-safe, deterministic.
std::vector<double> layer_density(const LayerScene& scene, const std::vector<Vec3d>& points);
// The cheap shape's density (no detail erosion) at each point averaged over
// the base noise's values: the smooth part of the weather map the sky light's
// occlusion reads (docs/render.md, "Ambient"). Without base noise, the cheap
// density itself. Validates as layer_density.
std::vector<double> layer_mean_density(const LayerScene& scene, const std::vector<Vec3d>& points);
// The altitude range [bottom, top] (metres) of the cloud shell render_layer
// marches: the lowest min_height and highest max_height over texels with
// coverage > 0 and max > min, the top raised by the anvil map's largest lift.
struct LayerShell {
    double bottom = 0, top = 0;
};
LayerShell layer_shell(const LayerScene& scene);

// How far (metres, horizontally) a texel's cloud reaches beyond the texel's
// centre: the bilinear footprint (2 texels), the curl distortion and the tops'
// downwind skew. A patch of the map holds every cloud rooted in it when it is
// grown by this much on each side (the diffusion patch, --export-scene's box).
double layer_reach(const LayerScene& scene);

// Throws atlas::Error naming the problem (null fields, missing channels,
// non-finite values: "channel 'coverage' holds NaN at texel (x, y)", bad
// numbers).
void validate_layer_scene(const LayerScene& scene);

// Throws atlas::Error "WHAT: channel 'c' holds NaN|Inf at texel (x, y)" for
// the first non-finite value (x fastest, channels in order).
void check_finite(const Field2D& f, const std::string& what);
void check_finite(const Field3D& f, const std::string& what);

// Physical mode with ms_diffusion: the side (metres) of the square patch of
// the shell the diffusion term covers (RenderSettings::light_grid voxels
// over it, from the shell's bottom to its top), centred under the camera's
// look-at point when that lies in the shell, else where the view ray meets
// the shell's middle. The grid grows by whole voxels of that size on each
// side to layer_reach (at most an eighth of the side), so it holds every
// cloud rooted in the square (a cloud cut at the patch's edge would lose its
// diffuse light there). Outside it the octaves alone light the clouds.
inline constexpr double kLayerDiffusionPatch = 16000;

struct LayerReport {
    bool base_noise = false, detail_noise = false, curl = false;
    bool cheap_search = true;     // HZD: cheap base-only samples until a cloud is near
    bool cone_skipping = false;   // envelope cone map used
    bool distance_skipping = false;
    bool wind = false;            // non-zero wind or top offset
    bool precipitation = false;   // some precipitation > 0
    bool anvil = false;           // an anvil map with some bias > 0
    bool vortex = false;          // vortex rings turn the storm (table given, time != 0 or some skew != 0)
    int sky_layers = 0;
    int point_lights = 0;         // lights integrated (given + flashes)
    bool sky_gradient = false;
    bool diffusion = false;       // physical model with ms_diffusion: the diffusion term ran over a kLayerDiffusionPatch square (plus layer_reach)
    uint64_t cheap_samples = 0;   // base-only density evaluations (view rays)
    uint64_t full_samples = 0;    // full density evaluations (view rays)
    uint64_t skipped_steps = 0;   // envelope jumps
    double seconds = 0;
    // "curved_earth base_noise detail_erosion curl ..." - space separated.
    std::vector<std::string> active_features() const;
};

struct LayerResult {
    Field2D image; // r, g, b, transmittance as RenderResult
    LayerReport report;
};

// Renders the layer with the camera, sun, sky, size, quality (step scale),
// extinction, phase, ambient, multiple scattering, seed, thread, light and
// light-field settings of `settings` (mode is voxel-only; the light grid
// sets the diffusion patch's resolution in the physical mode, see
// kLayerDiffusionPatch).
// Point lights and flashes (lights.h) light the layer as they light voxels:
// inverse square (5 m core), radius window, Beer from light_samples cheap
// density samples toward the light, dual-lobe HG.
// Throws atlas::Error on a bad setting or scene, and when the camera is
// under the ground ("the camera is 12 m under the ground"); CancelledError
// on cancel.
LayerResult render_layer(const LayerScene& scene, const RenderSettings& settings, const ProgressSink* progress = nullptr);

// Camera presets over the layer (aspect = width / height):
//   Ground  2 m over the ground at the map's south edge + 15 % looking north,
//           pitched up 20 degrees, fov 60
//   Aerial  1.5 km above the highest cloud top, south of the map centre,
//           looking north and down 20 degrees, fov 60
//   Orbit   looking at the cloud mass (centroid of coverage x thickness^2
//           at mid-cloud height) from the given azimuth (0 = from -y,
//           counter-clockwise) and elevation, at a distance that frames
//           one standard deviation of that mass (at least 2 km), fov 50
enum class LayerView { Ground, Aerial, Orbit };
Camera layer_camera(const LayerScene& scene, LayerView view, double aspect, double azimuth_deg = 30, double elevation_deg = 25);

// Lightning over the layer: a flash-probability field (LightField::probability)
// from a 2D map's channel (e.g. the set's superstorm_coverage): one z layer
// spanning [z_min, z_max] metres over the map's bounds, so a flash lands above
// a texel drawn by probability at a uniform height in that range. Throws on a
// bad channel or z_max <= z_min.
Field3DPtr layer_flash_probability(const Field2D& map, int channel, double z_min, double z_max);

// Intersections of the ray o + t d (unit d, t >= 0) with the cloud shell
// between radii r_inner and r_outer around `centre`, stopping at the ground
// sphere of radius r_ground (<= r_inner): up to two [t0, t1] segments in
// order. Returns the number of segments (0..2). The analytic core of the
// curved-Earth march, public for tests and tools.
int shell_segments(const Vec3d& o, const Vec3d& d, const Vec3d& centre, double r_ground, double r_inner, double r_outer, double seg[4]);

// The first t >= 0 where the ray meets the sphere of radius r (from outside
// or inside), or -1.
double ray_sphere_exit_or_hit(const Vec3d& o, const Vec3d& d, const Vec3d& centre, double r);

// Composites a voxel render (in front: its clouds, then its transmittance)
// over a layer render of the same settings: front clouds + T_front * back.
// Both images from render_clouds / render_layer with identical camera,
// size and sky. Throws atlas::Error on mismatched sizes.
Field2D composite_over(const Field2D& front, const Field2D& back, const RenderSettings& settings);

} // namespace atlas::render
