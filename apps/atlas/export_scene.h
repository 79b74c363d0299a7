// atlas preview --export-scene DIR: the voxel scene for a path tracer
// (scripts/cycles_reference.py renders it in Blender's Cycles).
#pragma once

#include "atlas/render/layer.h"
#include "atlas/render/renderer.h"

#include <filesystem>

namespace atlas::cli {

// Writes DIR/density.vdb (grid "density": the density the renderer sees,
// sampled at twice the scene's resolution per axis, at most 512) and
// DIR/scene.json (camera, sun, sky, extinction, phase function, image size,
// with the physical units a path tracer needs; docs/render.md, "Reference:
// Cycles"). A scene with up-rez noise is first baked to a plain density grid
// at its own resolution (render::density_scene), and `scene` is replaced by
// that baked scene so the preview that follows draws the exported density.
// Returns a one-line note for stderr.
std::string export_scene(const std::filesystem::path& dir, render::CloudScene& scene, const render::RenderSettings& s);

// The 2.5D layer's scene (docs/render.md, "2.5D against Cycles"): the layer's
// density (render::layer_density, the curved-Earth model render_layer marches)
// baked to a 384^2 x N grid over a square `patch` metres wide centred under
// the camera's look-at point (plus a margin for the bilinear map, the curl
// distortion and the tops' skew), and scene.json as export_scene. `layer` is
// changed so the preview that follows draws what was exported: coverage 0
// outside the patch with MapEdge::Empty, no haze, rain absorption, sky layers
// or envelope maps. Returns a one-line note for stderr.
std::string export_layer_scene(const std::filesystem::path& dir, render::LayerScene& layer, const render::RenderSettings& s, double patch = 16000);

} // namespace atlas::cli
