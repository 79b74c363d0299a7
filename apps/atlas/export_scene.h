// atlas preview --export-scene DIR: the voxel scene for a path tracer
// (scripts/cycles_reference.py renders it in Blender's Cycles).
#pragma once

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

} // namespace atlas::cli
