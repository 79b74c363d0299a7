// Internal to graph: one cook, step by step as docs/architecture.md names them. Session::run
// (evaluator.cpp) calls the steps in order; planning, fetching and cooking are in
// evaluator.cpp, planning and writing the outputs in cook_writes.cpp.
#pragma once

#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "atlas/core/memory_ledger.h"
#include "atlas/graph/evaluator.h"
#include "output_records.h"
#include "value_cache.h"

#include <chrono>
#include <exception>
#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

namespace atlas::detail {

// What a cook knows of one node of the graph.
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

} // namespace atlas::detail
