// atlas/render/scene.h - what the preview renderer draws: an NVDF set, its
// signed distance field and the up-rez noise, viewed by a camera under a sun.
//
// Units: world metres (the fields' bounds), directions are unit vectors in
// world space (z up), colours are linear RGB radiance (arbitrary scale; the
// PNG tone map exposes for 1.0 = white). All types are plain values; a const
// scene may be rendered from any number of threads.
#pragma once

#include "atlas/core/field.h"

#include <optional>
#include <string>

namespace atlas::render {

// The voxel cloud: Nubis modeling NVDF plus field data (docs/volumes.md).
//   modeling  channels dimensional_profile, detail_type, density_scale
//             (found by name, else channels 0, 1, 2), values nominally [0, 1]
//   sdf       signed distance in metres (negative inside), channel "sdf" or 0;
//             must share modeling's resolution and bounds
//   noise     optional Nubis noise volume, 4 channels (r, g = low/high
//             frequency wispy, b, a = low/high frequency billowy) in [0, 1],
//             tiling every noise_tile metres; fewer channels repeat the
//             last one. Null: no up-rez (density = dimensional profile).
//   uniform_detail_type, uniform_density_scale
//             when set (finite), that modeling channel is this value
//             everywhere and the field need not hold it (then modeling
//             may be the profile alone): a plain density grid's detail
//             type 0 and density scale S (scene_from_fields) cost no 67 MB
//             channel of one value each at 512x512x64.
struct CloudScene {
    Field3DPtr modeling;
    Field3DPtr sdf;
    Field3DPtr noise;
    double noise_tile = 256; // metres per noise period, > 0
    std::optional<float> uniform_detail_type;
    std::optional<float> uniform_density_scale;
    // Set for a plain density grid (measured or simulated data, not a modelled
    // NVDF): its densest voxel. Such data is previewed as it is (no up-rez by
    // default: it has its own detail, and erosion made foam of it) and its
    // units are read (PreviewOptions::density_units).
    std::optional<float> density_grid_max;
    // The SDF stored once per sdf_block^3 voxels of the modeling grid (a power of two, 1..64):
    // resolution ceil(n / sdf_block) per axis over the modeling's bounds, voxel
    // (x, y, z) reading block (x / b, y / b, z / b). A density grid's SDF is
    // constant over its blocks (render::load_scene): stored so, it takes 1/8 of
    // the memory and samples to the same values as broadcast to every voxel.
    int sdf_block = 1;
    // The SDF's interpolated value at any point is at most the distance to the
    // nearest non-zero density (a density grid's SDF is built so): the light
    // tables then skip the samples within that distance unread. An NVDF's SDF,
    // interpolated from distances at voxel centres (or 8-bit field data), need
    // not be, and its tables read every sample.
    bool sdf_is_lower_bound = false;
};

// A scene from one 4-channel "vdb_set" field (volume/nvdf's output, or
// volume::read_nubis_vdb): channels dimensional_profile, detail_type,
// density_scale, sdf. Throws atlas::Error naming a missing channel.
CloudScene scene_from_nvdf_set(Field3DPtr vdb_set, Field3DPtr noise = nullptr, double noise_tile = 256);

// Checks the scene (non-null fields, matching grids, the modeling channels
// that are not uniform present, finite uniform values, finite noise_tile >
// 0); throws atlas::Error naming the problem.
void validate_scene(const CloudScene& scene);

// Pinhole camera. fov_deg is the vertical field of view in degrees (0, 180);
// up is the world up hint (must not be parallel to look_at - position).
struct Camera {
    Vec3d position{{0, 0, 0}};
    Vec3d look_at{{0, 1, 0}};
    Vec3d up{{0, 0, 1}};
    double fov_deg = 50;
};

// A camera that frames `bounds` from outside: looking at its centre from the
// south-west-above at `elevation_deg`, `azimuth_deg` (0 = from -y, growing
// counter-clockwise seen from above), far enough that the whole box fits a
// `fov_deg` vertical field of view for the given aspect (width / height).
Camera framing_camera(const Box3d& bounds, double aspect, double azimuth_deg = 30, double elevation_deg = 20, double fov_deg = 50);

// Unit direction toward the sun from azimuth and elevation in degrees
// (elevation 0 = horizon, negative = below).
Vec3d sun_direction(double azimuth_deg, double elevation_deg);

} // namespace atlas::render

#include <vector>

namespace atlas::render {

// One field of a scene, and the name its errors carry (the file it came from).
struct SceneField {
    Field3DPtr field;
    std::string name;
};

// A scene from fields Atlas (or the Nubis pack) wrote, as io::read_field_file
// reads them (the caller reads the files: render works on memory):
//   one file   a VDB or EXR with channels dimensional_profile, detail_type,
//              density_scale, sdf (volume/nvdf's vdb_set), or a single
//              density channel (e.g. a float grid "density", as vdb_render
//              reads): density_scene's mapping (the sampled density is the
//              grid's) with an SDF for empty-space skipping (-min voxel in
//              the cells next to non-zero voxels, elsewhere a lower bound on
//              the distance to them); modeling is the profile alone (the
//              grid's own storage), detail type and density scale uniform
//   two files  the modeling NVDF (named channels, else the first three:
//              a TGA slice stack STEM.001.tga is R, G, B), then the SDF:
//              channel "sdf" in metres, or encoded field data ("field_data",
//              or a TGA stack's R) decoded d = v * 4352 - 256 metres.
// voxel_size > 0 (metres) replaces the bounds of files that carry none
// (images, TGA stacks: [0, n] per axis) with [0, n * voxel_size]; 0 keeps
// the files' bounds. Throws atlas::Error naming the field and the problem.
// A single density grid held by nothing else is used in place (no copy).
CloudScene scene_from_fields(std::vector<SceneField> fields, double voxel_size = 0);

} // namespace atlas::render
