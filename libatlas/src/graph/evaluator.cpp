// The evaluator: pull what the requested outputs need, hash before compute,
// serve from cache, cook the rest level by level in parallel, write outputs
// atomically.
#include "atlas/graph/evaluator.h"
#include "cook_steps.h"
#include "graph_walk.h"

#include "atlas/core/files.h"
#include "atlas/core/option_schema.h"
#include "atlas/core/parallel.h"
#include "atlas/io/writers.h"
#include "atlas/core/file_limits.h"
#include "output_records.h"
#include "value_cache.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <optional>
#include <exception>
#include <functional>
#include <mutex>
#include <set>
#include <sstream>

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

// Formats whose encoded files the disk cache keeps (costly to encode).
const std::set<std::string> kCachedOutputFormats = {"dds"};

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

namespace {

using Wanted = std::vector<std::pair<std::string, std::string>>;

// An output to write, as planned before anything cooks.
struct OutputPlan {
    const GraphOutput* out = nullptr;
    std::filesystem::path root, rel;
    std::string name; // the record's name: rel, generic form
    std::string spec; // hash of everything in the key but the source
    Hash128 key;
    // The files on disk were written with this spec from a value that may
    // be the same as the one cooked now (an upstream change that did not
    // change this port): compare value hashes before writing.
    const OutputRecord* same_spec = nullptr;
    enum { write, current, restore, copy } action = write;
    const OutputRecord* record = nullptr;
    EarlierOutput* earlier = nullptr; // copy: the same output an earlier cook wrote elsewhere
    std::optional<disk_cache::CachedFiles> cached;
};

// One cook, step by step as docs/architecture.md names them: plan, resolve, hash,
// plan the writes, fetch (from the caches), cook, report, write. Session::run calls
// the steps in that order; the tiled cook shares plan, resolve, cook and write's
// placing (cook_steps.h).
class CookRun {
public:
    CookRun(const Graph& g, const NodeRegistry& reg, ValueCache& cache, std::map<std::pair<std::string, int>, Hash128>& last_hashes, EarlierOutputs& earlier,
            const CookOptions& opt, CookResult& result);

    void plan(const Wanted* want_value); // 1. the targets: graph outputs or node ports
    void resolve();                      // 2. what they need, in order
    void hash();                         // 3. every needed node's hash, before anything cooks
    void plan_writes();                  // 3b. outputs already on disk or in the disk cache
    void fetch();                        // 4. consumers before producers: cached or to cook
    void cook();                         // 5-6. level by level, a level's nodes in parallel
    void report(bool for_values);        // 7. every node of the graph; the memory cache trimmed
    void values_for(std::vector<Value>& out) const;
    void write();                        // 8. the outputs, staged and committed together
    CookResult finish();

private:
    void progress_step(const std::string& task, const std::string& node, double node_fraction, bool finished);
    void warn(std::string message) { result_.warnings.push_back(std::move(message)); }
    struct PendingWrite;
    void encode(std::vector<PendingWrite>& batch);
    void finish_write(PendingWrite& w);
    void fail_output(PendingWrite& w, const std::string& msg);
    void check_texture_budget();
    void record_written();
    const std::string& value_hash(const GraphOutput* o);

    struct EvictorReset {
        const detail::MemoryLedger& l;
        CookResult& r;
        // A failed cook's report (read from last_) says how much was counted when it
        // stopped; a cook that returns sets the peak itself, as the copy it returns
        // is made before this runs.
        ~EvictorReset() {
            l.set_evictor(nullptr);
            r.memory_peak = l.peak();
        }
    };
    struct Written {
        size_t report; // index into result.outputs
        OutputPlan* plan;
        StagedOutputs* stage;
        std::vector<std::filesystem::path> staged;
    };
    // An output on its way: staged, then encoded (with others), then finished.
    struct PendingWrite {
        OutputPlan* plan;
        size_t report; // index into result.outputs
        StagedOutputs* stage;
        std::filesystem::path target; // the writer's staged path
        std::vector<std::filesystem::path> staged;
        std::shared_ptr<void> scratch_held;
        std::chrono::steady_clock::time_point start;
        double encode_seconds; // staging and writing (restoring) the files
        std::exception_ptr error;
        uint64_t scratch = 0;
    };

    const std::chrono::steady_clock::time_point t_start_ = std::chrono::steady_clock::now();
    const Graph& g_;
    const NodeRegistry& reg_;
    ValueCache& cache_;
    std::map<std::pair<std::string, int>, Hash128>& last_hashes_;
    EarlierOutputs& earlier_;
    const CookOptions& opt_;
    CookResult& result_;
    const int jobs_;
    // One budget per session: the live total of this cook's fields and values
    // and of the in-memory cache; before refusing it drops cache entries.
    const MemoryBudget budget_;
    const detail::MemoryLedger& ledger_;
    const detail::MemoryLedger::Attachment attached_;
    EvictorReset evictor_reset_;

    std::vector<const GraphOutput*> outputs_;
    Wanted targets_;
    std::map<std::string, NodeState> state_;
    std::vector<const GraphNode*> order_;
    std::vector<OutputPlan> plans_;
    std::map<std::filesystem::path, std::unique_ptr<OutputRecords>> records_;
    // What no output may replace: the graph file and every file the cook reads.
    std::vector<ProtectedFile> protect_;
    std::set<std::string> feeds_writes_; // nodes some output to write depends on
    bool cache_writable_ = false;
    std::map<std::string, std::shared_ptr<const NodeOutputs>> values_;
    std::map<std::string, uint64_t> released_bytes_;
    // Progress: one unit per node to cook and per output to write; each running node
    // adds what it reported of itself (never going back), and the fraction sent never
    // decreases: one 0..1 run per cook.
    std::mutex progress_mutex_;
    int units_ = 0, done_ = 0;
    std::map<std::string, double> in_flight_;
    double shown_ = 0;
    // Staged outputs and what they record.
    std::map<std::filesystem::path, std::unique_ptr<StagedOutputs>> staging_;
    std::vector<Written> written_;
    std::vector<std::pair<OutputPlan*, OutputRecord>> rekeyed_;
    std::map<std::pair<std::string, std::string>, std::string> value_hashes_;
};

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

// An output whose key is unchanged and whose files still match needs no value (nothing
// cooks or loads for it); one whose encoded files the disk cache holds is copied from there.
void CookRun::plan_writes() {
    const bool reuse = opt_.write_outputs && opt_.reuse_outputs && !opt_.checked;
    cache_writable_ = bool(opt_.cache_dir);
    if (!g_.file.empty()) protect_.push_back({g_.file, "the graph file"});
    for (const auto& in : result_.inputs) protect_.push_back({in.path, "an input file of the cook (node '" + in.node + "')"});
    if (opt_.write_outputs && !outputs_.empty()) {
        if (opt_.cache_dir) remove_stale_staging(*opt_.cache_dir);
        for (const GraphOutput* o : outputs_) {
            OutputPlan p;
            p.out = o;
            try {
                const detail::OutputPlace place = detail::output_place(opt_.out_dir, *o, opt_.allow_outside_out, protect_);
                p.root = place.root;
                p.rel = place.rel;
            } catch (const std::exception& e) {
                result_.error_output = o->file;
                result_.error_where = o->where.str();
                throw Error(o->where.str() + ": " + e.what());
            }
            p.name = p.rel.generic_string();
            const detail::OutputSpec spec = detail::output_spec(*o, p.name, state_.at(o->node).hash);
            p.spec = spec.spec;
            p.key = spec.key;
            auto& rec = records_[p.root];
            if (!rec) {
                remove_stale_staging(p.root); // what killed cooks left
                rec = std::make_unique<OutputRecords>(p.root);
            }
            if (reuse) {
                const auto earlier = earlier_.by_key.find(p.key.hex());
                if ((p.record = rec->current(p.name, p.key.hex()))) {
                    p.action = OutputPlan::current;
                } else if (earlier != earlier_.by_key.end() && earlier->second.root != p.root &&
                           files_unchanged(earlier->second.root, earlier->second.record.files)) {
                    p.action = OutputPlan::copy;
                    p.earlier = &earlier->second;
                } else if (const OutputRecord* r = rec->on_disk(p.name); r && r->spec == p.spec && !r->value_hash.empty()) {
                    p.same_spec = r;
                } else if (opt_.cache_dir && kCachedOutputFormats.count(o->format) &&
                           std::filesystem::exists(disk_cache::files_entry_path(*opt_.cache_dir, p.key))) {
                    std::string why;
                    p.cached = disk_cache::load_files(*opt_.cache_dir, p.key, &why);
                    // Only the files this output writes: its own name and its sidecars beside it.
                    if (p.cached)
                        for (const auto& [name, bytes] : p.cached->files) {
                            const std::filesystem::path f(name);
                            if (f.parent_path() != p.rel.parent_path() || f.filename().string().rfind(p.rel.filename().string(), 0) != 0) {
                                why = "it holds '" + name + "', not a file of this output";
                                p.cached.reset();
                                break;
                            }
                        }
                    if (p.cached) {
                        p.action = OutputPlan::restore;
                    } else {
                        std::error_code ec;
                        std::filesystem::remove(disk_cache::files_entry_path(*opt_.cache_dir, p.key), ec);
                        warn("disk cache: the encoded files of output '" + o->file + "' (" + disk_cache::files_entry_path(*opt_.cache_dir, p.key).string() +
                             ") are unusable (" + why + "); discarded, the output is written again");
                    }
                }
            }
            plans_.push_back(std::move(p));
        }
        // Only the outputs to write need values.
        targets_.clear();
        for (const auto& p : plans_)
            if (p.action == OutputPlan::write) targets_.emplace_back(p.out->node, p.out->port);
    }
    std::function<void(const std::string&)> mark_writes = [&](const std::string& name) {
        if (!feeds_writes_.insert(name).second) return;
        for (const auto& [port, b] : state_.at(name).node->inputs) mark_writes(b.node);
    };
    for (const auto& t : targets_) mark_writes(t.first);
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

// Outputs are staged in plan order, encoded in parallel (each writer makes its own
// files from a value nothing changes any more, so the bytes do not depend on what
// else runs), then finished in plan order: sizes, hashes, the disk cache, the report.
void CookRun::write() {
    if (!opt_.write_outputs || outputs_.empty()) {
        for (const GraphOutput* o : outputs_) result_.outputs.push_back({o->node, o->port, o->file, o->format, {}, {}, {}, {}});
        return;
    }
    std::vector<PendingWrite> batch;
    batch.reserve(plans_.size());
    // Writers' copies are held together while they run; one the budget refuses
    // beside the others waits for them (the same decisions whatever the thread count).
    auto flush = [&] {
        encode(batch);
        for (PendingWrite& w : batch) finish_write(w);
        batch.clear();
    };
    for (OutputPlan& p : plans_) {
        const GraphOutput* o = p.out;
        OutputReport orep{o->node, o->port, o->file, o->format, {}, {}, {}, {}, {}, 0.0};
        if (p.same_spec && p.same_spec->value_hash == value_hash(o)) {
            // Upstream changed, this port did not: the files already hold it.
            p.action = OutputPlan::current;
            p.record = p.same_spec;
            OutputRecord r = *p.same_spec;
            r.key = p.key.hex();
            rekeyed_.emplace_back(&p, std::move(r));
            progress_step("up to date: " + o->file, "", 0.0, true);
        }
        if (p.action == OutputPlan::current) {
            orep.status = "up to date";
            orep.metrics = p.record->metrics;
            for (const auto& f : p.record->files) orep.files.push_back({p.root / f.path, f.bytes, f.hash});
            result_.outputs.push_back(orep);
            continue;
        }
        PendingWrite w{&p, result_.outputs.size(), nullptr, {}, {}, {}, std::chrono::steady_clock::now(), 0.0, {}};
        result_.outputs.push_back(orep);
        const std::string what = "output '" + o->file + "': the writer's copy of the value";
        if (p.action == OutputPlan::write) {
            // A writer may copy the value (a slice stack, a half-float frame): room for one copy;
            // the DDS encoder holds its channels and blocks besides (cloudscape's modeling.dds
            // peaked 490 MB of RSS over the one copy counted), so two.
            w.scratch = value_bytes(values_.at(o->node)->at(o->port)) * (o->format == "dds" ? 2 : 1);
            bool fits = true;
            try {
                budget_.check(w.scratch, what);
            } catch (const MemoryBudgetError&) {
                fits = false;
            }
            if (!fits) flush(); // the writers before it finish first, then it is checked alone
        }
        std::optional<std::string> failure;
        try {
            opt_.progress.poll();
            auto& st = staging_[p.root];
            if (!st) {
                st = std::make_unique<StagedOutputs>(p.root);
                st->protect(protect_);
            }
            w.stage = st.get();
            if (p.action == OutputPlan::restore || p.action == OutputPlan::copy) {
                // Encoded files already exist: the disk cache's bytes, or the files an
                // earlier cook of the session wrote elsewhere.
                progress_step("writing " + o->file, "", 0.0, false);
                OutputReport& r = result_.outputs[w.report];
                const bool restore = p.action == OutputPlan::restore;
                r.status = restore ? "restored" : "copied";
                r.metrics = restore ? p.cached->metrics : p.earlier->record.metrics;
                if (restore)
                    for (const auto& [name, bytes] : p.cached->files) {
                        w.staged.push_back(st->stage(name));
                        write_file_checked(w.staged.back(), bytes.data(), bytes.size());
                    }
                else
                    for (const auto& f : p.earlier->record.files) {
                        w.staged.push_back(st->stage(f.path));
                        std::filesystem::copy_file(p.earlier->root / f.path, w.staged.back(), std::filesystem::copy_options::overwrite_existing);
                    }
                p.cached.reset();
                w.encode_seconds = seconds_since(w.start);
            } else {
                budget_.check(w.scratch, what);
                w.scratch_held = ledger_.hold(&p, w.scratch);
                w.target = st->stage(p.rel);
            }
        } catch (const CancelledError&) {
            throw;
        } catch (const std::exception& e) {
            failure = e.what();
        }
        if (failure) {
            // Flushed first, so that the report lists the outputs in plan order.
            flush();
            fail_output(w, *failure);
            continue;
        }
        batch.push_back(std::move(w));
    }
    flush();
    check_texture_budget();
    // Everything written: move it into place.
    // Every root's destinations checked and journaled before any file moves.
    for (auto& [root, st] : staging_) st->prepare();
    for (auto& [root, st] : staging_) st->commit();
    record_written();
}

// The batch's writers, up to the cook's jobs at a time.
void CookRun::encode(std::vector<PendingWrite>& batch) {
    std::vector<size_t> todo;
    for (size_t i = 0; i < batch.size(); ++i)
        if (batch[i].plan->action == OutputPlan::write) todo.push_back(i);
    ThreadLimit arena(jobs_);
    arena.run([&] {
        parallel_for_each(todo.size(), 1, [&](size_t k) {
            PendingWrite& w = batch[todo[k]];
            const GraphOutput* o = w.plan->out;
            const auto t0 = std::chrono::steady_clock::now();
            try {
                opt_.progress.poll();
                progress_step("writing " + o->file, "", 0.0, false);
                OutputReport& r = result_.outputs[w.report];
                r.status = "written";
                w.staged = io::write_value(values_.at(o->node)->at(o->port), w.target, o->format, o->options, &r.metrics);
            } catch (...) {
                w.error = std::current_exception();
            }
            w.encode_seconds = seconds_since(t0);
            w.scratch_held.reset();
        });
    });
}

// One output after its writer: what is on disk is what gets reported and recorded.
void CookRun::finish_write(PendingWrite& w) {
    const auto t0 = std::chrono::steady_clock::now();
    OutputPlan& p = *w.plan;
    const GraphOutput* o = p.out;
    OutputReport& orep = result_.outputs[w.report];
    std::optional<std::string> failure;
    if (w.error) {
        try {
            std::rethrow_exception(w.error);
        } catch (const CancelledError&) {
            throw;
        } catch (const std::exception& e) {
            failure = e.what();
        }
    } else {
        try {
            for (const auto& staged : w.staged) {
                std::error_code ec;
                const uint64_t bytes = std::filesystem::file_size(staged, ec);
                if (ec) throw Error("'" + staged.string() + "' was not written: " + ec.message());
                const auto final_path = w.stage->final_path(staged);
                orep.written.push_back(final_path);
                orep.files.push_back({final_path, bytes, file_content_hash(staged).hex()});
            }
            if (p.action == OutputPlan::copy)
                for (size_t k = 0; k < orep.files.size(); ++k)
                    if (orep.files[k].hash != p.earlier->record.files[k].hash)
                        throw Error("'" + (p.earlier->root / p.earlier->record.files[k].path).string() + "', copied from an earlier cook, changed while it was read");
        } catch (const CancelledError&) {
            throw;
        } catch (const std::exception& e) {
            failure = e.what();
        }
    }
    if (failure) {
        fail_output(w, *failure);
        return;
    }
    if (p.action == OutputPlan::write && cache_writable_ && kCachedOutputFormats.count(o->format)) {
        std::vector<std::pair<std::string, std::filesystem::path>> files;
        for (size_t k = 0; k < w.staged.size(); ++k) files.emplace_back(orep.files[k].path.lexically_relative(p.root).generic_string(), w.staged[k]);
        try {
            disk_cache::store_files(*opt_.cache_dir, p.key, files, orep.metrics);
        } catch (const std::exception& e) {
            cache_writable_ = false;
            warn("disk cache: cannot store the encoded files of output '" + o->file + "' (" + e.what() + "); cooking on without writing the cache");
        }
    }
    orep.seconds = w.encode_seconds + seconds_since(t0);
    written_.push_back({w.report, &p, w.stage, std::move(w.staged)});
    progress_step("wrote " + o->file, "", 0.0, true);
}

// The output failed, not the node that fed it: the report marks the output. With
// keep going, the cook goes on without it; else nothing is written and the
// report ends at this output.
void CookRun::fail_output(PendingWrite& w, const std::string& msg) {
    const GraphOutput* o = w.plan->out;
    OutputReport& orep = result_.outputs[w.report];
    orep.status = "failed";
    orep.error = msg;
    orep.written.clear();
    orep.files.clear();
    orep.seconds = w.encode_seconds;
    if (opt_.keep_going) {
        if (w.stage) w.stage->discard(w.plan->rel);
        warn("output '" + o->file + "' (" + o->where.str() + ") was not written (keep going): " + msg);
        return;
    }
    result_.outputs.resize(w.report + 1);
    result_.error_output = o->file;
    result_.error_where = o->where.str();
    throw Error(detail::output_error(*o, msg));
}

// Content hash of the value an output writes, once per node port.
const std::string& CookRun::value_hash(const GraphOutput* o) {
    auto [it, fresh] = value_hashes_.try_emplace({o->node, o->port});
    if (fresh) it->second = disk_cache::content_hash(values_.at(o->node)->at(o->port)).hex();
    return it->second;
}

// The graph's texture budget, on what is staged or already up to date, before anything moves.
void CookRun::check_texture_budget() {
    if (!g_.texture_budget_mb) return;
    const uint64_t texture_total = result_.texture_bytes();
    const double limit = *g_.texture_budget_mb * 1e6;
    if (double(texture_total) <= limit) return;
    std::vector<std::pair<uint64_t, std::string>> textures;
    for (const OutputReport& o : result_.outputs)
        if (const uint64_t b = o.texture_bytes()) textures.emplace_back(b, o.file);
    std::sort(textures.rbegin(), textures.rend());
    auto mb = [](double bytes) {
        std::ostringstream os;
        os.precision(3);
        os << bytes / 1e6 << " MB";
        return os.str();
    };
    std::string list;
    for (const auto& [b, file] : textures) list += (list.empty() ? "" : ", ") + file + " " + mb(double(b));
    result_.error_where = g_.budget_where.str();
    throw Error(g_.budget_where.str() + ": budget: the textures take " + mb(double(texture_total)) + ", over texture_mb " +
                detail::number_text(*g_.texture_budget_mb) + " by " + mb(double(texture_total) - limit) + " (largest first: " + list +
                "); nothing was written");
}

// Records what is on disk now (renames keep the mtime).
void CookRun::record_written() {
    for (auto& [plan, rec] : rekeyed_) records_.at(plan->root)->set(plan->name, std::move(rec));
    for (const auto& w : written_) {
        OutputRecord rec;
        rec.key = w.plan->key.hex();
        rec.spec = w.plan->spec;
        if (w.plan->action == OutputPlan::write) rec.value_hash = value_hash(w.plan->out);
        if (w.plan->action == OutputPlan::copy) rec.value_hash = w.plan->earlier->record.value_hash;
        const OutputReport& orep = result_.outputs[w.report];
        rec.metrics = orep.metrics;
        for (const auto& f : orep.files)
            rec.files.push_back({f.path.lexically_relative(w.plan->root).generic_string(), f.bytes, file_mtime_ns(f.path), f.hash});
        records_.at(w.plan->root)->set(w.plan->name, std::move(rec));
    }
    // What this cook leaves on disk, for the next cook of the session (issue 43 item 6).
    EarlierOutputs now;
    for (const OutputPlan& p : plans_)
        if (const OutputRecord* r = records_.at(p.root)->find(p.name); r && r->key == p.key.hex() && !r->files.empty())
            now.by_key[r->key] = {p.root, *r};
    earlier_ = std::move(now);
    for (auto& [root, rec] : records_) {
        try {
            rec->save();
        } catch (const std::exception& e) {
            warn("cannot record the outputs written in '" + root.string() + "' (" + e.what() + "); the next cook writes them again");
        }
    }
}

CookResult CookRun::finish() {
    if (opt_.cache_dir && opt_.cache_max_bytes > 0) disk_cache::prune(*opt_.cache_dir, opt_.cache_max_bytes);
    result_.seconds = seconds_since(t_start_);
    result_.memory_peak = ledger_.peak();
    return result_;
}

} // namespace

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
    CookRun cook(g, registry_, *cache_, last_hashes_, *earlier_, opt, last_);
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
