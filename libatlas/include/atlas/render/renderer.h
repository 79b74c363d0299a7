// atlas/render/renderer.h - the Nubis³-style CPU voxel cloud ray-marcher.
//
// Method (Schneider, "Nubis³", SIGGRAPH 2023; docs/render.md has formulas):
// march each view ray between the volume bounds, stepping by
// max(SDF, adaptive step growing with distance) with a per-pixel jitter;
// density only where SDF < 0, up-rezzed from the dimensional profile with
// the noise (wispy/billowy composites by detail type, twice-folded noise near
// the camera, value erosion, density scale, sharpening power); direct light
// from two explicit samples toward the sun plus a precomputed voxel light
// grid, Beer's law with the powder term, dual-lobe Henyey-Greenstein;
// ambient from the profile attenuated by summed density toward the sky; the
// multiple-scattering approximation from the profile. Optional point lights
// and lightning-flash lights (lights.h: inverse square, a few density
// samples toward each light, the same phase function) and a zenith-to-horizon
// sky gradient; without them that code does not run and the bytes are those
// of the renderer before they existed.
//
// Reference mode is the same integrator with small fixed steps, no SDF
// skipping, fully marched light and sky rays and no light grid.
//
// Threading and determinism: the image is split into fixed 16x16 tiles run
// by TBB; every pixel depends only on its own coordinates (jitter comes from
// hash_coords(seed, x, y)), so any thread count gives the same bytes.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/progress.h"
#include "atlas/render/lights.h"
#include "atlas/render/scene.h"

#include <optional>
#include <string>
#include <vector>

namespace atlas::render {

enum class RenderMode {
    Fast,      // SDF skipping, adaptive steps, voxel light grid
    Reference, // small fixed steps, marched light rays, no grid
};

// Octaves of multiple scattering the CLI's --artistic off uses.
inline constexpr int kPhysicalMsOctaves = 8;
// The octaves' extinction factor (RenderSettings::ms_extinction) the CLI's
// --artistic off uses beside the diffusion term (the octaves alone keep 0.5).
inline constexpr double kPhysicalMsExtinctionWithDiffusion = 0.75;

struct RenderSettings {
    Camera camera;
    Vec3d sun_direction{{0.4, -0.6, 0.5}}; // toward the sun, normalised internally
    Vec3f sun_colour{{1.0f, 0.95f, 0.88f}};   // linear radiance, >= 0
    // The sky: sky_colour at the zenith; with sky_horizon set, the
    // background is lerp(horizon, zenith, saturate(view.z)) and the ambient
    // term uses the cosine-weighted upper-hemisphere mean of that gradient,
    // horizon + 2/3 (zenith - horizon). Unset: one uniform colour (the
    // pre-gradient look, same bytes). Linear radiance, >= 0.
    Vec3f sky_colour{{0.30f, 0.45f, 0.75f}};
    std::optional<Vec3f> sky_horizon;
    int width = 320;                          // pixels, > 0
    int height = 180;                         // pixels, > 0
    RenderMode mode = RenderMode::Fast;
    // Fast mode: scales the step count (2 = half the step length), > 0.
    double quality = 1;
    // Extinction per metre at density 1, >= 0.
    double extinction = 0.04;
    // Dual-lobe HG: w * HG(g_forward) + (1 - w) * HG(g_back).
    double hg_forward = 0.6, hg_back = -0.3, hg_forward_weight = 0.7;
    double ambient_strength = 1.0;  // >= 0
    // Artistic lighting: the ambient's occlusion by the density above a
    // sample, exp(-sky_occlusion x tau_up). 1 is Beer along the vertical; sky
    // light arrives from the whole hemisphere and scatters on into the cloud,
    // so the preview's look relaxes it (0.1: lobes under an overhang stay
    // blue-grey, where 1 drew them black). >= 0; 0 = the talk's
    // sqrt(1 - profile) alone.
    double sky_occlusion = 1.0;
    double multiple_scattering = 0.5; // strength of the profile-based term, >= 0
    // Voxel light grid resolution (fast mode; the talk's is 256x256x32). Its
    // z is raised so cells are no taller than wide, and each axis capped at
    // twice the volume's resolution (at the volume's own where the diffusion
    // term solves on the grid).
    Vec3i light_grid{{128, 128, 32}};
    // Fast mode's accelerations, each switchable so that a test can show what
    // it changes: skip_empty_space, the SDF's sphere tracing (it walks the
    // march's own steps over the empty ball, so the picture is the same
    // bytes); use_light_grid, sun and sky optical depths looked up in the
    // light grid (off: marched light rays, as the reference mode does).
    bool skip_empty_space = true;
    bool use_light_grid = true;
    // Reference mode step (metres); 0 = a quarter of the smallest voxel.
    double reference_step = 0;
    // Stop a ray once its transmittance falls below this, [0, 1).
    double min_transmittance = 0.005;
    uint32_t seed = 1;
    int threads = 0; // 0 = TBB default; results do not depend on it
    // Optional lights (lights.h). Empty (the default): no light code runs.
    // light_fields are resolved to point lights (flash_lights) per render.
    std::vector<PointLight> lights;
    std::vector<LightField> light_fields;
    // Fast mode: density samples on the segment toward each point light
    // (reference mode marches it at 2 x reference_step), 1..64.
    int light_samples = 4;
    // The artistic terms of the Nubis lighting: the powder darkening, the
    // dimensional-profile multiple-scattering term and the in-scatter
    // probability sqrt(1 - profile) on the ambient. false: the physical model
    // a path tracer computes (docs/render.md, "Reference: Cycles"): albedo 1,
    // direct sun = Beer x phase, multiple scattering from ms_octaves, the sky
    // in-scattered as its radiance times the transmittance toward it (single
    // scattering) or fully (ms_octaves > 0: a conservative medium under a
    // uniform sky is as bright as the sky). multiple_scattering and
    // ambient_strength still scale the two terms.
    bool artistic = true;
    // Physical mode: octaves of the multiple-scattering series (Wrenninge,
    // "Art-directable multiple volumetric scattering", 2015): octave n >= 1
    // adds ms_energy^n x Beer(ms_extinction^n tau) x phase with both g
    // scaled by ms_anisotropy^n. 0 = single scattering only, 0..16.
    // The octaves are weighted by q^ms_scatter_power, q = 1 - e^-(tau_sun +
    // tau_zenith) the probability of scattering again (docs/render.md,
    // "Calibration against Cycles"), ms_scatter_power in [0, 8].
    int ms_octaves = 0;
    double ms_energy = 0.5, ms_extinction = 0.5, ms_anisotropy = 0.5; // each in [0, 1]
    double ms_scatter_power = 1;
    // Physical mode: multiple scattering in optically thick media by the
    // diffusion approximation on the light grid (docs/render.md, "Multiple
    // scattering by diffusion"): the fluence of the once-scattered sun light,
    // -div(D grad phi) = sigma_s T_sun E, D = 1 / (3 sigma_t (1 - g)),
    // Marshak boundaries, ms_diffusion_sweeps red-black SOR sweeps per level
    // of a coarse-to-fine cascade (1..4096). Per sample the multiply
    // scattered sun light is the larger of the octaves' and the diffusion's
    // P1 in-scattered radiance sigma_s (phi + 3 g F . w) / (4 pi)
    // (F = -D grad phi + g / (1 - g) T (-sun): the first scatter's forward
    // peak; w toward the eye); multiple_scattering scales it. Inside the
    // grid the sky's colour is lerp(horizon, zenith, the sky field's
    // weight) instead of the sphere's mean (the same grid solves the sky's
    // light coming in through the medium's faces). The 2.5D mode
    // solves it over a 16 km patch of its shell and the clouds' reach past
    // it (layer.h, kLayerDiffusionPatch).
    // Needs ms_octaves > 0 and multiple_scattering > 0; ignored with
    // artistic = true. false: the octaves alone (the bytes of the renderer
    // before it existed). The CLI's --artistic off turns it on.
    bool ms_diffusion = false;
    int ms_diffusion_sweeps = 32;
    // With ms_diffusion: the light the clouds shed onto each other (two
    // bounces, traced through the light grid) adds to the diffusion's source
    // (docs/render.md, "The light clouds shed onto each other"). Library
    // knob for comparisons; the CLI keeps it on.
    bool ms_inter_cloud = true;
};

// Which parts of the method ran (features the scene does not need are left
// out and listed as off) and how much work it took.
struct RenderReport {
    bool noise_uprez = false;      // noise given
    bool billowy = false;          // detail_type > 0 somewhere
    bool near_camera_detail = false; // twice-folded noise (camera within 198 m of the volume)
    bool sdf_skipping = false;     // fast mode
    bool light_grid = false;       // fast mode
    bool point_lights = false;     // at least one point light (given or from a light field)
    int point_light_count = 0;     // lights integrated (after resolving light fields)
    bool sky_gradient = false;     // sky_horizon set
    bool physical = false;         // artistic = false: the physical model (no powder, octave multiple scattering)
    bool diffusion = false;        // physical model with ms_diffusion: the diffusion term ran
    uint64_t density_samples = 0;  // view-ray density evaluations
    // "noise_uprez billowy ..." - the active features, space separated.
    std::vector<std::string> active_features() const;
};

// Image channels: "r", "g", "b" linear radiance of the pixel (clouds over
// the sky) and "transmittance" (1 = no cloud along the ray). Field y = 0 is
// the bottom row (io::write_image orientation); bounds [0,w] x [0,h].
struct RenderResult {
    Field2D image;
    RenderReport report;
};

// Renders the scene. Throws atlas::Error naming the setting on a bad
// setting (zero-size image, non-finite camera, fov outside (0, 180), ...),
// CancelledError when progress asks to stop. progress may be null; its
// callbacks are called from worker threads.
RenderResult render_clouds(const CloudScene& scene, const RenderSettings& settings, const ProgressSink* progress = nullptr);

} // namespace atlas::render

namespace atlas::render {

// The preview's sun (degrees, sun_direction's convention: azimuth 0 = from
// -y, counter-clockwise; elevation above the horizon): low in the south-west,
// so side and back light show the billows. preview_settings(), the preview
// looks of atlas/render/preview.h (the CLI) and the render/preview node's
// sun_azimuth / sun_elevation defaults all use it (docs/DECISIONS.md,
// 2026-12-02). RenderSettings' own default direction is unchanged.
inline constexpr double kPreviewSunAzimuthDeg = 230;
inline constexpr double kPreviewSunElevationDeg = 25;
// The preview's ambient occlusion by the density above (RenderSettings::
// sky_occlusion): relaxed as the sun's multiple scattering is (2026-12-07).
inline constexpr double kPreviewSkyOcclusion = 0.1;

// Settings for a w x h preview of a volume with these bounds: the default
// framing camera (framing_camera with its defaults), the preview sun
// (kPreviewSun*), the preview's sky occlusion (kPreviewSkyOcclusion), the
// default sky, fast mode. Throws atlas::Error on a
// non-positive size.
RenderSettings preview_settings(const Box3d& bounds, int width, int height);

// The density the voxel renderer sees (after the noise up-rez, without the
// near-camera detail; 0 outside the SDF), sampled at the voxel centres of a
// res grid over the scene's bounds: one channel "density" (extinction per
// metre = RenderSettings::extinction x density). For exporting the scene to
// another renderer (scripts/cycles_reference.py). Throws atlas::Error on a
// resolution outside 1..2048 per axis or an invalid scene.
Field3D sample_density(const CloudScene& scene, Vec3i res);

// A scene the voxel renderer draws with exactly `density` (channel 0, >= 0)
// at its voxel centres: no noise, detail type 0, the dimensional profile and
// density scale chosen so the renderer's sharpening power returns the value,
// an SDF that is inside everywhere (no empty-space skipping). Between voxel
// centres the renderer interpolates the profile, not the density.
CloudScene density_scene(const Field3D& density);

} // namespace atlas::render
