// The evaluator: pull what the requested outputs need, hash before compute,
// serve from cache, cook the rest level by level in parallel, write outputs
// atomically.
#include "atlas/graph/evaluator.h"
#include "cook_run.h"
#include "cook_steps.h"
#include "graph_walk.h"

#include "atlas/core/file_limits.h"
#include "atlas/core/files.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <optional>
#include <exception>
#include <functional>
#include <mutex>
#include <set>

namespace atlas {

namespace {

// Prefixes an error with the node it came from (unless it already names it)
// and the node's place in the graph file (file:line:col), keeping its type.
[[noreturn]] void rethrow_for_node(const std::string& name, const std::string& type, const std::string& where, std::exception_ptr ep) {
    auto located = [&](const std::string& msg, bool named) {
        std::string m = named ? msg : "node '" + name + "' (" + type + "): " + msg;
        if (!where.empty() && m.rfind(where, 0) != 0) m = where + ": " + m;
        return m;
    };
    try {
        std::rethrow_exception(ep);
    } catch (const CancelledError&) {
        throw;
    } catch (const MemoryBudgetError& e) {
        const std::string msg = e.what();
        throw MemoryBudgetError(located(msg, msg.rfind("node '", 0) == 0));
    } catch (const Error& e) {
        const std::string msg = e.what();
        throw Error(located(msg, msg.rfind("node '" + name + "'", 0) == 0));
    } catch (const std::bad_alloc&) {
        throw MemoryBudgetError(located("out of memory", false));
    } catch (const std::exception& e) {
        throw Error(located(e.what(), false));
    }
}

} // namespace

// ------------------------------------------------------------------ Session

Session::Session(NodeRegistry registry)
    : registry_(std::move(registry)), cache_(std::make_unique<ValueCache>()), earlier_(std::make_unique<EarlierOutputs>()) {}
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

std::vector<Session::MissingInput> Session::missing_inputs() const {
    const Graph& g = graph();
    std::vector<MissingInput> missing;
    for (const GraphNode& n : g.nodes) {
        const NodeType* type = registry_.find(n.type);
        if (!type) continue;
        for (const ParamDecl& p : type->decl.params()) {
            if (p.type != ParamType::Path) continue;
            const auto it = n.params.find(p.name);
            const ParamValue& v = it != n.params.end() ? it->second.value : p.default_value;
            const std::string* text = std::get_if<std::string>(&v);
            if (!text || text->empty()) continue;
            const std::filesystem::path path = std::filesystem::path(*text).is_absolute() ? std::filesystem::path(*text) : g.base_dir / *text;
            std::error_code ec;
            if (std::filesystem::exists(n.type == "import/tga_slices" ? path.parent_path() : path, ec)) continue;
            const GraphRequirement* by = nullptr;
            for (const GraphRequirement& r : g.requirements) {
                const auto rel = path.lexically_normal().lexically_relative(r.out);
                if (!rel.empty() && *rel.begin() != "..") by = &r;
            }
            missing.push_back({n.name, n.type, p.name, path, it != n.params.end() ? it->second.where.line : n.where.line, by});
        }
    }
    return missing;
}

namespace {
void cook_requirements_of(const Session& s, const CookOptions& options, const std::function<void(const GraphRequirement&)>& before,
                          std::vector<std::filesystem::path>& chain, std::vector<std::pair<std::string, CookResult>>& done) {
    std::vector<const GraphRequirement*> needed;
    for (const auto& m : s.missing_inputs())
        if (m.written_by && std::find(needed.begin(), needed.end(), m.written_by) == needed.end()) needed.push_back(m.written_by);
    for (const GraphRequirement* r : needed) {
        const auto key = std::filesystem::absolute(r->graph).lexically_normal();
        if (std::find(chain.begin(), chain.end(), key) != chain.end())
            throw ParseError(r->where, "requirement '" + r->graph.string() + "' leads back to a graph that requires it (a cycle)");
        Session sub(s.registry());
        sub.load(r->graph);
        chain.push_back(key);
        cook_requirements_of(sub, options, before, chain, done);
        chain.pop_back();
        if (before) before(*r);
        CookOptions o = options;
        o.out_dir = r->out;
        o.outputs.clear(); // everything it writes: this graph may read any of it
        done.emplace_back(r->graph.string(), CookResult{});
        try {
            done.back().second = sub.cook(o);
        } catch (...) {
            done.back().second = sub.last_result();
            throw;
        }
    }
}
} // namespace

std::vector<std::pair<std::string, CookResult>> Session::cook_requirements(const CookOptions& options,
                                                                           const std::function<void(const GraphRequirement&)>& before) {
    std::vector<std::filesystem::path> chain;
    if (!graph().file.empty()) chain.push_back(std::filesystem::absolute(graph().file).lexically_normal());
    std::vector<std::pair<std::string, CookResult>> done;
    cook_requirements_of(*this, options, before, chain, done);
    return done;
}

void Session::set_time(double t) {
    if (!graph_) throw Error("no graph loaded");
    set_graph_time(*graph_, registry_, t);
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

using detail::source_port;
using detail::topological_order;

Hash128 node_hash(const Graph& g, const NodeRegistry& reg, const GraphNode& n, const NodeType& type,
                  const std::map<std::string, Hash128>& input_hashes, int proxy) {
    Hasher h;
    h.add("atlas-node").add(type.name).add(int64_t(type.version));
    // A proxy cook's scaled parameters are what is hashed: a node with none keeps
    // its full-resolution hash (and cache entry) unless an input changed.
    auto params = resolved_params(n, type, proxy);
    for (const auto& d : type.decl.params()) {
        h.add(d.name);
        hash_param_value(h, params.at(d.name));
    }
    if (type.hash_extra) {
        NodeParams np(&type.decl, params, g.base_dir);
        try {
            type.hash_extra(np, h);
        } catch (...) {
            rethrow_for_node(n.name, n.type, n.where.str(), std::current_exception());
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
    for (const GraphNode* n : topological_order(g)) hashes[n->name] = node_hash(g, registry_, *n, *registry_.find(n->type), hashes, 1);
    return hashes;
}

CookResult Session::cook(const CookOptions& options) {
    // A failed cook commits nothing: outputs it had encoded and staged were
    // never moved into place, so the report must not call them written.
    auto nothing_written = [&] {
        for (OutputReport& o : last_.outputs)
            if (o.status == "written" || o.status == "restored") {
                o.status = "not written";
                o.written.clear();
                o.files.clear();
            }
    };
    try {
        return run(options, nullptr, nullptr);
    } catch (const CancelledError& e) {
        last_.status = "cancelled";
        last_.error = e.what();
        nothing_written();
        throw;
    } catch (const std::exception& e) {
        last_.status = "failed";
        last_.error = e.what();
        nothing_written();
        if (!last_.error_node.empty()) {
            NodeReport& r = last_.nodes[last_.error_node];
            if (graph_)
                if (const GraphNode* n = graph_->find(last_.error_node)) r.type = n->type;
            if (r.status.empty() || r.status == "cooked") {
                r.status = "failed";
                r.reason = e.what();
            }
        }
        throw;
    }
}

Value Session::get(const std::string& node, const std::string& port, const CookOptions& options) {
    return get({{node, port}}, options).at(0);
}

std::vector<Value> Session::get(const std::vector<std::pair<std::string, std::string>>& ports, const CookOptions& options) {
    CookOptions o = options;
    o.write_outputs = false;
    std::vector<Value> values;
    run(o, &ports, &values);
    return values;
}

namespace detail {

CookRun::CookRun(const Graph& g, const NodeRegistry& reg, ValueCache& cache, std::map<std::pair<std::string, int>, Hash128>& last_hashes, EarlierOutputs& earlier,
                 const CookOptions& opt, CookResult& result)
    : g_(g), reg_(reg), cache_(cache), last_hashes_(last_hashes), earlier_(earlier), opt_(opt), result_(result), jobs_(opt.jobs > 0 ? opt.jobs : hardware_threads()),
      budget_(opt.memory_budget), ledger_(cache.ledger()), attached_(budget_, ledger_), evictor_reset_{ledger_, result} {
    ledger_.reset_peak();
    ledger_.set_evictor([c = &cache_](uint64_t missing) { c->evict(missing); });
    result_.memory_budget = opt.memory_budget;
    result_.proxy = opt.proxy;
}

void CookRun::plan(const Wanted* want_value) {
    if (want_value) {
        for (const auto& [node, port] : *want_value) {
            const GraphNode* n = g_.find(node);
            if (!n) throw Error("unknown node '" + node + "'");
            const NodeType* t = reg_.find(n->type);
            std::string p = port.empty() ? t->decl.outputs().front().name : port;
            if (!t->decl.find_output(p)) throw Error("node '" + node + "' (" + n->type + ") has no output '" + p + "'");
            targets_.emplace_back(node, p);
        }
    } else {
        outputs_ = detail::select_outputs(g_, opt_.outputs);
        for (const GraphOutput* o : outputs_) targets_.emplace_back(o->node, o->port);
    }
}

void CookRun::resolve() {
    for (const auto& n : g_.nodes) state_[n.name] = {&n, reg_.find(n.type)};
    std::vector<std::string> nodes;
    for (const auto& t : targets_) nodes.push_back(t.first);
    order_ = detail::needed_nodes(g_, nodes);
    for (const GraphNode* n : order_) state_.at(n->name).needed = true;
}

// Only what is needed is hashed: an unused import node's missing file is not an error.
void CookRun::hash() {
    std::map<std::string, Hash128> hashes;
    for (const GraphNode* n : order_) {
        NodeState& s = state_.at(n->name);
        std::vector<FileRead> reads;
        {
            // What hash_extra reads: the cook's input files (none larger than the budget; Ctrl-C stops a long hash).
            FileReadRecorder recorder(&reads);
            const detail::FileReadLimits limits(opt_.memory_budget, opt_.progress.is_cancelled);
            try {
                s.hash = node_hash(g_, reg_, *n, *s.type, hashes, opt_.proxy);
            } catch (...) {
                result_.error_node = n->name;
                result_.error_where = n->where.str();
                throw;
            }
        }
        for (const auto& r : reads) result_.inputs.push_back({r.path, r.bytes, r.hash.hex(), n->name});
        hashes[n->name] = s.hash;
    }
}

void CookRun::fetch() {
    for (const auto& t : targets_) state_.at(t.first).required = true;
    for (auto it = order_.rbegin(); it != order_.rend(); ++it) {
        NodeState& s = state_.at((*it)->name);
        if (!s.required) continue;
        if (auto hit = cache_.find(s.hash)) {
            s.cached = hit;
            s.cache_source = "memory cache";
        } else if (opt_.cache_dir && disk_cache::contains(*opt_.cache_dir, s.hash)) {
            std::string why;
            auto loaded = disk_cache::load(*opt_.cache_dir, s.hash, &why);
            // Every port the node declares, or the entry is not this node's.
            if (loaded)
                for (const auto& out : s.type->decl.outputs())
                    if (!loaded->count(out.name)) {
                        why = "it has no output '" + out.name + "'";
                        loaded.reset();
                        break;
                    }
            if (loaded) {
                s.cached = held_outputs(std::move(*loaded), ledger_);
                s.cache_source = "disk cache";
                if (opt_.keep_values) cache_.put(s.hash, s.cached);
            } else {
                // A damaged entry is never used: remove it and cook again.
                const auto path = disk_cache::entry_path(*opt_.cache_dir, s.hash);
                std::error_code ec;
                std::filesystem::remove(path, ec);
                warn("disk cache: entry " + path.string() + " of node '" + (*it)->name + "' is unusable (" + why +
                     "); discarded, the node cooks again");
            }
        }
        s.cook = opt_.checked || !s.cached;
        if (s.cook)
            for (const auto& [port, b] : (*it)->inputs) state_.at(b.node).required = true;
    }
    for (const GraphNode* n : order_) {
        const NodeState& s = state_.at(n->name);
        if (s.required && !s.cook) values_[n->name] = s.cached;
    }
}

void CookRun::progress_step(const std::string& task, const std::string& node, double node_fraction, bool finished) {
    if (!opt_.progress.on_progress) return;
    std::lock_guard<std::mutex> lock(progress_mutex_);
    if (finished) {
        ++done_;
        in_flight_.erase(node);
    } else if (!node.empty()) {
        double& f = in_flight_[node];
        f = std::max(f, std::clamp(node_fraction, 0.0, 1.0));
    }
    double sum = done_;
    for (const auto& [name, f] : in_flight_) sum += f;
    shown_ = std::max(shown_, units_ ? std::min(1.0, sum / units_) : 1.0);
    opt_.progress.on_progress({task, shown_, done_, units_});
}

void CookRun::cook() {
    // Levels: a node cooks after every producer it cooks from.
    std::vector<std::vector<const GraphNode*>> levels;
    for (const GraphNode* n : order_) {
        NodeState& s = state_.at(n->name);
        if (!s.cook) continue;
        int lvl = 0;
        for (const auto& [port, b] : n->inputs) {
            const NodeState& src = state_.at(b.node);
            if (src.cook) lvl = std::max(lvl, src.level + 1);
        }
        s.level = lvl;
        if (int(levels.size()) <= lvl) levels.resize(size_t(lvl) + 1);
        levels[size_t(lvl)].push_back(n);
        ++units_;
    }
    result_.jobs = jobs_;
    for (const auto& p : plans_) units_ += p.action != OutputPlan::current;

    auto report_progress = [&](const std::string& name, double node_fraction) { progress_step("node '" + name + "'", name, node_fraction, false); };
    std::map<std::string, int> pending; // consumers still to cook, per producer
    for (const auto& level : levels)
        for (const GraphNode* n : level)
            for (const auto& [port, b] : n->inputs) ++pending[b.node];
    std::set<std::string> target_nodes;
    for (const auto& t : targets_) target_nodes.insert(t.first);
    ThreadLimit arena(jobs_);
    for (const auto& level : levels) {
        std::vector<std::exception_ptr> errors(level.size());
        std::vector<NodeReport> reports(level.size());
        std::vector<std::shared_ptr<const NodeOutputs>> produced(level.size());
        arena.run([&] {
            parallel_for_each(level.size(), 1, [&](size_t i) {
                const GraphNode& n = *level[i];
                const NodeState& s = state_.at(n.name);
                try {
                    opt_.progress.poll();
                    std::map<std::string, Value> inputs;
                    // `values_` is only written between levels, so reading it here needs no lock.
                    for (const auto& [port, b] : n.inputs) inputs[port] = values_.at(b.node)->at(source_port(g_, reg_, b));
                    NodeParams params(&s.type->decl, resolved_params(n, *s.type, opt_.proxy), g_.base_dir);
                    ProgressSink node_progress;
                    node_progress.is_cancelled = opt_.progress.is_cancelled;
                    node_progress.on_progress = [&, name = n.name](const ProgressEvent& e) { report_progress(name, e.fraction); };
                    // The node's own budget: what it allocates counts against the
                    // live total until its cook ends (issue 17 item 6).
                    const MemoryBudget node_budget(budget_.limit());
                    std::optional<detail::MemoryLedger::ScratchScope> scratch(std::in_place, node_budget, ledger_);
                    report_progress(n.name, 0.0);
                    detail::NodeRun run = detail::cook_node(n, *s.type, params, std::move(inputs), node_budget, node_progress);
                    // The outputs leave the node's scratch for their own tokens (counted once).
                    scratch.reset();
                    produced[i] = held_outputs(std::move(run.outputs), ledger_);
                    reports[i].seconds = run.seconds;
                    reports[i].metrics = std::move(run.metrics);
                    reports[i].warnings = std::move(run.warnings);
                } catch (...) {
                    errors[i] = std::current_exception();
                }
                progress_step("node '" + n.name + "'", n.name, 1.0, true);
            });
        });
        // Deterministic error choice: the first failing node in level order.
        for (size_t i = 0; i < level.size(); ++i)
            if (errors[i]) {
                result_.error_node = level[i]->name;
                result_.error_where = level[i]->where.str();
                rethrow_for_node(level[i]->name, level[i]->type, level[i]->where.str(), errors[i]);
            }
        for (size_t i = 0; i < level.size(); ++i) {
            const GraphNode& n = *level[i];
            NodeState& s = state_.at(n.name);
            if (opt_.checked && s.cached) {
                for (const auto& [port, v] : *s.cached) {
                    auto it = produced[i]->find(port);
                    if (it == produced[i]->end() || !values_equal(v, it->second)) {
                        result_.error_node = n.name;
                        result_.error_where = n.where.str();
                        throw Error("checked mode: node '" + n.name + "' (" + n.type + "): output '" + port +
                                    "' differs from the cached result with the same hash; the node's hash misses something its cook reads");
                    }
                }
            }
            values_[n.name] = produced[i];
            if (opt_.keep_values) cache_.put(s.hash, produced[i]);
            if (cache_writable_) {
                try {
                    disk_cache::store(*opt_.cache_dir, s.hash, *produced[i]);
                } catch (const std::exception& e) {
                    // A full or unwritable cache disk costs speed, not the cook.
                    cache_writable_ = false;
                    warn("disk cache: cannot store node '" + n.name + "' (" + e.what() + "); cooking on without writing the cache");
                }
            }
            NodeReport& r = reports[i];
            r.status = "cooked";
            r.reason = opt_.checked && s.cached ? "checked mode: re-cooked and matched the " + s.cache_source : "";
            result_.nodes[n.name] = std::move(r);
        }
        // A value no node still to cook reads, and no target, is let go here
        // (the in-memory cache may keep it, and give it up under the budget).
        for (const GraphNode* n : level)
            for (const auto& [port, b] : n->inputs)
                if (--pending[b.node] == 0 && !target_nodes.count(b.node) && values_.count(b.node)) {
                    for (const auto& [p, v] : *values_.at(b.node)) released_bytes_[b.node] += value_bytes(v);
                    values_.erase(b.node);
                    // A one-shot cook keeps no other reference (checked mode compares with it).
                    if (!opt_.keep_values && !opt_.checked) state_.at(b.node).cached.reset();
                }
    }
}

void CookRun::report(bool for_values) {
    std::unordered_set<Hash128, Hash128Hasher> keep;
    for (const auto& n : g_.nodes) {
        const NodeState& s = state_.at(n.name);
        NodeReport& r = result_.nodes[n.name];
        r.type = n.type;
        if (s.needed) {
            r.hash = s.hash.hex();
            keep.insert(s.hash);
        }
        if (values_.count(n.name) && values_.at(n.name))
            for (const auto& [port, v] : *values_.at(n.name)) r.bytes += value_bytes(v);
        if (released_bytes_.count(n.name)) r.bytes = released_bytes_.at(n.name);
        if (s.cook) continue;
        if (!s.needed) {
            r.status = "skipped";
            r.reason = "not needed by the requested outputs";
        } else if (s.required) {
            r.status = "cached";
            r.reason = s.cache_source;
        } else if (!feeds_writes_.count(n.name) && !for_values) {
            r.status = "skipped";
            r.reason = "not needed: the outputs it feeds are up to date";
        } else {
            r.status = "skipped";
            r.reason = "not needed: everything downstream came from the cache";
        }
    }
    // Keep results of nodes that are part of the graph now (needed this time
    // or not), at full resolution and at each proxy factor used (an artist
    // switches between them); drop stale ones (old parameter values, removed nodes).
    for (const auto& [key, h] : last_hashes_)
        if (g_.find(key.first) && !(key.second == opt_.proxy && state_.at(key.first).needed)) keep.insert(h);
    for (const auto& n : g_.nodes)
        if (state_.at(n.name).needed) last_hashes_[{n.name, opt_.proxy}] = state_.at(n.name).hash;
    cache_.retain_only(keep);
}

void CookRun::values_for(std::vector<Value>& out) const {
    for (const auto& t : targets_) out.push_back(values_.at(t.first)->at(t.second));
}

CookResult CookRun::finish() {
    if (opt_.cache_dir && opt_.cache_max_bytes > 0) disk_cache::prune(*opt_.cache_dir, opt_.cache_max_bytes);
    result_.seconds = seconds_since(t_start_);
    result_.memory_peak = ledger_.peak();
    return result_;
}

} // namespace detail

CookResult Session::run(const CookOptions& opt, const std::vector<std::pair<std::string, std::string>>* want_value,
                        std::vector<Value>* values_out) {
    // Filled as the cook goes, so that a failed cook still reports what happened.
    last_ = CookResult{};
    last_.checked = opt.checked;
    const Graph& g = graph();
    last_.texture_budget_mb = g.texture_budget_mb;
    if (opt.proxy < 1 || opt.proxy > 64) throw Error("proxy: expected a factor 1..64, got " + std::to_string(opt.proxy));
    if (opt.proxy > 1 && opt.write_outputs && !want_value)
        throw Error("a proxy cook (proxy " + std::to_string(opt.proxy) +
                    ") is for interaction: its results are never written as final outputs; cook without proxy to write them");
    detail::CookRun cook(g, registry_, *cache_, last_hashes_, *earlier_, opt, last_);
    cook.plan(want_value);
    cook.resolve();
    cook.hash();
    cook.plan_writes();
    cook.fetch();
    cook.cook();
    cook.report(want_value != nullptr);
    if (values_out) cook.values_for(*values_out);
    cook.write();
    return cook.finish();
}

std::vector<std::filesystem::path> CookResult::depends(const std::filesystem::path& graph_file) const {
    std::vector<std::filesystem::path> v;
    std::set<std::filesystem::path> seen;
    auto add = [&](const std::filesystem::path& p) {
        if (!p.empty() && seen.insert(p.lexically_normal()).second) v.push_back(p);
    };
    add(graph_file);
    for (const auto& in : inputs) add(in.path);
    return v;
}

uint64_t OutputReport::texture_bytes() const {
    if (format != "dds") return 0;
    uint64_t b = 0;
    for (const auto& f : files)
        if (f.path.extension() == ".dds") b += f.bytes; // not the .dds.json manifest beside it
    return b;
}

uint64_t CookResult::texture_bytes() const {
    uint64_t b = 0;
    for (const OutputReport& o : outputs) b += o.texture_bytes();
    return b;
}

std::vector<std::string> CookResult::with_status(const std::string& wanted) const {
    std::vector<std::string> v;
    for (const auto& [name, r] : nodes)
        if (r.status == wanted) v.push_back(name);
    return v;
}

} // namespace atlas
