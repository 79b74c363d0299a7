// atlas/graph/evaluator.h - cooking a graph: lazy, hashed, cached, parallel.
//
// Cooking pulls only what the requested outputs need (a node no requested
// output depends on is never cooked). Each node's content hash covers its
// type, version, resolved parameters, hash_extra and its inputs' hashes;
// results are cached by hash in memory (per Session) and optionally on disk.
// Independent nodes cook in parallel inside a TBB arena of `jobs` threads;
// results do not depend on the thread count.
#pragma once

#include "atlas/core/files.h"
#include "atlas/core/hash.h"
#include "atlas/core/progress.h"
#include "atlas/graph/graph.h"

#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace atlas {

struct CookOptions {
    // Outputs to produce, by file name or node name; empty = every output.
    std::vector<std::string> outputs;
    int jobs = 0;                                // 0 = all hardware threads
    bool checked = false;                        // re-cook everything and compare with the cache
    std::optional<std::filesystem::path> cache_dir; // on-disk cache; none when empty
    uint64_t memory_budget = MemoryBudget::kDefaultLimit;
    std::filesystem::path out_dir = ".";
    bool allow_outside_out = false;              // permit absolute / escaping output paths
    bool write_outputs = true;                   // false: cook values only (hosts, tests)
    // An output whose key (source content hash, port, format, options, path)
    // is unchanged and whose files on disk still match what this output
    // wrote last is not written again, and nothing cooks or loads for it.
    // false (or checked mode): write every output.
    bool reuse_outputs = true;
    // With a cache_dir: after the cook, remove least recently used entries
    // until the cache holds at most this many bytes (0 = no limit).
    uint64_t cache_max_bytes = 0;
    // An output whose writer fails (a DDS bound a slider move put out of reach) is reported
    // failed, with its error as a warning, and the other outputs are written: what an editor
    // wants from one edit. false (the default, and `atlas cook` without --keep-going): the
    // cook fails and writes nothing.
    bool keep_going = false;
    // A proxy cook for interaction: every world-space grid 1/proxy of its cells per
    // axis over the same bounds (the parameters declared to follow it,
    // ParamDecl::proxy; docs/nodes.md lists them per node). Its results hash, and
    // so cache, apart from full ones; it never writes outputs (write_outputs must be
    // false). 1: full resolution.
    int proxy = 1;
    // false: a one-shot cook (`atlas cook`): the session's in-memory cache keeps
    // none of this cook's values, so each is freed once the nodes reading it and
    // the outputs it feeds are done (the cloudscape's peak 2.1 -> GB; issue 49).
    // true: an editor's session keeps every value for the next edit.
    bool keep_values = true;
    ProgressSink progress;
};

// Per-node record of a cook. Keys and meanings are documented in docs/report.md.
struct NodeReport {
    std::string type;
    std::string status; // "cooked", "cached" or "skipped"
    std::string reason; // why cached/skipped, e.g. "memory cache", "not needed by the requested outputs"
    std::string hash;   // hex; empty when skipped
    double seconds = 0;
    uint64_t bytes = 0; // size of the node's output values
    std::map<std::string, double> metrics;
    std::vector<std::string> warnings;
};

struct OutputFileReport {
    std::filesystem::path path; // final path
    uint64_t bytes = 0;
    std::string hash;           // content hash (file_content_hash), hex
};

struct OutputReport {
    std::string node, port, file, format;
    std::vector<std::filesystem::path> written; // files written by this cook (none when up to date)
    std::map<std::string, double> metrics; // what the writer measured, e.g. a DDS encode's errors
    // "written" (encoded and written), "restored" (copied from the disk
    // cache's encoded files), "up to date" (the files on disk already held
    // it: not touched), "not written" (a failed or cancelled cook had
    // encoded it, but committed nothing), "failed" (its writer failed: error
    // says why); empty when outputs are not written.
    std::string status;
    std::vector<OutputFileReport> files; // every file of the output, written or not
    std::string error;                   // why it failed (status "failed")
    double seconds = 0;                  // encoding, writing (and a DDS's verification) and hashing its files
    // GPU texture memory: the bytes of a DDS output's files (what an engine loads as is); 0 otherwise.
    uint64_t texture_bytes() const;
};

// A file the cook read (an input file, a preset or forecast file a node reads).
struct InputReport {
    std::filesystem::path path;
    uint64_t bytes = 0;
    std::string hash; // file_content_hash, hex
    std::string node; // the node that reads it
};

struct CookResult {
    std::map<std::string, NodeReport> nodes;
    std::vector<OutputReport> outputs;
    std::vector<InputReport> inputs;
    std::vector<std::string> warnings; // cook-level: corrupt cache entries, an unwritable cache
    double seconds = 0;
    int jobs = 1;
    bool checked = false;
    int proxy = 1; // CookOptions::proxy
    // The --memory-budget and the most the cook's ledger counted at once
    // (values, the in-memory cache, running nodes' scratch, writers' copies).
    uint64_t memory_budget = 0, memory_peak = 0;
    std::optional<double> texture_budget_mb; // the graph's budget: {texture_mb} (report.md)
    uint64_t texture_bytes() const;          // the outputs' OutputReport::texture_bytes, summed
    // "ok", "failed" or "cancelled"; for a failure, the message and where:
    // the node that failed, or the output that failed (its file; error_node is
    // then empty: the node that fed it did not fail), or neither when the graph
    // itself failed; and its file:line:col.
    std::string status = "ok";
    std::string error, error_node, error_output, error_where;

    std::vector<std::string> with_status(const std::string& wanted) const;
    // Every file the cook depends on: the graph file (when given) and the inputs, without repeats.
    std::vector<std::filesystem::path> depends(const std::filesystem::path& graph_file) const;
    // The --report JSON document (stable keys, see docs/report.md).
    std::string to_json(const std::string& graph_file) const;
};

// One --report document for several graphs cooked in one call (see docs/report.md).
std::string combined_report_json(const std::vector<std::pair<std::string, CookResult>>& cooks);

class ValueCache; // in-memory cache, keyed by node hash
struct EarlierOutputs; // the files the last writing cook left, by output key

// A loaded graph plus its in-memory cache: the embedding API. A host keeps
// one Session per open graph, edits parameters and re-cooks; only what
// changed is cooked again. Not thread-safe: one cook at a time per Session.
class Session {
public:
    explicit Session(NodeRegistry registry);
    ~Session();
    Session(Session&&) noexcept;
    Session& operator=(Session&&) noexcept;

    void load(const std::filesystem::path& graph_file);
    void load_text(const std::string& text, const std::string& name, const std::filesystem::path& base_dir);
    const Graph& graph() const;
    const NodeRegistry& registry() const { return registry_; }

    // Input files (Path parameters) that do not exist now: the graph is well
    // formed, but its cook will fail unless something writes them first.
    // A slice stack's parameter (a pattern or DIR/NAME) needs its folder.
    struct MissingInput {
        std::string node, type, param;
        std::filesystem::path path; // resolved against the graph's folder
        int line = 0;               // of the parameter, else of the node
        const GraphRequirement* written_by = nullptr; // the requirement whose `out` holds it
    };
    std::vector<MissingInput> missing_inputs() const;
    // Cooks every `requires:` graph that writes a missing input (into its `out`,
    // with `options` otherwise; one level of requirements each, recursively,
    // a cycle refused). `before` is told each graph before it cooks. Returns
    // (graph file, result) in cook order; a failure throws like cook().
    std::vector<std::pair<std::string, CookResult>> cook_requirements(
        const CookOptions& options, const std::function<void(const GraphRequirement&)>& before = {});

    // Parameter overrides (validated; throw atlas::Error).
    void set(const std::string& node, const std::string& param, const ParamValue& value);
    // The graph's time in seconds (docs/graph-format.md, "Time"): keyed parameters
    // take their values at t; the next cook re-cooks only what reads them.
    void set_time(double t);
    void set_text(const std::string& node, const std::string& param, const std::string& text);

    // Cooks the requested outputs and writes them (atomically: a failed cook
    // writes nothing). Throws atlas::Error (CancelledError on cancel).
    CookResult cook(const CookOptions& options);
    // The result of the last cook, also when it threw: status "failed" or
    // "cancelled", the error and where, and what had happened until then.
    const CookResult& last_result() const { return last_; }
    // Cooks just what one node output needs and returns its value.
    Value get(const std::string& node, const std::string& port, const CookOptions& options = {});
    // The same for several (node, port) pairs in one cook, values in their order.
    std::vector<Value> get(const std::vector<std::pair<std::string, std::string>>& ports, const CookOptions& options = {});

    // Content hash of every node (for tests and tools).
    std::map<std::string, Hash128> node_hashes() const;

private:
    CookResult run(const CookOptions& options, const std::vector<std::pair<std::string, std::string>>* want_value,
                   std::vector<Value>* values_out);
    NodeRegistry registry_;
    std::unique_ptr<Graph> graph_;
    std::unique_ptr<ValueCache> cache_;
    std::map<std::pair<std::string, int>, Hash128> last_hashes_; // (node, proxy) -> hash when last needed
    std::unique_ptr<EarlierOutputs> earlier_;
    CookResult last_;
};

} // namespace atlas
