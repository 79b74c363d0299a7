// atlas/preview/web_view.h - a graph's 2.5D cloudscape as a page that
// @takram/three-clouds (three.js) draws in real time: `atlas view GRAPH`.
//
// Writes, into one folder (committed atomically; a failure leaves nothing):
//   local_weather.png  the NDF set in three-clouds' weather layout (ndf/three_clouds.h)
//   shape.bin          128^3 bytes, the equalised base shape; x fastest
//   shape_detail.bin   32^3 bytes, the detail FBM
//   turbulence.png     the curl as three-clouds' turbulence texture
//   scene.json         layers, texture repeats and offsets, camera, sun, and what
//                      of Atlas's model the layout keeps (docs/web.md)
//   scene.js           the same scene with the textures inlined as data URLs
//   index.html, atlas_view.js, atmosphere.js   the page (plugins/web/dist)
// The page opens from disk (no server). The volumes are in the engine's axis order:
// three-clouds stacks its shape volume along Earth-centred axes, which at the
// scene's place (latitude 0, longitude 0) are up, east, north; so byte
// i + 128 (j + 128 k) holds Atlas's (x = j, y = k, z = i).
//
// Errors are atlas::Error: a graph with no 2.5D layer, a missing page bundle
// (plugins/web not built), noise volumes of other sizes than three-clouds reads.
#pragma once

#include "atlas/preview/graph_preview.h"

#include <filesystem>
#include <string>
#include <vector>

namespace atlas::preview {

struct WebViewOptions {
    // The built page: index.html, atlas_view.js, atmosphere.js (plugins/web/dist).
    std::filesystem::path bundle_dir;
    std::string title; // shown on the page
};

struct WebViewResult {
    std::filesystem::path index; // out_dir/index.html
    std::vector<std::string> log; // what the layout kept and dropped, for the CLI
};

// The folder for `preview` (prepare_graph_preview with a 2.5D layer), drawn with
// the camera and sun of `options` (the same flags as atlas preview).
WebViewResult write_web_view(const GraphPreview& preview, const render::PreviewOptions& options,
                             const std::filesystem::path& out_dir, const WebViewOptions& how);

// Where the built page is: $ATLAS_WEB_DIR when set (only there), else
// `exe_dir`/../share/atlas/web, else the source tree's plugins/web/dist. Throws
// atlas::Error naming where it looked and how to build it.
std::filesystem::path find_web_bundle(const std::filesystem::path& exe_dir);

} // namespace atlas::preview
