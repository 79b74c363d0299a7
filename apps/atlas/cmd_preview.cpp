// atlas preview (GRAPH | FILES...): render an NVDF set with the preview
// ray-marcher (libatlas/render) to PNG or EXR; --sweep prints fast-vs-
// reference error and time per quality; --turntable writes N frames.
#include "cli.h"
#include "progress_bar.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "atlas/graph/evaluator.h"
#include "atlas/io/readers.h"
#include "atlas/render/image_out.h"
#include "atlas/render/renderer.h"
#include "atlas/render/sweep.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <optional>
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

// The NVDF set a graph writes: the first volume/nvdf node with an output.
// Cooked like `atlas cook` (same disk cache, so a second preview of an
// unchanged graph cooks nothing) but without writing the graph's files.
render::CloudScene scene_from_graph(const std::string& file, int jobs, ProgressSink progress,
                                    const std::optional<std::filesystem::path>& cache_dir, bool quiet) {
    Session session(builtin_nodes());
    session.load(file);
    for (const auto& out : session.graph().outputs) {
        const GraphNode* n = session.graph().find(out.node);
        if (!n || n->type != "volume/nvdf") continue;
        CookOptions o;
        o.write_outputs = false;
        o.jobs = jobs;
        o.cache_dir = cache_dir;
        o.progress = std::move(progress);
        o.outputs = {out.file};
        const CookResult r = session.cook(o);
        if (!quiet)
            std::fprintf(stderr, "graph: cooked %zu, cached %zu nodes in %.2f s%s\n", r.with_status("cooked").size(),
                         r.with_status("cached").size(), r.seconds, cache_dir ? (" (cache " + cache_dir->string() + ")").c_str() : "");
        Value v = session.get(out.node, "vdb_set", o); // from the session's memory cache now
        return render::scene_from_nvdf_set(std::get<Field3DPtr>(v));
    }
    throw Error(file + ": the graph writes no volume/nvdf output to preview");
}

// Writes into `staged` (a temporary path); the caller moves it into place.
void write_picture(const Field2D& image, const std::filesystem::path& staged, double exposure) {
    auto ext = staged.extension().string();
    if (ext == ".exr") render::write_preview_exr(image, staged);
    else render::write_preview_png(image, staged, exposure);
}

// A picture written atomically: a failed render or write leaves no file.
void write_picture_atomic(const Field2D& image, const std::filesystem::path& path, double exposure) {
    write_file_atomic(path, [&](const std::filesystem::path& tmp) { write_picture(image, tmp, exposure); });
}

render::PointLight parse_light(const std::string& text) {
    const size_t n = std::count(text.begin(), text.end(), ',') + 1;
    if (n != 7 && n != 8) throw UsageError{"--light expects X,Y,Z,R,G,B,INTENSITY[,RADIUS], got '" + text + "'", "preview"};
    auto v = numbers(text, n, "--light");
    render::PointLight l;
    l.position = {{v[0], v[1], v[2]}};
    l.colour = {{float(v[3]), float(v[4]), float(v[5])}};
    l.intensity = v[6];
    l.radius = n == 8 ? v[7] : 0.0;
    return l;
}

} // namespace

int run_preview(const Args& a) {
    if (a.positional.empty()) throw UsageError{"expected a graph file or NVDF files", "preview"};
    if (!a.has("--out") && !a.has("--sweep")) throw UsageError{"expected -o OUT.png (or OUT.exr)", "preview"};
    int jobs = 0;
    if (a.has("--jobs")) {
        jobs = static_cast<int>(numbers(a.get("--jobs"), 1, "--jobs")[0]);
        if (jobs < 1 || jobs > 1024) throw UsageError{"--jobs expects a number of threads >= 1", "preview"};
    }
    int w = 960, h = 540;
    if (a.has("--size")) {
        std::string s = a.get("--size");
        auto x = s.find('x');
        if (x == std::string::npos) throw UsageError{"--size expects WxH, e.g. 960x540, got '" + s + "'", "preview"};
        w = static_cast<int>(numbers(s.substr(0, x), 1, "--size")[0]);
        h = static_cast<int>(numbers(s.substr(x + 1), 1, "--size")[0]);
    }
    const bool quiet = a.has("--quiet");
    ProgressBar bar(!quiet);
    ProgressSink sink = bar.sink();

    Field3DPtr noise;
    if (a.has("--noise")) noise = io::as_field3d(io::read_field_file(a.get("--noise")));
    if (a.has("--cache") && a.has("--no-cache")) throw UsageError{"--cache and --no-cache contradict each other", "preview"};
    std::optional<std::filesystem::path> cache_dir;
    if (a.has("--cache")) cache_dir = a.get("--cache");
    else if (const char* env = std::getenv("ATLAS_CACHE_DIR"); env && *env && !a.has("--no-cache")) cache_dir = env;
    render::CloudScene scene;
    if (a.positional.size() == 1 && is_graph(a.positional[0])) {
        scene = scene_from_graph(a.positional[0], jobs, sink, cache_dir, quiet);
    } else {
        std::vector<std::filesystem::path> files(a.positional.begin(), a.positional.end());
        scene = render::load_scene(files, a.has("--voxel") ? numbers(a.get("--voxel"), 1, "--voxel")[0] : 0.0);
    }
    scene.noise = noise;
    if (a.has("--noise-tile")) scene.noise_tile = numbers(a.get("--noise-tile"), 1, "--noise-tile")[0];
    render::validate_scene(scene);

    const Box3d bounds = scene.modeling->bounds();
    render::RenderSettings s = render::preview_settings(bounds, w, h);
    s.threads = jobs;
    if (a.has("--camera")) {
        auto v = numbers(a.get("--camera"), 6, "--camera");
        s.camera.position = {{v[0], v[1], v[2]}};
        s.camera.look_at = {{v[3], v[4], v[5]}};
    }
    if (a.has("--fov")) s.camera.fov_deg = numbers(a.get("--fov"), 1, "--fov")[0];
    if (a.has("--sun")) {
        auto v = numbers(a.get("--sun"), 2, "--sun");
        s.sun_direction = render::sun_direction(v[0], v[1]);
    }
    if (a.has("--quality")) s.quality = numbers(a.get("--quality"), 1, "--quality")[0];
    if (a.has("--extinction")) s.extinction = numbers(a.get("--extinction"), 1, "--extinction")[0];
    if (a.has("--reference")) s.mode = render::RenderMode::Reference;
    if (a.has("--sky")) {
        auto v = numbers(a.get("--sky"), 6, "--sky");
        s.sky_colour = {{float(v[0]), float(v[1]), float(v[2])}};
        s.sky_horizon = Vec3f{{float(v[3]), float(v[4]), float(v[5])}};
    }
    for (const auto& l : a.all("--light")) s.lights.push_back(parse_light(l));
    const double exposure = a.has("--exposure") ? numbers(a.get("--exposure"), 1, "--exposure")[0] : 1.5;

    if (a.has("--sweep")) {
        auto r = render::quality_sweep(scene, s, {0.25, 0.5, 1, 2, 4}, &sink);
        bar.finish();
        // stdout: the table (data); a CSV-friendly layout.
        std::printf("quality,seconds,rmse_radiance,rmse_transmittance\n");
        std::printf("reference,%.3f,0,0\n", r.reference_seconds);
        for (const auto& row : r.rows) std::printf("%g,%.3f,%.6f,%.6f\n", row.quality, row.seconds, row.rmse, row.transmittance_rmse);
        if (a.has("--out")) write_picture_atomic(r.reference, a.get("--out"), exposure);
        return 0;
    }

    const std::filesystem::path out = a.get("--out");
    const int frames = a.has("--turntable") ? static_cast<int>(numbers(a.get("--turntable"), 1, "--turntable")[0]) : 0;
    if (a.has("--turntable") && (frames < 1 || frames > 3600)) throw UsageError{"--turntable expects 1..3600 frames", "preview"};
    auto t0 = std::chrono::steady_clock::now();
    render::RenderReport report;
    if (frames == 0) {
        auto r = render::render_clouds(scene, s, &sink);
        report = r.report;
        write_picture_atomic(r.image, out, exposure);
        bar.finish();
        std::cout << out.string() << "\n";
    } else {
        // All frames or none: staged beside OUT, moved into place at the end.
        StagedOutputs staged(out.parent_path().empty() ? std::filesystem::path(".") : out.parent_path());
        std::vector<std::filesystem::path> paths;
        for (int i = 0; i < frames; ++i) {
            s.camera = render::framing_camera(bounds, double(w) / h, 30 + 360.0 * i / frames);
            auto r = render::render_clouds(scene, s, &sink);
            report = r.report;
            char suffix[32];
            std::snprintf(suffix, sizeof suffix, "_%03d", i);
            const std::filesystem::path name = out.stem().string() + suffix + out.extension().string();
            write_picture(r.image, staged.stage(name), exposure);
            paths.push_back(out.parent_path() / name);
        }
        staged.commit();
        bar.finish();
        for (const auto& p : paths) std::cout << p.string() << "\n";
    }
    if (!quiet) {
        const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        std::string features;
        for (const auto& f : report.active_features()) features += " " + f;
        std::fprintf(stderr, "rendered %dx%d%s in %.2f s; features:%s\n", w, h, frames ? (" x" + std::to_string(frames)).c_str() : "", secs,
                     features.c_str());
    }
    return 0;
}

} // namespace atlas::cli
