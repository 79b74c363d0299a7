// atlas preview (GRAPH | FILES...): render an NVDF set with the preview
// ray-marcher (libatlas/render) to PNG or EXR; --sweep prints fast-vs-
// reference error and time per quality; --turntable writes N frames.
#include "cli.h"
#include "export_scene.h"
#include "progress_bar.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "atlas/graph/evaluator.h"
#include "atlas/io/animation.h"
#include "atlas/io/exr.h"
#include "atlas/io/image.h"
#include "atlas/preview/graph_preview.h"
#include "atlas/render/image_out.h"
#include "atlas/render/layer.h"
#include "atlas/render/preview.h"
#include "atlas/render/preview_options.h"
#include "atlas/render/renderer.h"
#include "atlas/render/sweep.h"

#include <algorithm>
#include <chrono>
#include <functional>
#include <cstdio>
#include <iostream>
#include <memory>
#include <optional>
#include <thread>
#include <sstream>

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

// Writes into `staged` (a temporary path); the caller moves it into place.
// `shown`: the image already tone-mapped with `exposure`, when the caller has it.
void write_picture(const Field2D& image, const std::filesystem::path& staged, double exposure, const Field2D* shown = nullptr) {
    auto ext = staged.extension().string();
    if (ext == ".exr") {
        io::ExrOptions o;
        o.channel_meaning = render::kLinearImageMeaning;
        io::write_exr(image, staged, o);
    } else {
        io::write_image(shown ? *shown : render::tone_map(image, exposure), staged);
    }
}

// A picture written atomically: a failed render or write leaves no file.
void write_picture_atomic(const Field2D& image, const std::filesystem::path& path, double exposure) {
    write_file_atomic(path, [&](const std::filesystem::path& tmp) { write_picture(image, tmp, exposure); });
}

} // namespace

// The preview's render flags: the schema's (render::preview_options) and the
// spellings that set several of its options (--sun AZ,EL, --camera, --view, ...),
// parsed by the schema as the render/preview node's parameters are.
render::PreviewOptions read_preview_flags(const Args& a, const char* command) {
    render::PreviewOptions o;
    const auto schema = render::preview_options();
    read_schema_flags(a, schema, o, command);
    for (const render::OptionSpelling& sp : render::preview_cli_spellings()) {
        if (!a.has(sp.cli_flag)) continue;
        const std::string text = a.get(sp.cli_flag);
        std::vector<std::pair<std::string, std::string>> parts;
        if (!sp.expand(text, parts)) throw UsageError{std::string(sp.cli_flag) + " expects " + sp.metavar + ", got '" + text + "'", command};
        for (const auto& [name, value] : parts) {
            const TextOption<render::PreviewOptions>* opt = find_option(schema, name);
            if (!opt || !set_text_option(*opt, value, o))
                throw UsageError{std::string(sp.cli_flag) + " expects " + sp.metavar + " with " + name + " " + (opt ? opt->expected() : "?") + ", got '" +
                                     text + "'",
                                 command};
        }
    }
    try {
        render::check_preview_options(o);
    } catch (const Error& e) {
        throw UsageError{e.what(), command};
    }
    return o;
}

// One preview: cook, render, write. `depends` receives the files a --watch
// loop polls (the graph file and every file the cook read). `session` is kept
// by --watch between rounds: what it cooked stays in memory, so an edit cooks
// only the nodes it changed (also with --no-cache).
int preview_once(const Args& a, std::vector<std::filesystem::path>& depends, std::unique_ptr<Session>& session) {
    if (a.positional.empty()) throw UsageError{"expected a graph file or NVDF files", "preview"};
    if (!a.has("--out") && !a.has("--sweep")) throw UsageError{"expected -o OUT.png (or OUT.exr)", "preview"};
    int jobs = 0;
    if (a.has("--jobs")) {
        jobs = static_cast<int>(numbers(a.get("--jobs"), 1, "--jobs")[0]);
        if (jobs < 1 || jobs > 1024) throw UsageError{"--jobs expects a number of threads >= 1", "preview"};
    }
    const render::PreviewOptions po = read_preview_flags(a, "preview");
    const int w = po.size[0], h = po.size[1];
    std::string mode = a.has("--mode") ? a.get("--mode") : "auto";
    if (mode != "auto" && mode != "layer" && mode != "voxel") throw UsageError{"--mode expects layer or voxel, got '" + mode + "'", "preview"};
    const bool quiet = a.has("--quiet");
    ProgressBar bar(!quiet);
    ProgressSink sink = bar.sink();
    const auto t_start = std::chrono::steady_clock::now();

    preview::GraphPreviewOptions how;
    how.cache_dir = cache_dir_flag(a, "preview");
    how.jobs = jobs;
    how.progress = sink;
    how.mode = mode;
    how.noise = a.has("--noise") ? a.get("--noise") : "auto";
    if (a.has("--proxy")) {
        how.proxy = static_cast<int>(numbers(a.get("--proxy"), 1, "--proxy")[0]);
        if (how.proxy < 1 || how.proxy > 64) throw UsageError{"--proxy expects a factor 1..64 (4: a quarter of the cells per axis)", "preview"};
    }
    if (a.positional.size() > 1)
        for (const std::string& f : a.positional)
            if (is_graph(f))
                throw UsageError{"a graph is previewed alone: '" + f + "' was given with " + std::to_string(a.positional.size() - 1) +
                                     " more file(s); preview the graph, or the files it writes",
                                 "preview"};
    const bool from_graph = a.positional.size() == 1 && is_graph(a.positional[0]);
    if (!from_graph && mode == "layer") throw UsageError{"--mode layer needs a graph that writes an NDF set", "preview"};
    if (!from_graph && how.proxy > 1) throw UsageError{"--proxy scales a graph's grids; files are drawn as they are", "preview"};
    if (a.has("--slice")) how.slice = static_cast<int>(numbers(a.get("--slice"), 1, "--slice")[0]);
    if (a.has("--slice") && how.slice < 0) throw UsageError{"--slice expects a time slice >= 0", "preview"};
    how.forecast = a.has("--frames");
    if (a.has("--voxel")) how.voxel = numbers(a.get("--voxel"), 1, "--voxel")[0];

    // The library entry every front end calls (atlas/preview/graph_preview.h): what the
    // graph writes, cooked as values, the scenes and the render job.
    preview::GraphPreview prepared;
    if (from_graph) {
        if (!session) session = std::make_unique<Session>(builtin_nodes());
        session->load(a.positional[0]);
        apply_sets(*session, a, "preview");
        // A graph with a time range (docs/graph-format.md, "Time") is drawn at --time.
        if (const auto& gt = session->graph().time; gt && a.has("--time")) {
            if (po.time < gt->start || po.time > gt->end)
                throw UsageError{"--time " + format_param_value(po.time) + ": " + a.positional[0] + "'s time runs from " + format_param_value(gt->start) +
                                     " to " + format_param_value(gt->end) + " s",
                                 "preview"};
            session->set_time(po.time);
        }
        prepared = preview::prepare_graph_preview(*session, po, how, a.positional[0]);
    } else {
        std::vector<std::filesystem::path> files(a.positional.begin(), a.positional.end());
        prepared = preview::prepare_file_preview(files, po, how);
    }
    depends = prepared.depends;
    if (!quiet)
        for (const std::string& line : prepared.log) std::fprintf(stderr, "%s\n", line.c_str());
    render::PreviewJob& job = prepared.job;
    const bool have_voxel = prepared.voxel, have_layer = prepared.layer;
    const Field3DPtr forecast = prepared.forecast;
    const int slice0 = prepared.slice;
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
    // A graph with a time range steps its own time, a frame (1 / fps) at a time by
    // default: keyed parameters change, and each frame re-cooks what reads them.
    const bool timed = sequence && from_graph && session && session->graph().time;
    const double time_step = a.has("--time-step") ? numbers(a.get("--time-step"), 1, "--time-step")[0]
                                                  : (timed ? 1.0 / session->graph().time->fps : 60.0);
    const double graph_time0 = timed ? session->graph().current_time : 0.0;
    if (timed && graph_time0 + (frames - 1) * time_step > session->graph().time->end + 1e-9)
        throw UsageError{"--frames " + std::to_string(frames) + " from " + format_param_value(graph_time0) + " s, " + format_param_value(time_step) +
                             " s apart, runs past the graph's end at " + format_param_value(session->graph().time->end) + " s",
                         "preview"};
    // A sequence can also be one animation and one contact sheet, staged and
    // committed with its frames.
    for (const char* opt : {"--animation", "--contact-sheet", "--fps", "--animation-quality"})
        if (a.has(opt) && frames == 0) throw UsageError{std::string(opt) + " needs --frames N or --turntable N", "preview"};
    if ((a.has("--fps") || a.has("--animation-quality")) && !a.has("--animation"))
        throw UsageError{std::string(a.has("--fps") ? "--fps" : "--animation-quality") + " needs --animation FILE.webp", "preview"};
    const std::filesystem::path animation_path = a.has("--animation") ? std::filesystem::path(a.get("--animation")) : std::filesystem::path();
    const std::filesystem::path sheet_path = a.has("--contact-sheet") ? std::filesystem::path(a.get("--contact-sheet")) : std::filesystem::path();
    if (!animation_path.empty() && animation_path.extension() != ".webp")
        throw UsageError{"--animation writes an animated WebP: name it .webp, not '" + animation_path.string() + "'", "preview"};
    if (!sheet_path.empty() && sheet_path.extension() == ".exr")
        throw UsageError{"--contact-sheet writes a tone-mapped picture (.png), not EXR", "preview"};
    io::AnimationOptions anim_options;
    if (a.has("--fps")) anim_options.fps = numbers(a.get("--fps"), 1, "--fps")[0];
    if (a.has("--animation-quality")) anim_options.quality = static_cast<int>(numbers(a.get("--animation-quality"), 1, "--animation-quality")[0]);
    std::unique_ptr<io::AnimationWriter> animation;
    if (!animation_path.empty()) animation = std::make_unique<io::AnimationWriter>(w, h, anim_options);
    std::unique_ptr<render::ContactSheet> sheet;
    if (!sheet_path.empty()) sheet = std::make_unique<render::ContactSheet>(frames, w, h);
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
                if (timed && i > 0) {
                    // The camera stays where frame 0 put it (a default camera frames
                    // each frame's clouds, and the view would jump).
                    const render::Camera camera = s.camera;
                    session->set_time(graph_time0 + i * time_step);
                    prepared = preview::prepare_graph_preview(*session, po, how, a.positional[0]);
                    s.camera = camera;
                }
                // A time sequence: the wind scroll advances, each frame a new flash,
                // and a forecast its next time slice (the envelope follows the slice).
                if (have_layer) {
                    render::LayerScene& layer_now = *job.layer;
                    layer_now.time = time0 + i * time_step;
                    if (forecast) {
                        layer_now.ndf = render::weather_map_as_set(preview::forecast_slice(*forecast, (slice0 + i) % forecast->nz()));
                        if (layer_now.envelope.cone_map) layer_now.envelope.cone_map = render::cloud_top_cone_map(*layer_now.ndf);
                    }
                }
                for (auto& f : s.light_fields) f.flash = flash0 + i;
            } else if (have_layer) {
                s.camera = render::layer_camera(*job.layer, render::LayerView::Orbit, double(w) / h, 30 + 360.0 * i / frames, po.elevation);
            } else {
                s.camera = render::framing_camera(have_voxel && from_graph ? render::cloud_bounds(*job.voxel) : bounds, double(w) / h,
                                                  30 + 360.0 * i / frames);
            }
            Field2D image = render_frame();
            char suffix[32];
            std::snprintf(suffix, sizeof suffix, "_%03d", i);
            const std::filesystem::path name = out.stem().string() + suffix + out.extension().string();
            // Tone-mapped once for the frame, the animation and the sheet.
            std::optional<Field2D> shown;
            if (animation || sheet) shown = render::tone_map(image, exposure);
            write_picture(image, staged.stage(name), exposure, shown ? &*shown : nullptr);
            paths.push_back(out.parent_path() / name);
            if (animation) animation->add(*shown);
            if (sheet) sheet->add(i, *shown);
        }
        // The animation and the sheet sit where they were asked for: staged
        // beside OUT when they share its folder, else each atomically.
        auto extra = [&](const std::filesystem::path& p, const std::function<void(const std::filesystem::path&)>& write) {
            const std::filesystem::path folder = p.parent_path().empty() ? std::filesystem::path(".") : p.parent_path();
            const std::filesystem::path out_folder = out.parent_path().empty() ? std::filesystem::path(".") : out.parent_path();
            std::error_code ec;
            if (std::filesystem::equivalent(folder, out_folder, ec)) {
                write(staged.stage(p.filename()));
            } else {
                write_file_atomic(p, write);
            }
            paths.push_back(p);
        };
        if (animation) extra(animation_path, [&](const std::filesystem::path& t) { animation->write(t); });
        if (sheet) extra(sheet_path, [&](const std::filesystem::path& t) { io::write_image(sheet->sheet(), t); });
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
    std::unique_ptr<Session> session;
    if (!a.has("--watch")) return preview_once(a, depends, session);
    if (a.positional.size() != 1 || !is_graph(a.positional[0])) throw UsageError{"--watch needs one graph file", "preview"};
    const int max_rounds = a.has("--watch-max") ? static_cast<int>(numbers(a.get("--watch-max"), 1, "--watch-max")[0]) : -1;
    depends = {a.positional[0]};
    auto round = [&] {
        try {
            preview_once(a, depends, session);
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
