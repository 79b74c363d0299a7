// atlas cook / atlas validate.
#include "cli.h"
#include "progress_bar.h"

#include "atlas/core/files.h"
#include "atlas/core/memory.h"
#include "atlas/graph/evaluator.h"

#include <cstdlib>
#include <fstream>
#include <iostream>

namespace atlas::cli {

namespace {
void apply_sets(Session& s, const Args& a, const std::string& cmd) {
    for (const auto& kv : a.all("--set")) {
        auto eq = kv.find('=');
        auto dot = kv.find('.');
        if (eq == std::string::npos || dot == std::string::npos || dot > eq)
            throw UsageError{"--set expects NODE.PARAM=VALUE, got '" + kv + "'", cmd};
        s.set_text(kv.substr(0, dot), kv.substr(dot + 1, eq - dot - 1), kv.substr(eq + 1));
    }
}

std::string one_graph(const Args& a, const std::string& cmd) {
    if (a.positional.size() != 1) throw UsageError{"expected one graph file, got " + std::to_string(a.positional.size()), cmd};
    return a.positional[0];
}
} // namespace

int run_cook(const Args& a) {
    const std::string file = one_graph(a, "cook");
    const bool quiet = a.has("--quiet");
    Session session(builtin_nodes());
    session.load(file);
    apply_sets(session, a, "cook");

    CookOptions o;
    o.out_dir = a.get("--out", ".");
    o.outputs = a.all("--output");
    o.checked = a.has("--checked");
    o.allow_outside_out = a.has("--allow-outside-out");
    if (a.has("--jobs")) {
        try {
            o.jobs = std::stoi(a.get("--jobs"));
        } catch (...) {
            o.jobs = -1;
        }
        if (o.jobs < 1 || o.jobs > 1024) throw UsageError{"--jobs expects a number of threads >= 1, got '" + a.get("--jobs") + "'", "cook"};
    }
    if (a.has("--memory-budget")) o.memory_budget = parse_byte_size(a.get("--memory-budget"));
    if (a.has("--cache") && a.has("--no-cache")) throw UsageError{"--cache and --no-cache contradict each other", "cook"};
    if (a.has("--cache")) o.cache_dir = a.get("--cache");
    else if (const char* env = std::getenv("ATLAS_CACHE_DIR"); env && *env && !a.has("--no-cache")) o.cache_dir = env;

    ProgressBar bar(!quiet);
    o.progress = bar.sink();
    CookResult r = session.cook(o);
    bar.finish();

    if (a.has("--report")) {
        std::string json = r.to_json(file);
        write_file_atomic(a.get("--report"), [&](const std::filesystem::path& tmp) {
            std::ofstream f(tmp);
            f << json;
            if (!f) throw Error(a.get("--report") + ": cannot write report");
        });
    }
    size_t files = 0;
    for (const auto& out : r.outputs) files += out.written.size();
    // stdout: one summary line, then the written files (data for scripts).
    std::cout << "cooked " << r.with_status("cooked").size() << ", cached " << r.with_status("cached").size() << ", skipped "
              << r.with_status("skipped").size() << " nodes in " << r.seconds << " s; wrote " << files << " files to "
              << o.out_dir.string() << "\n";
    for (const auto& out : r.outputs)
        for (const auto& p : out.written) std::cout << p.string() << "\n";
    if (!quiet)
        for (const auto& [name, nr] : r.nodes)
            for (const auto& w : nr.warnings) std::cerr << file << ": warning: node '" << name << "': " << w << "\n";
    return 0;
}

int run_validate(const Args& a) {
    const std::string file = one_graph(a, "validate");
    Session session(builtin_nodes());
    session.load(file);
    apply_sets(session, a, "validate");
    const Graph& g = session.graph();
    std::cout << file << ": ok (" << g.nodes.size() << " nodes, " << g.outputs.size() << " outputs)\n";
    return 0;
}

} // namespace atlas::cli
