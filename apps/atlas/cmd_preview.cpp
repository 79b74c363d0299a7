// atlas preview (GRAPH | FILES...): render an NVDF set with the preview
// ray-marcher (libatlas/render) to PNG or EXR; --sweep prints fast-vs-
// reference error and time per quality; --turntable writes N frames.
#include "cli.h"
#include "export_scene.h"
#include "progress_bar.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "atlas/graph/evaluator.h"
#include "atlas/io/exr.h"
#include "atlas/io/image.h"
#include "atlas/io/readers.h"
#include "atlas/ndf/cone_map.h"
#include "atlas/render/image_out.h"
#include "atlas/render/layer.h"
#include "atlas/render/preview.h"
#include "atlas/render/preview_options.h"
#include "atlas/render/renderer.h"
#include "atlas/render/sweep.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <limits>
#include <thread>
#include <optional>
#include <sstream>
#include <variant>

namespace atlas::cli {

namespace {

std::vector<double> numbers(const std::string& text, size_t count, const std::string& option) {
    std::vector<double> v;
    std::stringstream ss(text);
    std::string part;
    while (std::getline(ss, part, ',')) {
        try {
            size_t used = 0;
            v.push_back(std::stod(part, &used));
            if (used != part.size()) throw std::invalid_argument(part);
        } catch (const std::exception&) {
            throw UsageError{option + " expects numbers separated by commas, got '" + text + "'", "preview"};
        }
    }
    if (v.size() != count) throw UsageError{option + " expects " + std::to_string(count) + " comma-separated numbers, got '" + text + "'", "preview"};
    return v;
}

bool is_graph(const std::string& f) {
    auto ext = std::filesystem::path(f).extension().string();
    return ext == ".yaml" || ext == ".yml" || ext == ".atlas";
}

// What a graph writes that the preview can draw, found by cooking (values
// only, through the cache like `atlas cook`) the graph's outputs:
//   volume/nvdf vdb_set                    -> voxel mode
//   a 2D field with coverage, min_height, max_height (an NDF set) -> 2.5D mode
//   a 2D field with coverage only (a weather map)      -> 2.5D, heights 1500..4000 m
//   a 2D field with bottom, top (ndf/profile_lut)      -> the layer's profile LUT
//   a 2D field with anvil_bias (ndf/superstorm anvil)  -> the storm's anvil spread
//   ndf/vortex_rings' table (inner, outer, speed, ...)  -> the storm turns with --time
//   a 2D field with apex_height, cone_ratio (ndf/cone_map) / ndf/distance_map -> envelope
//   a 2D field with a 'cirrus' channel (ndf/cirrus)    -> a cirrus layer at 8 km
//   otherwise the last 1-channel 2D field               -> a sky layer at 6 km (Quilez)
struct GraphContent {
    Field3DPtr nvdf;
    Field2DPtr ndf, lut, cone, cirrus, sky2d, anvil, vortex;
    Field3DPtr distance;
    Field3DPtr forecast; // ndf/forecast maps: z = time slice, channels coverage, precipitation, type, ...
    std::string ndf_node;
    std::vector<std::string> written; // "node 'n' (type) port 'p' -> file"
    std::vector<std::filesystem::path> depends; // the graph file and every file the cook read (--watch)
};

void apply_sets(Session& s, const Args& a) {
    for (const auto& kv : a.all("--set")) {
        auto eq = kv.find('=');
        auto dot = kv.find('.');
        if (eq == std::string::npos || dot == std::string::npos || dot > eq)
            throw UsageError{"--set expects NODE.PARAM=VALUE, got '" + kv + "'", "preview"};
        s.set_text(kv.substr(0, dot), kv.substr(dot + 1, eq - dot - 1), kv.substr(eq + 1));
    }
}

bool has_channels(const Field2D& f, std::initializer_list<const char*> names) {
    for (const char* n : names)
        if (f.find_channel(n) < 0) return false;
    return true;
}

GraphContent cook_graph(Session& session, const std::string& file, int jobs, ProgressSink progress,
                        const std::optional<std::filesystem::path>& cache_dir, bool quiet) {
    GraphContent g;
    struct Want {
        std::string node, port, type, file;
        bool generic; // a PortType::Field port: 2D or 3D, known only once cooked
    };
    std::vector<Want> wants;
    for (const auto& out : session.graph().outputs) {
        const GraphNode* n = session.graph().find(out.node);
        if (!n) continue;
        const NodeType* t = session.registry().find(n->type);
        if (!t || t->decl.outputs().empty()) continue;
        const PortDecl* port = out.port.empty() ? &t->decl.outputs().front() : t->decl.find_output(out.port);
        if (!port) continue;
        g.written.push_back("node '" + out.node + "' (" + n->type + ") port '" + port->name + "' -> " + out.file);
        const bool nvdf = n->type == "volume/nvdf" && port->name == "vdb_set";
        const bool dist = n->type == "ndf/distance_map";
        const bool forecast = port->type == PortType::Field3D && n->type.rfind("ndf/", 0) == 0;
        if (nvdf || dist || forecast || port->type == PortType::Field2D || port->type == PortType::Field)
            wants.push_back({out.node, port->name, n->type, out.file, port->type == PortType::Field && !nvdf && !dist});
    }
    // Two passes: typed outputs first; generic field outputs (which may be
    // large volumes) only when nothing drawable was found.
    for (int pass = 0; pass < 2; ++pass) {
        std::vector<const Want*> now;
        for (const auto& w : wants)
            if (w.generic == (pass == 1)) now.push_back(&w);
        if (now.empty()) continue;
        if (pass == 1 && (g.nvdf || g.ndf || g.cirrus || g.sky2d)) break;
        CookOptions o;
        o.write_outputs = false;
        o.jobs = jobs;
        o.cache_dir = cache_dir;
        o.progress = progress;
        for (const Want* w : now) o.outputs.push_back(w->file);
        const CookResult r = session.cook(o);
        for (const auto& d : r.depends(file))
            if (std::find(g.depends.begin(), g.depends.end(), d) == g.depends.end()) g.depends.push_back(d);
        if (!quiet)
            std::fprintf(stderr, "graph: cooked %zu, cached %zu nodes in %.2f s%s\n", r.with_status("cooked").size(), r.with_status("cached").size(),
                         r.seconds, cache_dir ? (" (cache " + cache_dir->string() + ")").c_str() : "");
        for (const Want* wp : now) {
            const Want& w = *wp;
            Value v = session.get(w.node, w.port, o); // from the session's memory cache now
            const std::string what = file + ": node '" + w.node + "' output '" + w.port + "'";
            if (auto* f3 = std::get_if<Field3DPtr>(&v); f3 && *f3) {
                if (w.type == "volume/nvdf" && !g.nvdf) render::check_finite(**f3, what), g.nvdf = *f3;
                else if (w.type == "ndf/distance_map" && !g.distance) render::check_finite(**f3, what), g.distance = *f3;
                else if ((*f3)->find_channel("coverage") >= 0 && !g.forecast) render::check_finite(**f3, what), g.forecast = *f3;
                continue;
            }
            auto* f2 = std::get_if<Field2DPtr>(&v);
            if (!f2 || !*f2) continue;
            const Field2D& f = **f2;
            if (render::is_ndf_set(f) || render::is_weather_map(f)) {
                render::check_finite(f, what);
                if (!g.ndf) g.ndf = *f2, g.ndf_node = w.node; // a weather map becomes a set in render::layer_preview_scene
            } else if (has_channels(f, {"inner", "outer", "speed", "overlap_end"})) {
                render::check_finite(f, what);
                if (!g.vortex) g.vortex = *f2;
            } else if (has_channels(f, {"anvil_bias"})) {
                render::check_finite(f, what);
                g.anvil = *f2; // the last one written: the end of a stencil chain
            } else if (has_channels(f, {"bottom", "top"})) {
                if (!g.lut) g.lut = *f2;
            } else if (has_channels(f, {"apex_height", "cone_ratio"})) {
                if (!g.cone) g.cone = *f2;
            } else if (has_channels(f, {"cirrus"})) {
                render::check_finite(f, what);
                if (!g.cirrus) g.cirrus = *f2;
            } else if (f.channels() == 1 && w.type.rfind("volume/", 0) != 0) {
                // (A volume node's 2D output is a picture of the volume, e.g.
                // volume/projection's top view, not a sky texture.)
                render::check_finite(f, what);
                g.sky2d = *f2; // the last one written
            }
        }
    }
    return g;
}

// Slice z of a stack of weather maps (ndf/forecast's maps) as a 2D map.
Field2D forecast_slice(const Field3D& f, int z) {
    const Box3d& b = f.bounds();
    Field2D m({{f.nx(), f.ny()}}, f.channels(), Box2d{{{b.min[0], b.min[1]}}, {{b.max[0], b.max[1]}}}, f.channel_names());
    for (int c = 0; c < f.channels(); ++c)
        for (int y = 0; y < f.ny(); ++y)
            for (int x = 0; x < f.nx(); ++x) m.at(c, x, y) = f.at(c, x, y, z);
    return m;
}

// The HZD noise set and the default profile LUT, cooked through the same
// cache as the graph (a second preview cooks nothing).
struct LayerInputs {
    Field3DPtr low, high;
    Field2DPtr curl, lut;
};
// Cooks a small built-in graph (no files written) through the same cache as the
// previewed graph, so a second preview cooks nothing; prints what it did.
CookOptions cook_builtin(Session& s, const std::string& text, const std::string& what, int jobs,
                         const std::optional<std::filesystem::path>& cache_dir, ProgressSink progress, bool quiet) {
    s.load_text(text, "<preview " + what + ">", ".");
    CookOptions o;
    o.write_outputs = false;
    o.jobs = jobs;
    o.cache_dir = cache_dir;
    o.progress = std::move(progress);
    const CookResult r = s.cook(o);
    if (!quiet)
        std::fprintf(stderr, "%s: cooked %zu, cached %zu in %.2f s\n", what.c_str(), r.with_status("cooked").size(), r.with_status("cached").size(),
                     r.seconds);
    return o;
}

LayerInputs cook_layer_inputs(int jobs, const std::optional<std::filesystem::path>& cache_dir, ProgressSink progress, bool quiet) {
    Session s(builtin_nodes());
    const CookOptions o = cook_builtin(s,
                                       "atlas: 1\n"
                                       "nodes:\n"
                                       "  hzd_noise: {type: noise/hzd_set, params: {low_size: 128, high_size: 32, curl_size: 128, seed: 0}}\n"
                                       "  profile_lut: {type: ndf/profile_lut, params: {resolution: [97, 128]}}\n"
                                       "outputs:\n"
                                       "  - {node: hzd_noise, port: low, file: low.exr}\n"
                                       "  - {node: hzd_noise, port: high, file: high.exr}\n"
                                       "  - {node: hzd_noise, port: curl, file: curl.exr}\n"
                                       "  - {node: profile_lut, file: lut.exr}\n",
                                       "noise/hzd_set + ndf/profile_lut", jobs, cache_dir, std::move(progress), quiet);
    LayerInputs in;
    in.low = std::get<Field3DPtr>(s.get("hzd_noise", "low", o));
    in.high = std::get<Field3DPtr>(s.get("hzd_noise", "high", o));
    in.curl = std::get<Field2DPtr>(s.get("hzd_noise", "curl", o));
    in.lut = std::get<Field2DPtr>(s.get("profile_lut", "out", o));
    return in;
}

Field3DPtr cook_voxel_noise(int jobs, const std::optional<std::filesystem::path>& cache_dir, ProgressSink progress, bool quiet) {
    Session s(builtin_nodes());
    const CookOptions o = cook_builtin(s,
                                       "atlas: 1\nnodes:\n  nubis_noise: {type: noise/nubis_set, params: {size: 128, seed: 0}}\n"
                                       "outputs:\n  - {node: nubis_noise, file: nubis_noise.exr}\n",
                                       "noise/nubis_set", jobs, cache_dir, std::move(progress), quiet);
    return std::get<Field3DPtr>(s.get("nubis_noise", "out", o));
}

// Writes into `staged` (a temporary path); the caller moves it into place.
void write_picture(const Field2D& image, const std::filesystem::path& staged, double exposure) {
    auto ext = staged.extension().string();
    if (ext == ".exr") {
        io::ExrOptions o;
        o.channel_meaning = render::kLinearImageMeaning;
        io::write_exr(image, staged, o);
    } else {
        io::write_image(render::tone_map(image, exposure), staged);
    }
}

// A picture written atomically: a failed render or write leaves no file.
void write_picture_atomic(const Field2D& image, const std::filesystem::path& path, double exposure) {
    write_file_atomic(path, [&](const std::filesystem::path& tmp) { write_picture(image, tmp, exposure); });
}

} // namespace

namespace {

// The preview's render flags: the schema's (render::preview_options) and the
// spellings that set several of its options (--sun AZ,EL, --camera, --view, ...),
// parsed by the schema as the render/preview node's parameters are.
render::PreviewOptions read_preview_flags(const Args& a) {
    render::PreviewOptions o;
    const auto schema = render::preview_options();
    read_schema_flags(a, schema, o, "preview");
    for (const render::OptionSpelling& sp : render::preview_cli_spellings()) {
        if (!a.has(sp.cli_flag)) continue;
        const std::string text = a.get(sp.cli_flag);
        std::vector<std::pair<std::string, std::string>> parts;
        if (!sp.expand(text, parts)) throw UsageError{std::string(sp.cli_flag) + " expects " + sp.metavar + ", got '" + text + "'", "preview"};
        for (const auto& [name, value] : parts) {
            const TextOption<render::PreviewOptions>* opt = find_option(schema, name);
            if (!opt || !set_text_option(*opt, value, o))
                throw UsageError{std::string(sp.cli_flag) + " expects " + sp.metavar + " with " + name + " " + (opt ? opt->expected() : "?") + ", got '" +
                                     text + "'",
                                 "preview"};
        }
    }
    try {
        render::check_preview_options(o);
    } catch (const Error& e) {
        throw UsageError{e.what(), "preview"};
    }
    return o;
}

} // namespace

// One preview: cook, render, write. `depends` receives the files a --watch
// loop polls (the graph file and every file the cook read).
int preview_once(const Args& a, std::vector<std::filesystem::path>& depends) {
    if (a.positional.empty()) throw UsageError{"expected a graph file or NVDF files", "preview"};
    if (!a.has("--out") && !a.has("--sweep")) throw UsageError{"expected -o OUT.png (or OUT.exr)", "preview"};
    int jobs = 0;
    if (a.has("--jobs")) {
        jobs = static_cast<int>(numbers(a.get("--jobs"), 1, "--jobs")[0]);
        if (jobs < 1 || jobs > 1024) throw UsageError{"--jobs expects a number of threads >= 1", "preview"};
    }
    const render::PreviewOptions po = read_preview_flags(a);
    const int w = po.size[0], h = po.size[1];
    std::string mode = a.has("--mode") ? a.get("--mode") : "auto";
    if (mode != "auto" && mode != "layer" && mode != "voxel") throw UsageError{"--mode expects layer or voxel, got '" + mode + "'", "preview"};
    const bool quiet = a.has("--quiet");
    ProgressBar bar(!quiet);
    ProgressSink sink = bar.sink();
    const auto t_start = std::chrono::steady_clock::now();

    Field3DPtr noise;
    const std::string noise_opt = a.has("--noise") ? a.get("--noise") : "auto";
    if (noise_opt != "auto" && noise_opt != "none" && noise_opt != "nubis") noise = io::as_field3d(io::read_field_file(noise_opt));
    if (a.has("--cache") && a.has("--no-cache")) throw UsageError{"--cache and --no-cache contradict each other", "preview"};
    std::optional<std::filesystem::path> cache_dir;
    if (a.has("--cache")) cache_dir = a.get("--cache");
    else if (const char* env = std::getenv("ATLAS_CACHE_DIR"); env && *env && !a.has("--no-cache")) cache_dir = env;

    bool have_voxel = false, have_layer = false;
    Field3DPtr forecast; // time slices, when the preview steps a forecast
    int slice0 = 0;
    render::CloudScene scene;
    render::LayerScene layer;
    if (a.positional.size() > 1)
        for (const std::string& f : a.positional)
            if (is_graph(f))
                throw UsageError{"a graph is previewed alone: '" + f + "' was given with " + std::to_string(a.positional.size() - 1) +
                                     " more file(s); preview the graph, or the files it writes",
                                 "preview"};
    if (a.positional.size() == 1 && is_graph(a.positional[0])) {
        const std::string file = a.positional[0];
        Session session(builtin_nodes());
        session.load(file);
        apply_sets(session, a);
        depends = {file};
        GraphContent g = cook_graph(session, file, jobs, sink, cache_dir, quiet);
        for (const auto& d : g.depends)
            if (std::find(depends.begin(), depends.end(), d) == depends.end()) depends.push_back(d);
        // A forecast (ndf/forecast) is drawn when asked for (--slice, --frames) or when nothing else is there.
        if (g.forecast && (a.has("--slice") || a.has("--frames") || !g.ndf)) {
            forecast = g.forecast;
            slice0 = a.has("--slice") ? static_cast<int>(numbers(a.get("--slice"), 1, "--slice")[0]) : 0;
            if (slice0 < 0 || slice0 >= forecast->nz())
                throw UsageError{"--slice expects 0.." + std::to_string(forecast->nz() - 1) + " (the forecast's time slices)", "preview"};
            g.ndf = std::make_shared<const Field2D>(forecast_slice(*forecast, slice0));
        }
        const bool layerish = g.ndf || g.cirrus || g.sky2d;
        if (!g.nvdf && !layerish) {
            std::string list;
            for (const auto& x : g.written) list += "\n  " + x;
            throw Error(file + ": the graph writes nothing to preview: no volume/nvdf vdb_set (voxel mode), no NDF set or weather map (2.5D mode) and no "
                               "2D sky layer; it writes:" + (list.empty() ? std::string(" no outputs") : list));
        }
        if (mode == "voxel" && !g.nvdf) throw Error(file + ": --mode voxel, but the graph writes no volume/nvdf output");
        if (mode == "layer" && !layerish) throw Error(file + ": --mode layer, but the graph writes no NDF set, weather map or 2D sky layer");
        have_voxel = g.nvdf && mode != "layer";
        have_layer = layerish && mode != "voxel";
        if (have_voxel) scene = render::scene_from_nvdf_set(g.nvdf);
        if (have_layer) {
            LayerInputs in = cook_layer_inputs(jobs, cache_dir, sink, quiet);
            // The library assembles the scene (the render/preview node calls the same).
            render::LayerPreviewInputs li;
            li.ndf = g.ndf;
            li.profile_lut = g.lut ? g.lut : in.lut;
            li.base_noise = in.low;
            li.detail_noise = in.high;
            li.curl = in.curl;
            li.cone_map = g.cone;
            li.anvil = g.anvil;
            li.vortex_table = g.vortex;
            li.distance_map = g.distance;
            li.cirrus = g.cirrus;
            li.sky_texture = g.sky2d;
            layer = render::layer_preview_scene(li);
        }
    } else {
        if (mode == "layer") throw UsageError{"--mode layer needs a graph that writes an NDF set", "preview"};
        std::vector<render::SceneField> files;
        for (const std::string& p : a.positional) files.push_back({io::as_field3d(io::read_field_file(p)), p});
        scene = render::scene_from_fields(std::move(files), a.has("--voxel") ? numbers(a.get("--voxel"), 1, "--voxel")[0] : 0.0);
        have_voxel = true;
    }
    if (have_voxel) {
        // Voxel up-rez by default for modelled clouds (an NVDF set): the Nubis
        // noise set (noise/nubis_set 128^3), cooked through the same cache as
        // the graph. A plain density grid (a sim, a production cloud) has its
        // own detail: eroding it made foam, so it is drawn as it is.
        if (noise_opt == "nubis" || (noise_opt == "auto" && !scene.density_grid_max)) noise = cook_voxel_noise(jobs, cache_dir, sink, quiet);
        if (noise_opt == "auto" && scene.density_grid_max && !quiet)
            std::fprintf(stderr, "noise: none for a plain density grid (its own detail is kept); --noise nubis or FILE up-rezzes it anyway\n");
        scene.noise = noise;
    }
    if (po.lightning && !have_layer) throw UsageError{"--lightning places flashes over a 2.5D layer; this preview has no NDF set", "preview"};
    // The library entry the render/preview node calls: the options applied to the
    // scenes, the settings of the render calls (render/preview.h).
    const bool from_graph = a.positional.size() == 1 && is_graph(a.positional[0]);
    render::PreviewJob job = render::prepare_preview(have_voxel ? std::optional<render::CloudScene>(scene) : std::nullopt,
                                                     have_layer ? std::optional<render::LayerScene>(layer) : std::nullopt, po,
                                                     from_graph ? render::PreviewLook::Graph : render::PreviewLook::Fields, nullptr, jobs);
    if (!quiet)
        for (const std::string& note : job.notes) std::fprintf(stderr, "%s\n", note.c_str());
    render::RenderSettings& s = job.settings;
    const Box3d bounds = have_voxel ? job.voxel->modeling->bounds() : Box3d{{{0, 0, 0}}, {{1, 1, 1}}};
    const double exposure = job.exposure;
    if (a.has("--export-scene")) {
        if (have_voxel && have_layer) throw UsageError{"--export-scene exports a voxel or a 2.5D scene, not both at once (use --mode)", "preview"};
        const std::string note = have_layer ? export_layer_scene(a.get("--export-scene"), *job.layer, s) : export_scene(a.get("--export-scene"), *job.voxel, s);
        if (!quiet) std::fprintf(stderr, "%s\n", note.c_str());
    }

    if (a.has("--sweep")) {
        if (!have_voxel) throw UsageError{"--sweep measures the voxel renderer; the graph has no volume/nvdf output", "preview"};
        auto r = render::quality_sweep(*job.voxel, s, {0.25, 0.5, 1, 2, 4}, &sink);
        bar.finish();
        // stdout: the table (data); a CSV-friendly layout.
        std::printf("quality,seconds,rmse_radiance,rmse_transmittance\n");
        std::printf("reference,%.3f,0,0\n", r.reference_seconds);
        for (const auto& row : r.rows) std::printf("%g,%.3f,%.6f,%.6f\n", row.quality, row.seconds, row.rmse, row.transmittance_rmse);
        if (a.has("--out")) write_picture_atomic(r.reference, a.get("--out"), exposure);
        return 0;
    }

    const int flash0 = int(po.flash_index);
    const std::filesystem::path out = a.get("--out");
    if (a.has("--turntable") && a.has("--frames")) throw UsageError{"--turntable and --frames contradict each other", "preview"};
    const bool sequence = a.has("--frames");
    const char* frames_opt = sequence ? "--frames" : "--turntable";
    const int frames = a.has(frames_opt) ? static_cast<int>(numbers(a.get(frames_opt), 1, frames_opt)[0]) : 0;
    if (a.has(frames_opt) && (frames < 1 || frames > 3600)) throw UsageError{std::string(frames_opt) + " expects 1..3600 frames", "preview"};
    const double time_step = a.has("--time-step") ? numbers(a.get("--time-step"), 1, "--time-step")[0] : 60.0;
    const double time0 = have_layer ? job.layer->time : 0.0;
    auto t0 = std::chrono::steady_clock::now();
    std::string features;
    // One frame: the layer, the voxel set, or the voxel set composited over the layer.
    auto render_frame = [&]() {
        render::PreviewFrame f = render::render_preview(job, &sink);
        features.clear();
        if (f.layer_report) {
            const render::LayerReport& r = *f.layer_report;
            features += " [2.5D:";
            for (const auto& x : r.active_features()) features += " " + x;
            char buf[128];
            std::snprintf(buf, sizeof buf, "; %.2f s, %llu cheap + %llu full samples, %llu skips]", r.seconds, (unsigned long long)r.cheap_samples,
                          (unsigned long long)r.full_samples, (unsigned long long)r.skipped_steps);
            features += buf;
        }
        if (f.voxel_report) {
            features += have_layer ? " [voxel:" : "";
            for (const auto& x : f.voxel_report->active_features()) features += " " + x;
            if (have_layer) features += "]";
        }
        return std::move(f.image);
    };
    if (frames == 0) {
        Field2D image = render_frame();
        write_picture_atomic(image, out, exposure);
        bar.finish();
        std::cout << out.string() << "\n";
    } else {
        // All frames or none: staged beside OUT, moved into place at the end.
        StagedOutputs staged(out.parent_path().empty() ? std::filesystem::path(".") : out.parent_path());
        std::vector<std::filesystem::path> paths;
        for (int i = 0; i < frames; ++i) {
            if (sequence) {
                // A time sequence: the wind scroll advances, each frame a new flash,
                // and a forecast its next time slice (the envelope follows the slice).
                if (have_layer) {
                    render::LayerScene& layer_now = *job.layer;
                    layer_now.time = time0 + i * time_step;
                    if (forecast) {
                        layer_now.ndf = render::weather_map_as_set(forecast_slice(*forecast, (slice0 + i) % forecast->nz()));
                        if (layer_now.envelope.cone_map) layer_now.envelope.cone_map = render::cloud_top_cone_map(*layer_now.ndf);
                    }
                }
                for (auto& f : s.light_fields) f.flash = flash0 + i;
            } else if (have_layer) {
                s.camera = render::layer_camera(*job.layer, render::LayerView::Orbit, double(w) / h, 30 + 360.0 * i / frames, po.elevation);
            } else {
                s.camera = render::framing_camera(have_voxel && is_graph(a.positional[0]) ? render::cloud_bounds(*job.voxel) : bounds, double(w) / h,
                                                  30 + 360.0 * i / frames);
            }
            Field2D image = render_frame();
            char suffix[32];
            std::snprintf(suffix, sizeof suffix, "_%03d", i);
            const std::filesystem::path name = out.stem().string() + suffix + out.extension().string();
            write_picture(image, staged.stage(name), exposure);
            paths.push_back(out.parent_path() / name);
        }
        staged.commit();
        bar.finish();
        for (const auto& p : paths) std::cout << p.string() << "\n";
    }
    if (!quiet) {
        const auto now = std::chrono::steady_clock::now();
        const double secs = std::chrono::duration<double>(now - t0).count();
        const double total = std::chrono::duration<double>(now - t_start).count();
        std::fprintf(stderr, "rendered %dx%d%s (%s) in %.2f s (%.2f s with cooking); features:%s\n", w, h,
                     frames ? (" x" + std::to_string(frames)).c_str() : "",
                     have_layer && have_voxel ? "2.5D + voxel composited" : (have_layer ? "2.5D" : "voxel"), secs, total, features.c_str());
    }
    return 0;
}

namespace {

using FileStamps = std::vector<std::pair<std::filesystem::path, std::filesystem::file_time_type>>;

FileStamps stamps_of(const std::vector<std::filesystem::path>& files) {
    FileStamps st;
    for (const auto& f : files) {
        std::error_code ec;
        st.emplace_back(f, std::filesystem::last_write_time(f, ec));
    }
    return st;
}

} // namespace

// --watch: preview, then poll the graph and its input files twice a second;
// on a change re-cook (through the cache: only what changed) and re-render,
// printing each step's time (the cook and render summaries). A failing
// round prints its error and waits for the next change. --watch-max N stops
// after N re-renders (scripts, tests).
int run_preview(const Args& a) {
    std::vector<std::filesystem::path> depends;
    if (!a.has("--watch")) return preview_once(a, depends);
    if (a.positional.size() != 1 || !is_graph(a.positional[0])) throw UsageError{"--watch needs one graph file", "preview"};
    const int max_rounds = a.has("--watch-max") ? static_cast<int>(numbers(a.get("--watch-max"), 1, "--watch-max")[0]) : -1;
    depends = {a.positional[0]};
    auto round = [&] {
        try {
            preview_once(a, depends);
        } catch (const UsageError&) {
            throw;
        } catch (const std::exception& e) {
            std::fprintf(stderr, "watch: error: %s\n", e.what());
        }
    };
    round();
    for (int n = 0; max_rounds < 0 || n < max_rounds; ++n) {
        const FileStamps before = stamps_of(depends);
        std::fprintf(stderr, "watch: waiting for a change in %zu file(s)\n", depends.size());
        for (;;) {
            std::this_thread::sleep_for(std::chrono::milliseconds(500));
            const FileStamps now = stamps_of(depends);
            if (now != before) {
                for (size_t i = 0; i < now.size() && i < before.size(); ++i)
                    if (now[i].second != before[i].second) std::fprintf(stderr, "watch: %s changed\n", now[i].first.string().c_str());
                break;
            }
        }
        const auto t = std::chrono::steady_clock::now();
        round();
        std::fprintf(stderr, "watch: re-cooked and re-rendered in %.2f s\n",
                     std::chrono::duration<double>(std::chrono::steady_clock::now() - t).count());
    }
    return 0;
}

} // namespace atlas::cli
