// atlas/preview/graph_preview.h - the one preview entry for a cooked session or
// files: `atlas preview`, `atlas preview --watch`, Python's Session.preview, the C
// API's atlas_session_preview and the Blender add-on all call it (docs/embedding.md,
// "Previews"). It finds what a graph writes that a preview draws (an NVDF set, an
// NDF set or weather map, sky textures, the storm's tables), cooks those values only
// (no files written) through the session, cooks the built-in noise sets once per
// process, and returns the prepared render job (atlas/render/preview.h).
//
// Errors are atlas::Error naming the graph and what it writes. Deterministic: the
// picture does not depend on `jobs`.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/progress.h"
#include "atlas/graph/evaluator.h"
#include "atlas/render/preview.h"
#include "atlas/render/preview_options.h"

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

namespace atlas::preview {

struct GraphPreviewOptions {
    int jobs = 0; // 0: all hardware threads
    std::optional<std::filesystem::path> cache_dir;
    ProgressSink progress;
    std::string mode = "auto";  // auto | voxel | layer: which of the graph's clouds
    std::string noise = "auto"; // voxel up-rez: auto | nubis | none | a 4-channel volume file
    // A graph's ndf/forecast: the time slice drawn. -1: the forecast is drawn (slice
    // 0) only when the graph writes no other map; `forecast` then asks for it.
    int slice = -1;
    bool forecast = false;
    // Cook at a reduced resolution (CookOptions::proxy): every world-space grid
    // 1/proxy of its cells per axis over the same bounds; 1: full resolution.
    int proxy = 1;
    double voxel = 0; // files without bounds (TGA stacks): metres per voxel
};

struct GraphPreview {
    render::PreviewJob job;
    bool voxel = false, layer = false; // which scenes the job draws
    Field3DPtr forecast;               // an ndf/forecast's maps when a slice of them is drawn
    int slice = 0;
    // The graph file and every file the cook read (what --watch polls).
    std::vector<std::filesystem::path> depends;
    // What happened on the way, for a log: cooks ("graph: cooked 3, cached 9 nodes
    // in 0.21 s"), the noise choice, then the job's notes.
    std::vector<std::string> log;
    double cook_seconds = 0;
};

// The session's graph, cooked for a preview. `graph_file` names the graph in
// messages and `depends` (may be empty for a graph loaded from text).
GraphPreview prepare_graph_preview(Session& session, const render::PreviewOptions& options, const GraphPreviewOptions& how,
                                   const std::filesystem::path& graph_file = {});

// Files (NVDF VDB, plain density VDB or EXR, TGA stacks, DDS) drawn as voxel clouds.
GraphPreview prepare_file_preview(const std::vector<std::filesystem::path>& files, const render::PreviewOptions& options,
                                  const GraphPreviewOptions& how);

// Slice z of a stack of weather maps (ndf/forecast's maps) as a 2D map.
Field2D forecast_slice(const Field3D& maps, int z);

// Prepares and renders in one call: the picture of a session's graph (r, g, b linear
// radiance, transmittance; render::tone_map for 8-bit).
render::PreviewFrame preview_session(Session& session, const render::PreviewOptions& options, const GraphPreviewOptions& how,
                                     const std::filesystem::path& graph_file = {});

// Sets PreviewOptions from (option name, text) pairs as the render/preview node's
// parameters and `atlas preview`'s flags spell them (docs/options.md): "size"
// "640,360", "view" "orbit", "sun_azimuth" "200", ... Throws atlas::Error naming an
// unknown option or a bad value; then checks the whole (check_preview_options).
void set_preview_options(render::PreviewOptions& options, const std::vector<std::pair<std::string, std::string>>& settings);

} // namespace atlas::preview
