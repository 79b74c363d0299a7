// The preview of a session's graph or of files: what a graph writes that a preview
// draws, cooked as values; the built-in noise sets; the scenes; the render job.
#include "atlas/preview/graph_preview.h"

#include "atlas/core/error.h"
#include "atlas/io/readers.h"
#include "atlas/render/layer.h"
#include "atlas/render/scene.h"

#include <algorithm>
#include <cstdio>
#include <map>
#include <mutex>
#include <optional>
#include <variant>

namespace atlas::preview {

namespace {

// What a graph writes that the preview can draw, found by cooking (values only)
// the graph's outputs:
//   volume/nvdf vdb_set, volume/blend      -> voxel mode
//   a 2D field with coverage, min_height, max_height (an NDF set) -> 2.5D mode
//   a 2D field with coverage only (a weather map)      -> 2.5D, heights 1500..4000 m
//   a 2D field with bottom, top (ndf/profile_lut)      -> the layer's profile LUT
//   a 2D field with anvil_bias (ndf/superstorm anvil)  -> the storm's anvil spread
//   ndf/vortex_rings' table (inner, outer, speed, ...)  -> the storm turns with --time
//   ndf/lightning's table (time, duration, x, y, z, intensity, ...) -> flash lights
//   a 2D field with apex_height, cone_ratio (ndf/cone_map) / ndf/distance_map -> envelope
//   a 2D field with a 'cirrus' channel (ndf/cirrus)    -> a cirrus layer at 8 km
//   otherwise the last 1-channel 2D field               -> a sky layer at 6 km (Quilez)
struct GraphContent {
    Field3DPtr nvdf;
    Field2DPtr ndf, lut, cone, cirrus, sky2d, horizon, anvil, vortex;
    Field2DPtr flashes; // ndf/lightning's table: x = flash
    Field3DPtr distance;
    Field3DPtr forecast; // ndf/forecast maps: z = time slice, channels coverage, precipitation, type, ...
    std::vector<std::string> written; // "node 'n' (type) port 'p' -> file"
};

bool has_channels(const Field2D& f, std::initializer_list<const char*> names) {
    for (const char* n : names)
        if (f.find_channel(n) < 0) return false;
    return true;
}

std::string cook_line(const char* what, const CookResult& r, const GraphPreviewOptions& how) {
    char buf[256];
    std::snprintf(buf, sizeof buf, "%s: cooked %zu, cached %zu nodes in %.2f s%s", what, r.with_status("cooked").size(), r.with_status("cached").size(),
                  r.seconds, r.proxy > 1 ? (" at proxy " + std::to_string(r.proxy)).c_str() : "");
    std::string line = buf;
    if (how.cache_dir) line += " (cache " + how.cache_dir->string() + ")";
    return line;
}

CookOptions value_cook(const GraphPreviewOptions& how) {
    CookOptions o;
    o.write_outputs = false;
    o.jobs = how.jobs;
    o.cache_dir = how.cache_dir;
    o.progress = how.progress;
    o.proxy = how.proxy;
    return o;
}

GraphContent cook_graph(Session& session, const std::string& file, const GraphPreviewOptions& how, GraphPreview& out) {
    GraphContent g;
    struct Want {
        std::string node, port, type, file;
        bool generic; // a PortType::Field port: 2D or 3D, known only once cooked
    };
    std::vector<Want> wants;
    for (const auto& o : session.graph().outputs) {
        const GraphNode* n = session.graph().find(o.node);
        if (!n) continue;
        const NodeType* t = session.registry().find(n->type);
        if (!t || t->decl.outputs().empty()) continue;
        const PortDecl* port = o.port.empty() ? &t->decl.outputs().front() : t->decl.find_output(o.port);
        if (!port) continue;
        g.written.push_back("node '" + o.node + "' (" + n->type + ") port '" + port->name + "' -> " + o.file);
        // An NVDF set: volume/nvdf's, or two of them blended (volume/blend).
        const bool nvdf = (n->type == "volume/nvdf" && port->name == "vdb_set") || n->type == "volume/blend";
        const bool dist = n->type == "ndf/distance_map";
        const bool forecast = port->type == PortType::Field3D && n->type.rfind("ndf/", 0) == 0;
        if (nvdf || dist || forecast || port->type == PortType::Field2D || port->type == PortType::Field)
            wants.push_back({o.node, port->name, n->type, o.file, port->type == PortType::Field && !nvdf && !dist});
    }
    // Two passes: typed outputs first; generic field outputs (which may be
    // large volumes) only when nothing drawable was found.
    for (int pass = 0; pass < 2; ++pass) {
        std::vector<const Want*> now;
        for (const auto& w : wants)
            if (w.generic == (pass == 1)) now.push_back(&w);
        if (now.empty()) continue;
        if (pass == 1 && (g.nvdf || g.ndf || g.cirrus || g.sky2d || g.horizon)) break;
        CookOptions o = value_cook(how);
        for (const Want* w : now) o.outputs.push_back(w->file);
        const CookResult r = session.cook(o);
        out.cook_seconds += r.seconds;
        for (const auto& d : r.depends(file))
            if (std::find(out.depends.begin(), out.depends.end(), d) == out.depends.end()) out.depends.push_back(d);
        out.log.push_back(cook_line("graph", r, how));
        for (const Want* wp : now) {
            const Want& w = *wp;
            Value v = session.get(w.node, w.port, o); // from the session's memory cache now
            const std::string what = file + ": node '" + w.node + "' output '" + w.port + "'";
            if (auto* f3 = std::get_if<Field3DPtr>(&v); f3 && *f3) {
                if ((w.type == "volume/nvdf" || (w.type == "volume/blend" && (*f3)->find_channel("dimensional_profile") >= 0)) && !g.nvdf)
                    render::check_finite(**f3, what), g.nvdf = *f3;
                else if (w.type == "ndf/distance_map" && !g.distance) render::check_finite(**f3, what), g.distance = *f3;
                else if ((*f3)->find_channel("coverage") >= 0 && !g.forecast) render::check_finite(**f3, what), g.forecast = *f3;
                continue;
            }
            auto* f2 = std::get_if<Field2DPtr>(&v);
            if (!f2 || !*f2) continue;
            const Field2D& f = **f2;
            if (render::is_ndf_set(f) || render::is_weather_map(f)) {
                render::check_finite(f, what);
                if (!g.ndf) g.ndf = *f2; // a weather map becomes a set in render::layer_preview_scene
            } else if (has_channels(f, {"inner", "outer", "speed", "overlap_end"})) {
                render::check_finite(f, what);
                if (!g.vortex) g.vortex = *f2;
            } else if (has_channels(f, {"time", "duration", "x", "y", "z", "intensity", "ground"})) {
                render::check_finite(f, what);
                g.flashes = *f2; // the last one written
            } else if (has_channels(f, {"anvil_bias"})) {
                render::check_finite(f, what);
                g.anvil = *f2; // the last one written: the end of a stencil chain
            } else if (has_channels(f, {"bottom", "top"})) {
                if (!g.lut) g.lut = *f2;
            } else if (has_channels(f, {"apex_height", "cone_ratio"})) {
                if (!g.cone) g.cone = *f2;
            } else if (has_channels(f, {"cirrus_horizon"})) {
                // Far Cry 6's horizon strip goes around the camera; drawn as a sky
                // plane it stretched into bars across the sky.
                render::check_finite(f, what);
                if (!g.horizon) g.horizon = *f2;
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

// The built-in noise sets and the default profile LUT: the same values for every
// preview, so they are cooked once per process (through the cache directory when
// one is given) and kept: a re-render after an edit cooks none of them.
struct LayerInputs {
    Field3DPtr low, high;
    Field2DPtr curl, lut;
};

CookOptions cook_builtin(Session& s, const std::string& text, const char* what, const GraphPreviewOptions& how, GraphPreview& out) {
    s.load_text(text, std::string("<preview ") + what + ">", ".");
    CookOptions o = value_cook(how);
    o.proxy = 1; // fixed tile sets: not world grids
    const CookResult r = s.cook(o);
    out.cook_seconds += r.seconds;
    out.log.push_back(cook_line(what, r, how));
    return o;
}

std::mutex builtin_mutex;

LayerInputs layer_inputs(const GraphPreviewOptions& how, GraphPreview& out) {
    static LayerInputs kept;
    std::lock_guard<std::mutex> lock(builtin_mutex);
    if (kept.low) return kept;
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
                                       "noise/hzd_set + ndf/profile_lut", how, out);
    LayerInputs in;
    in.low = std::get<Field3DPtr>(s.get("hzd_noise", "low", o));
    in.high = std::get<Field3DPtr>(s.get("hzd_noise", "high", o));
    in.curl = std::get<Field2DPtr>(s.get("hzd_noise", "curl", o));
    in.lut = std::get<Field2DPtr>(s.get("profile_lut", "out", o));
    kept = in;
    return in;
}

Field3DPtr voxel_noise(const GraphPreviewOptions& how, GraphPreview& out) {
    static Field3DPtr kept;
    std::lock_guard<std::mutex> lock(builtin_mutex);
    if (kept) return kept;
    Session s(builtin_nodes());
    const CookOptions o = cook_builtin(s,
                                       "atlas: 1\nnodes:\n  nubis_noise: {type: noise/nubis_set, params: {size: 128, seed: 0}}\n"
                                       "outputs:\n  - {node: nubis_noise, file: nubis_noise.exr}\n",
                                       "noise/nubis_set", how, out);
    kept = std::get<Field3DPtr>(s.get("nubis_noise", "out", o));
    return kept;
}

void check_how(const GraphPreviewOptions& how) {
    if (how.mode != "auto" && how.mode != "layer" && how.mode != "voxel") throw Error("preview mode: expected auto, layer or voxel, got '" + how.mode + "'");
    if (how.noise.empty()) throw Error("preview noise: expected auto, nubis, none or a volume file");
    if (how.proxy < 1 || how.proxy > 64) throw Error("preview proxy: expected 1..64, got " + std::to_string(how.proxy));
}

// The voxel up-rez: by default the Nubis noise set for modelled clouds (an NVDF
// set); a plain density grid (a sim, a production cloud) has its own detail:
// eroding it made foam, so it is drawn as it is.
void apply_noise(render::CloudScene& scene, const GraphPreviewOptions& how, GraphPreview& out) {
    if (how.noise == "none") return;
    if (how.noise != "auto" && how.noise != "nubis") {
        scene.noise = io::as_field3d(io::read_field_file(how.noise));
        return;
    }
    if (how.noise == "nubis" || !scene.density_grid_max) {
        scene.noise = voxel_noise(how, out);
        return;
    }
    out.log.push_back("noise: none for a plain density grid (its own detail is kept); --noise nubis or FILE up-rezzes it anyway");
}

// One strike sequence of a lightning table's window (a frame's) as point lights:
// its flashes come within a second or two, about one exposure, where every flash of a
// 20-second frame at once lit the whole storm. A window without flashes is one row of
// intensity 0.
void add_flash_lights(const Field2D& table, render::PreviewOptions& options, GraphPreview& out) {
    const int x = table.find_channel("x"), y = table.find_channel("y"), z = table.find_channel("z"), in = table.find_channel("intensity"),
              seq = table.find_channel("sequence");
    // The sequence with the most flashes in the window (the earliest of equals): one that
    // started in the frame before shows only its tail here.
    std::map<double, int> count;
    std::optional<double> pick;
    for (int i = 0; i < table.width(); ++i)
        if (table.at(in, i, 0) > 0) {
            const double s = seq >= 0 ? table.at(seq, i, 0) : 0.0;
            const int c = ++count[s];
            if (!pick || c > count[*pick] || (c == count[*pick] && s < *pick)) pick = s;
        }
    int n = 0;
    for (int i = 0; i < table.width() && pick; ++i) {
        const double intensity = table.at(in, i, 0);
        if (!(intensity > 0) || (seq >= 0 && table.at(seq, i, 0) != *pick)) continue;
        options.lights.push_back({{{table.at(x, i, 0), table.at(y, i, 0), table.at(z, i, 0)}}, options.flash_colour, intensity, options.flash_radius});
        ++n;
    }
    out.log.push_back(n ? "lightning: the window's longest strike sequence drawn, " + std::to_string(n) + " flash" + (n == 1 ? "" : "es") +
                              " as lights; --no-flash-schedule leaves it out"
                        : "lightning: no flashes in the cooked window");
}

void finish(GraphPreview& out, std::optional<render::CloudScene> voxel, std::optional<render::LayerScene> layer, const render::PreviewOptions& options,
            render::PreviewLook look, const GraphPreviewOptions& how) {
    if (options.lightning && !layer) throw Error("lightning places flashes over a 2.5D layer; this preview has no NDF set");
    out.voxel = voxel.has_value();
    out.layer = layer.has_value();
    out.job = render::prepare_preview(std::move(voxel), std::move(layer), options, look, nullptr, how.jobs);
    out.log.insert(out.log.end(), out.job.notes.begin(), out.job.notes.end());
}

} // namespace

Field2D forecast_slice(const Field3D& f, int z) {
    const Box3d& b = f.bounds();
    Field2D m({{f.nx(), f.ny()}}, f.channels(), Box2d{{{b.min[0], b.min[1]}}, {{b.max[0], b.max[1]}}}, f.channel_names());
    for (int c = 0; c < f.channels(); ++c)
        for (int y = 0; y < f.ny(); ++y)
            for (int x = 0; x < f.nx(); ++x) m.at(c, x, y) = f.at(c, x, y, z);
    return m;
}

GraphPreview prepare_graph_preview(Session& session, const render::PreviewOptions& options, const GraphPreviewOptions& how,
                                   const std::filesystem::path& graph_file) {
    check_how(how);
    render::check_preview_options(options);
    GraphPreview out;
    const std::string file = graph_file.empty() ? (session.graph().file.empty() ? std::string("<graph>") : session.graph().file.string()) : graph_file.string();
    if (!graph_file.empty()) out.depends.push_back(graph_file);
    GraphContent g = cook_graph(session, file, how, out);
    // A forecast (ndf/forecast) is drawn when asked for (a slice, a sequence) or when nothing else is there.
    if (g.forecast && (how.slice >= 0 || how.forecast || !g.ndf)) {
        out.forecast = g.forecast;
        out.slice = std::max(how.slice, 0);
        if (out.slice >= g.forecast->nz())
            throw Error(file + ": slice " + std::to_string(out.slice) + " of a forecast with " + std::to_string(g.forecast->nz()) + " time slices (0.." +
                        std::to_string(g.forecast->nz() - 1) + ")");
        g.ndf = std::make_shared<const Field2D>(forecast_slice(*g.forecast, out.slice));
    }
    const bool layerish = g.ndf || g.cirrus || g.sky2d || g.horizon;
    if (!g.nvdf && !layerish) {
        std::string list;
        for (const auto& x : g.written) list += "\n  " + x;
        throw Error(file + ": the graph writes nothing to preview: no volume/nvdf vdb_set (voxel mode), no NDF set or weather map (2.5D mode) and no "
                           "2D sky layer; it writes:" + (list.empty() ? std::string(" no outputs") : list));
    }
    if (how.mode == "voxel" && !g.nvdf) throw Error(file + ": mode voxel, but the graph writes no volume/nvdf output");
    if (how.mode == "layer" && !layerish) throw Error(file + ": mode layer, but the graph writes no NDF set, weather map or 2D sky layer");
    std::optional<render::CloudScene> voxel;
    std::optional<render::LayerScene> layer;
    if (g.nvdf && how.mode != "layer") {
        voxel = render::scene_from_nvdf_set(g.nvdf);
        apply_noise(*voxel, how, out);
    }
    if (layerish && how.mode != "voxel") {
        const LayerInputs in = layer_inputs(how, out);
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
        li.horizon_strip = g.horizon;
        layer = render::layer_preview_scene(li);
    }
    render::PreviewOptions lit = options;
    if (g.flashes && options.flash_schedule) add_flash_lights(*g.flashes, lit, out);
    finish(out, std::move(voxel), std::move(layer), lit, render::PreviewLook::Graph, how);
    return out;
}

GraphPreview prepare_file_preview(const std::vector<std::filesystem::path>& files, const render::PreviewOptions& options, const GraphPreviewOptions& how) {
    check_how(how);
    render::check_preview_options(options);
    if (files.empty()) throw Error("preview: no files given");
    if (how.mode == "layer") throw Error("preview mode layer needs a graph that writes an NDF set");
    GraphPreview out;
    std::vector<render::SceneField> fields;
    for (const auto& p : files) {
        fields.push_back({io::as_field3d(io::read_field_file(p)), p.string()});
        out.depends.push_back(p);
    }
    render::CloudScene scene = render::scene_from_fields(std::move(fields), how.voxel);
    apply_noise(scene, how, out);
    finish(out, std::move(scene), std::nullopt, options, render::PreviewLook::Fields, how);
    return out;
}

render::PreviewFrame preview_session(Session& session, const render::PreviewOptions& options, const GraphPreviewOptions& how,
                                     const std::filesystem::path& graph_file) {
    const GraphPreview p = prepare_graph_preview(session, options, how, graph_file);
    return render::render_preview(p.job, &how.progress);
}

void set_preview_options(render::PreviewOptions& options, const std::vector<std::pair<std::string, std::string>>& settings) {
    const auto schema = render::preview_options();
    for (const auto& [name, text] : settings) {
        const TextOption<render::PreviewOptions>* opt = find_option(schema, name);
        if (!opt) {
            std::string names;
            for (const auto& o : schema) names += (names.empty() ? "" : ", ") + std::string(o.name);
            throw Error("preview option '" + name + "' does not exist; the options are " + names + " (docs/options.md)");
        }
        // A host's list joined with commas ("640,360") also reads where the CLI's
        // spelling separates numbers otherwise ("640x360").
        std::string alt = text;
        if (opt->separator != ',') std::replace(alt.begin(), alt.end(), ',', opt->separator);
        if (!set_text_option(*opt, text, options) && !set_text_option(*opt, alt, options))
            throw Error("preview option '" + name + "' expects " + opt->expected() + ", got '" + text + "'");
    }
    render::check_preview_options(options);
}

} // namespace atlas::preview
