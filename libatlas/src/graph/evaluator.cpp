// The evaluator: pull what the requested outputs need, hash before compute,
// serve from cache, cook the rest level by level in parallel, write outputs
// atomically.
#include "atlas/graph/evaluator.h"

#include "atlas/core/files.h"
#include "atlas/io/writers.h"
#include "value_cache.h"

#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <functional>
#include <set>

namespace atlas {

namespace {

double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// Prefixes an error with the node it came from (unless it already names it).
[[noreturn]] void rethrow_for_node(const std::string& name, const std::string& type, std::exception_ptr ep) {
    try {
        std::rethrow_exception(ep);
    } catch (const CancelledError&) {
        throw;
    } catch (const MemoryBudgetError& e) {
        std::string msg = e.what();
        if (msg.rfind("node '", 0) == 0) throw;
        throw MemoryBudgetError("node '" + name + "' (" + type + "): " + msg);
    } catch (const Error& e) {
        std::string msg = e.what();
        if (msg.rfind("node '" + name + "'", 0) == 0) throw;
        throw Error("node '" + name + "' (" + type + "): " + msg);
    } catch (const std::bad_alloc&) {
        throw MemoryBudgetError("node '" + name + "' (" + type + "): out of memory");
    } catch (const std::exception& e) {
        throw Error("node '" + name + "' (" + type + "): " + e.what());
    }
}

struct NodeState {
    const GraphNode* node = nullptr;
    const NodeType* type = nullptr;
    Hash128 hash;
    bool needed = false;   // some requested output depends on it
    bool required = false; // its value must be present in this cook
    bool cook = false;     // it will be cooked
    std::shared_ptr<const NodeOutputs> cached; // value found in a cache
    std::string cache_source;
    int level = 0;
};

} // namespace

// ------------------------------------------------------------------ Session

Session::Session(NodeRegistry registry) : registry_(std::move(registry)), cache_(std::make_unique<ValueCache>()) {}
Session::~Session() = default;
Session::Session(Session&&) noexcept = default;
Session& Session::operator=(Session&&) noexcept = default;

void Session::load(const std::filesystem::path& graph_file) { graph_ = std::make_unique<Graph>(load_graph(graph_file, registry_)); }

void Session::load_text(const std::string& text, const std::string& name, const std::filesystem::path& base_dir) {
    graph_ = std::make_unique<Graph>(parse_graph(text, name, base_dir, registry_));
}

const Graph& Session::graph() const {
    if (!graph_) throw Error("no graph loaded");
    return *graph_;
}

void Session::set(const std::string& node, const std::string& param, const ParamValue& value) {
    if (!graph_) throw Error("no graph loaded");
    set_param(*graph_, registry_, node, param, value);
}

void Session::set_text(const std::string& node, const std::string& param, const std::string& text) {
    if (!graph_) throw Error("no graph loaded");
    set_param_text(*graph_, registry_, node, param, text, "--set " + node + "." + param + "=" + text);
}

namespace {

// Topological order (inputs first) of every node, following file order.
std::vector<const GraphNode*> topological_order(const Graph& g) {
    std::vector<const GraphNode*> order;
    std::set<std::string> done;
    std::function<void(const GraphNode&)> visit = [&](const GraphNode& n) {
        if (done.count(n.name)) return;
        done.insert(n.name);
        for (const auto& [port, b] : n.inputs) visit(*g.find(b.node));
        order.push_back(&n);
    };
    for (const auto& n : g.nodes) visit(n);
    return order;
}

std::string source_port(const Graph& g, const NodeRegistry& reg, const InputBinding& b) {
    if (!b.port.empty()) return b.port;
    return reg.find(g.find(b.node)->type)->decl.outputs().front().name;
}

Hash128 node_hash(const Graph& g, const NodeRegistry& reg, const GraphNode& n, const NodeType& type,
                  const std::map<std::string, Hash128>& input_hashes) {
    Hasher h;
    h.add("atlas-node").add(type.name).add(int64_t(type.version));
    auto params = resolved_params(n, type);
    for (const auto& d : type.decl.params()) {
        h.add(d.name);
        hash_param_value(h, params.at(d.name));
    }
    if (type.hash_extra) {
        NodeParams np(&type.decl, params, g.base_dir);
        try {
            type.hash_extra(np, h);
        } catch (...) {
            rethrow_for_node(n.name, n.type, std::current_exception());
        }
    }
    for (const auto& in : type.decl.inputs()) {
        h.add(in.name);
        auto it = n.inputs.find(in.name);
        if (it == n.inputs.end()) {
            h.add("unconnected");
        } else {
            h.add(input_hashes.at(it->second.node)).add(source_port(g, reg, it->second));
        }
    }
    return h.finish();
}

} // namespace

std::map<std::string, Hash128> Session::node_hashes() const {
    const Graph& g = graph();
    std::map<std::string, Hash128> hashes;
    for (const GraphNode* n : topological_order(g)) hashes[n->name] = node_hash(g, registry_, *n, *registry_.find(n->type), hashes);
    return hashes;
}

CookResult Session::cook(const CookOptions& options) { return run(options, nullptr, nullptr); }

Value Session::get(const std::string& node, const std::string& port, const CookOptions& options) {
    CookOptions o = options;
    o.write_outputs = false;
    std::vector<std::pair<std::string, std::string>> want{{node, port}};
    std::vector<Value> values;
    run(o, &want, &values);
    return values.at(0);
}

CookResult Session::run(const CookOptions& opt, const std::vector<std::pair<std::string, std::string>>* want_value,
                        std::vector<Value>* values_out) {
    const auto t_start = std::chrono::steady_clock::now();
    const Graph& g = graph();
    const int jobs = opt.jobs > 0 ? opt.jobs : int(tbb::info::default_concurrency());
    const MemoryBudget budget(opt.memory_budget);

    // 1. Targets: the requested graph outputs, or explicit node ports.
    std::vector<const GraphOutput*> outputs;
    std::vector<std::pair<std::string, std::string>> targets;
    if (want_value) {
        for (const auto& [node, port] : *want_value) {
            const GraphNode* n = g.find(node);
            if (!n) throw Error("unknown node '" + node + "'");
            const NodeType* t = registry_.find(n->type);
            std::string p = port.empty() ? t->decl.outputs().front().name : port;
            if (!t->decl.find_output(p)) throw Error("node '" + node + "' (" + n->type + ") has no output '" + p + "'");
            targets.emplace_back(node, p);
        }
    } else {
        std::set<std::string> requested(opt.outputs.begin(), opt.outputs.end());
        std::set<std::string> matched;
        for (const auto& o : g.outputs) {
            bool take = requested.empty() || requested.count(o.file) || requested.count(o.node);
            if (requested.count(o.file)) matched.insert(o.file);
            if (requested.count(o.node)) matched.insert(o.node);
            if (take) {
                outputs.push_back(&o);
                targets.emplace_back(o.node, o.port);
            }
        }
        for (const auto& r : requested) {
            if (matched.count(r)) continue;
            std::vector<std::string> names;
            for (const auto& o : g.outputs) names.push_back(o.file);
            throw Error("unknown output '" + r + "'" + name_hint(r, names, "the graph writes"));
        }
    }

    // 2. What the targets need, in topological order.
    std::map<std::string, NodeState> state;
    for (const auto& n : g.nodes) state[n.name] = {&n, registry_.find(n.type)};
    std::function<void(const std::string&)> mark = [&](const std::string& name) {
        NodeState& s = state.at(name);
        if (s.needed) return;
        s.needed = true;
        for (const auto& [port, b] : s.node->inputs) mark(b.node);
    };
    for (const auto& t : targets) mark(t.first);
    std::vector<const GraphNode*> order;
    for (const GraphNode* n : topological_order(g))
        if (state.at(n->name).needed) order.push_back(n);

    // 3. Hash before compute (only what is needed: an unused import node's
    //    missing file is not an error).
    std::map<std::string, Hash128> hashes;
    for (const GraphNode* n : order) {
        NodeState& s = state.at(n->name);
        s.hash = node_hash(g, registry_, *n, *s.type, hashes);
        hashes[n->name] = s.hash;
    }

    // 4. Decide, consumers before producers, what must be present and cooked.
    for (const auto& t : targets) state.at(t.first).required = true;
    for (auto it = order.rbegin(); it != order.rend(); ++it) {
        NodeState& s = state.at((*it)->name);
        if (!s.required) continue;
        if (auto hit = cache_->find(s.hash)) {
            s.cached = hit;
            s.cache_source = "memory cache";
        } else if (opt.cache_dir && disk_cache::contains(*opt.cache_dir, s.hash)) {
            if (auto loaded = disk_cache::load(*opt.cache_dir, s.hash)) {
                s.cached = std::make_shared<const NodeOutputs>(std::move(*loaded));
                s.cache_source = "disk cache";
                cache_->put(s.hash, s.cached);
            }
        }
        s.cook = opt.checked || !s.cached;
        if (s.cook)
            for (const auto& [port, b] : (*it)->inputs) state.at(b.node).required = true;
    }

    // 5. Levels: a node cooks after every producer it cooks from.
    std::vector<std::vector<const GraphNode*>> levels;
    for (const GraphNode* n : order) {
        NodeState& s = state.at(n->name);
        if (!s.cook) continue;
        int lvl = 0;
        for (const auto& [port, b] : n->inputs) {
            const NodeState& src = state.at(b.node);
            if (src.cook) lvl = std::max(lvl, src.level + 1);
        }
        s.level = lvl;
        if (int(levels.size()) <= lvl) levels.resize(size_t(lvl) + 1);
        levels[size_t(lvl)].push_back(n);
    }
    int total = 0;
    for (const auto& l : levels) total += int(l.size());

    CookResult result;
    result.jobs = jobs;
    result.checked = opt.checked;
    std::map<std::string, std::shared_ptr<const NodeOutputs>> values;
    for (const GraphNode* n : order) {
        const NodeState& s = state.at(n->name);
        if (s.required && !s.cook) values[n->name] = s.cached;
    }

    // 6. Cook, level by level; nodes of one level in parallel.
    std::atomic<int> done{0};
    auto report_progress = [&](const std::string& task, double node_fraction) {
        if (!opt.progress.on_progress) return;
        double f = total ? (done.load() + node_fraction) / total : 1.0;
        opt.progress.on_progress({task, std::min(1.0, f), done.load(), total});
    };
    tbb::task_arena arena(jobs);
    for (const auto& level : levels) {
        std::vector<std::exception_ptr> errors(level.size());
        std::vector<NodeReport> reports(level.size());
        std::vector<std::shared_ptr<const NodeOutputs>> produced(level.size());
        arena.execute([&] {
            tbb::parallel_for(size_t(0), level.size(), size_t(1), [&](size_t i) {
                const GraphNode& n = *level[i];
                const NodeState& s = state.at(n.name);
                try {
                    opt.progress.poll();
                    std::map<std::string, Value> inputs;
                    // `values` is only written between levels, so reading it here needs no lock.
                    for (const auto& [port, b] : n.inputs) inputs[port] = values.at(b.node)->at(source_port(g, registry_, b));
                    NodeParams params(&s.type->decl, resolved_params(n, *s.type), g.base_dir);
                    ProgressSink node_progress;
                    node_progress.is_cancelled = opt.progress.is_cancelled;
                    node_progress.on_progress = [&, name = n.name](const ProgressEvent& e) { report_progress("node '" + name + "'", e.fraction); };
                    CookContext ctx(n.name, n.type, s.type->decl, params, std::move(inputs), budget, node_progress);
                    report_progress("node '" + n.name + "'", 0.0);
                    const auto t0 = std::chrono::steady_clock::now();
                    s.type->cook(ctx);
                    reports[i].seconds = seconds_since(t0);
                    for (const auto& out : s.type->decl.outputs())
                        if (!ctx.outputs().count(out.name))
                            throw Error("internal: node did not set its output '" + out.name + "'");
                    auto outs = std::make_shared<NodeOutputs>(ctx.outputs());
                    reports[i].metrics = ctx.metrics();
                    reports[i].warnings = ctx.warnings();
                    produced[i] = outs;
                } catch (...) {
                    errors[i] = std::current_exception();
                }
                done.fetch_add(1);
                report_progress("node '" + n.name + "'", 0.0);
            });
        });
        // Deterministic error choice: the first failing node in level order.
        for (size_t i = 0; i < level.size(); ++i)
            if (errors[i]) rethrow_for_node(level[i]->name, level[i]->type, errors[i]);
        for (size_t i = 0; i < level.size(); ++i) {
            const GraphNode& n = *level[i];
            NodeState& s = state.at(n.name);
            if (opt.checked && s.cached) {
                for (const auto& [port, v] : *s.cached) {
                    auto it = produced[i]->find(port);
                    if (it == produced[i]->end() || !values_equal(v, it->second))
                        throw Error("checked mode: node '" + n.name + "' (" + n.type + "): output '" + port +
                                    "' differs from the cached result with the same hash; the node's hash misses something its cook reads");
                }
            }
            values[n.name] = produced[i];
            cache_->put(s.hash, produced[i]);
            if (opt.cache_dir) disk_cache::store(*opt.cache_dir, s.hash, *produced[i]);
            NodeReport& r = reports[i];
            r.status = "cooked";
            r.reason = opt.checked && s.cached ? "checked mode: re-cooked and matched the " + s.cache_source : "";
            result.nodes[n.name] = std::move(r);
        }
    }

    // 7. Report every node of the graph.
    std::unordered_set<Hash128, Hash128Hasher> keep;
    for (const auto& n : g.nodes) {
        const NodeState& s = state.at(n.name);
        NodeReport& r = result.nodes[n.name];
        r.type = n.type;
        if (s.needed) {
            r.hash = s.hash.hex();
            keep.insert(s.hash);
        }
        if (values.count(n.name) && values.at(n.name))
            for (const auto& [port, v] : *values.at(n.name)) r.bytes += value_bytes(v);
        if (s.cook) continue;
        if (!s.needed) {
            r.status = "skipped";
            r.reason = "not needed by the requested outputs";
        } else if (s.required) {
            r.status = "cached";
            r.reason = s.cache_source;
        } else {
            r.status = "skipped";
            r.reason = "not needed: everything downstream came from the cache";
        }
    }
    // Keep results of nodes that are part of the graph now (needed this time
    // or not); drop stale ones (old parameter values, removed nodes).
    for (const auto& [name, h] : last_hashes_)
        if (g.find(name) && !state.at(name).needed) keep.insert(h);
    for (const auto& n : g.nodes)
        if (state.at(n.name).needed) last_hashes_[n.name] = state.at(n.name).hash;
    cache_->retain_only(keep);

    // 8. Values for the host, or files (all staged, committed together).
    if (values_out)
        for (const auto& t : targets) values_out->push_back(values.at(t.first)->at(t.second));
    if (opt.write_outputs && !outputs.empty()) {
        std::map<std::filesystem::path, std::unique_ptr<StagedOutputs>> staging;
        for (const GraphOutput* o : outputs) {
            try {
                opt.progress.poll();
                std::filesystem::path final_path = resolve_output_path(opt.out_dir, o->file, opt.allow_outside_out);
                std::filesystem::path root = opt.out_dir, rel = std::filesystem::path(o->file).lexically_normal();
                if (std::filesystem::path(o->file).is_absolute() || rel.begin()->string() == "..") {
                    root = final_path.parent_path();
                    rel = final_path.filename();
                }
                auto& st = staging[root];
                if (!st) st = std::make_unique<StagedOutputs>(root);
                if (opt.progress.on_progress) opt.progress.on_progress({"writing " + o->file, 1.0, total, total});
                OutputReport orep{o->node, o->port, o->file, o->format, {}, {}};
                for (const auto& staged : io::write_value(values.at(o->node)->at(o->port), st->stage(rel), o->format, o->options, &orep.metrics))
                    orep.written.push_back(st->final_path(staged));
                result.outputs.push_back(orep);
            } catch (const CancelledError&) {
                throw;
            } catch (const std::exception& e) {
                // Writers already name the output ("output 'x.png': ..."); add the graph position.
                const std::string msg = e.what();
                throw Error(o->where.str() + ": " + (msg.rfind("output '", 0) == 0 ? msg : "output '" + o->file + "': " + msg));
            }
        }
        // Everything written: move it into place.
        for (auto& [root, st] : staging) st->commit();
    } else {
        for (const GraphOutput* o : outputs) result.outputs.push_back({o->node, o->port, o->file, o->format, {}, {}});
    }
    result.seconds = seconds_since(t_start);
    return result;
}

std::vector<std::string> CookResult::with_status(const std::string& status) const {
    std::vector<std::string> v;
    for (const auto& [name, r] : nodes)
        if (r.status == status) v.push_back(name);
    return v;
}

} // namespace atlas
