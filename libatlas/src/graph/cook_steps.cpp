// The cook's steps shared by the evaluator and the tiled cook (cook_steps.h).
#include "cook_steps.h"
#include "graph_walk.h"

#include "atlas/core/hash.h"
#include "atlas/core/parallel.h"
#include "atlas/io/writers.h"
#include "atlas/core/progress.h"

#include <chrono>
#include <functional>
#include <set>

namespace atlas::detail {

std::vector<const GraphOutput*> select_outputs(const Graph& g, const std::vector<std::string>& wanted) {
    std::vector<const GraphOutput*> outputs;
    const std::set<std::string> requested(wanted.begin(), wanted.end());
    std::set<std::string> matched;
    for (const auto& o : g.outputs) {
        const bool take = requested.empty() || requested.count(o.file) || requested.count(o.node);
        if (requested.count(o.file)) matched.insert(o.file);
        if (requested.count(o.node)) matched.insert(o.node);
        if (take) outputs.push_back(&o);
    }
    for (const auto& r : requested) {
        if (matched.count(r)) continue;
        std::vector<std::string> names;
        for (const auto& o : g.outputs) names.push_back(o.file);
        throw Error("unknown output '" + r + "'" + name_hint(r, names, "the graph writes"));
    }
    return outputs;
}

std::vector<const GraphNode*> needed_nodes(const Graph& g, const std::vector<std::string>& targets) {
    std::set<std::string> needed;
    std::function<void(const std::string&)> mark = [&](const std::string& name) {
        if (!needed.insert(name).second) return;
        for (const auto& [port, b] : g.find(name)->inputs) mark(b.node);
    };
    for (const auto& t : targets) mark(t);
    std::vector<const GraphNode*> order;
    for (const GraphNode* n : topological_order(g))
        if (needed.count(n->name)) order.push_back(n);
    return order;
}

NodeRun cook_node(const GraphNode& n, const NodeType& type, const NodeParams& params, std::map<std::string, Value> inputs,
                  const MemoryBudget& budget, const ProgressSink& progress, const TileWindow* window) {
    CookContext ctx(n.name, n.type, type.decl, params, std::move(inputs), budget, progress);
    ctx.set_window(window);
    const auto t0 = std::chrono::steady_clock::now();
    {
        // The node's parallel loops poll Ctrl-C between blocks.
        const CancelScope cancel_scope(&progress.is_cancelled);
        type.cook(ctx);
    }
    NodeRun run;
    run.seconds = seconds_since(t0);
    for (const auto& out : type.decl.outputs())
        if (!ctx.outputs().count(out.name)) throw Error("internal: node did not set its output '" + out.name + "'");
    run.outputs = ctx.outputs();
    run.metrics = ctx.metrics();
    run.warnings = ctx.warnings();
    return run;
}

OutputPlace output_place(const std::filesystem::path& out_dir, const GraphOutput& o, bool allow_outside,
                         const std::vector<ProtectedFile>& protect) {
    const std::filesystem::path final_path = resolve_output_path(out_dir, o.file, allow_outside);
    check_destination(final_path, protect);
    OutputPlace p{out_dir, std::filesystem::path(o.file).lexically_normal()};
    if (std::filesystem::path(o.file).is_absolute() || p.rel.begin()->string() == "..") {
        p.root = final_path.parent_path();
        p.rel = final_path.filename();
    }
    return p;
}

// Bump when the output records' meaning changes (every output is written again on
// the next cook); one writer's byte changes bump that writer's version instead.
constexpr int kOutputFormatVersion = 1;

OutputSpec output_spec(const GraphOutput& o, const std::string& name, const Hash128& node_hash) {
    // The format's own writer version (io::OutputFormat::version; the DDS encoder's
    // compress::kEncoderVersion), so a changed writer rewrites its outputs by itself.
    int writer_version = 0;
    for (const io::OutputFormat& f : io::output_formats())
        if (f.name == o.format) writer_version = f.version;
    Hasher spec;
    spec.add("atlas-output").add(int64_t(kOutputFormatVersion)).add(int64_t(writer_version)).add(o.port).add(o.format).add(name);
    for (const auto& [k, v] : o.options) spec.add(k).add(v);
    return {spec.finish().hex(), Hasher(spec).add(node_hash).finish()};
}

std::string output_error(const GraphOutput& o, const std::string& message) {
    return o.where.str() + ": " + (message.rfind("output '", 0) == 0 ? message : "output '" + o.file + "': " + message);
}

} // namespace atlas::detail
