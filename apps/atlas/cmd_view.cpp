// atlas view GRAPH: the graph's 2.5D cloudscape as a page @takram/three-clouds
// draws in real time (atlas/preview/web_view.h); opens it in a browser.
#include "cli.h"
#include "progress_bar.h"

#include "atlas/graph/evaluator.h"
#include "atlas/preview/graph_preview.h"
#include "atlas/preview/web_view.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>
#include <spawn.h>

extern char** environ;

namespace atlas::cli {

int run_view(const Args& a) {
    if (a.positional.size() != 1) throw UsageError{"expected one graph file", "view"};
    const std::filesystem::path graph = a.positional[0];
    const std::filesystem::path out = a.has("--out") ? std::filesystem::path(a.get("--out")) : graph.stem().concat("_view");
    const render::PreviewOptions po = read_preview_flags(a, "view");
    const bool quiet = a.has("--quiet");
    ProgressBar bar(!quiet);
    preview::GraphPreviewOptions how;
    how.progress = bar.sink();
    how.mode = "layer";
    how.cache_dir = cache_dir_flag(a, "view");
    std::error_code ec;
    const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
    preview::WebViewOptions web;
    web.bundle_dir = preview::find_web_bundle(ec ? std::filesystem::path() : exe.parent_path());
    web.title = graph.filename().string() + " - Atlas, drawn by @takram/three-clouds";

    Session session(builtin_nodes());
    session.load(graph);
    apply_sets(session, a, "view");
    const preview::GraphPreview prepared = preview::prepare_graph_preview(session, po, how, graph);
    const preview::WebViewResult r = preview::write_web_view(prepared, po, out, web);
    bar.finish();
    if (!quiet)
        for (const std::string& line : r.log) std::fprintf(stderr, "%s\n", line.c_str());
    std::cout << r.index.string() << "\n";
    // Open it where there is a display to open it on; a page opened from disk needs no server.
    const bool display = std::getenv("DISPLAY") || std::getenv("WAYLAND_DISPLAY");
    if (a.has("--no-open") || !display) {
        if (!quiet) std::fprintf(stderr, "open %s in a browser with WebGL2 to orbit the clouds\n", r.index.string().c_str());
        return 0;
    }
    const std::string path = r.index.string();
    char* argv[] = {const_cast<char*>("xdg-open"), const_cast<char*>(path.c_str()), nullptr};
    pid_t pid = 0;
    if (posix_spawnp(&pid, "xdg-open", nullptr, nullptr, argv, environ) != 0 && !quiet)
        std::fprintf(stderr, "could not run xdg-open; open %s in a browser with WebGL2\n", path.c_str());
    return 0;
}

} // namespace atlas::cli
