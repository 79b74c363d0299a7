// Internal: the in-memory (value_cache.cpp) and on-disk (disk_cache.cpp) caches of node results, keyed by hash.
#pragma once

#include "atlas/core/hash.h"
#include "atlas/core/memory_ledger.h"
#include "atlas/core/value.h"
#include "atlas/graph/disk_cache.h"

#include <filesystem>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <utility>
#include <vector>
#include <unordered_map>
#include <unordered_set>

namespace atlas {

using NodeOutputs = std::map<std::string, Value>;

// The outputs as one shared value whose bytes are held against `budget`
// while it lives (objects already held, e.g. fields a node made through its
// CookContext, count once).
std::shared_ptr<const NodeOutputs> held_outputs(NodeOutputs outputs, const detail::MemoryLedger& ledger);

class ValueCache {
public:
    // The session's live memory total: the cache outlives cooks, so what it
    // keeps counts against the next cook's budget.
    const detail::MemoryLedger& ledger() const { return ledger_; }
    // Drops entries, those nothing else holds first, until `bytes` were given
    // back to the ledger or nothing is left to drop. Thread-safe against itself.
    void evict(uint64_t bytes);
    std::shared_ptr<const NodeOutputs> find(const Hash128& h) const;
    void put(const Hash128& h, std::shared_ptr<const NodeOutputs> v);
    // Drops every entry whose hash is not in `keep` (results of nodes that
    // no longer exist or whose parameters changed).
    void retain_only(const std::unordered_set<Hash128, Hash128Hasher>& keep);
    size_t size() const { return entries_.size(); }

private:
    std::unordered_map<Hash128, std::shared_ptr<const NodeOutputs>, Hash128Hasher> entries_;
    detail::MemoryLedger ledger_;
    std::mutex evict_mutex_;
};

// On-disk cache: one file per node result, DIR/<hash>.atlascache, written
// atomically and ending in a checksum of its bytes. A file that cannot be
// read back (truncated, corrupt, other version) is a miss, never an error;
// `why_not` says why. A successful load refreshes the entry's mtime, which
// prune() uses as its last use.
namespace disk_cache {
std::filesystem::path entry_path(const std::filesystem::path& dir, const Hash128& h);
bool contains(const std::filesystem::path& dir, const Hash128& h);
std::optional<NodeOutputs> load(const std::filesystem::path& dir, const Hash128& h, std::string* why_not = nullptr);
// Throws atlas::Error when the entry cannot be written (full disk); nothing partial remains.
void store(const std::filesystem::path& dir, const Hash128& h, const NodeOutputs& outputs);
void touch(const std::filesystem::path& entry);

// Encoded output files (e.g. a DDS texture) by output key, DIR/<key>.atlasout:
// the files' relative names and bytes plus the writer's metrics, checksummed.
struct CachedFiles {
    std::vector<std::pair<std::string, std::string>> files; // relative name, bytes
    std::map<std::string, double> metrics;
};
std::filesystem::path files_entry_path(const std::filesystem::path& dir, const Hash128& key);
void store_files(const std::filesystem::path& dir, const Hash128& key,
                 const std::vector<std::pair<std::string, std::filesystem::path>>& files, const std::map<std::string, double>& metrics);
std::optional<CachedFiles> load_files(const std::filesystem::path& dir, const Hash128& key, std::string* why_not = nullptr);


// ContentHasher of a value's serialised form (shape, bounds, channel names
// and data): equal values give equal hashes, fast enough for every output.
Hash128 content_hash(const Value& v);
// Serialisation (exposed for tests).
std::string serialize(const NodeOutputs& outputs);
std::optional<NodeOutputs> deserialize(const std::string& bytes, std::string* why_not = nullptr);
} // namespace disk_cache

} // namespace atlas
