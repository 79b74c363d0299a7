// Internal: the in-memory and on-disk caches of node results, keyed by hash.
#pragma once

#include "atlas/core/hash.h"
#include "atlas/core/value.h"

#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <unordered_set>

namespace atlas {

using NodeOutputs = std::map<std::string, Value>;

class ValueCache {
public:
    std::shared_ptr<const NodeOutputs> find(const Hash128& h) const;
    void put(const Hash128& h, std::shared_ptr<const NodeOutputs> v);
    // Drops every entry whose hash is not in `keep` (results of nodes that
    // no longer exist or whose parameters changed).
    void retain_only(const std::unordered_set<Hash128, Hash128Hasher>& keep);
    size_t size() const { return entries_.size(); }

private:
    std::unordered_map<Hash128, std::shared_ptr<const NodeOutputs>, Hash128Hasher> entries_;
};

// On-disk cache: one file per node result, DIR/<hash>.atlascache, written
// atomically. A file that cannot be read back (truncated, other version) is
// a miss, never an error.
namespace disk_cache {
std::filesystem::path entry_path(const std::filesystem::path& dir, const Hash128& h);
bool contains(const std::filesystem::path& dir, const Hash128& h);
std::optional<NodeOutputs> load(const std::filesystem::path& dir, const Hash128& h, std::string* why_not = nullptr);
void store(const std::filesystem::path& dir, const Hash128& h, const NodeOutputs& outputs);
// Serialisation (exposed for tests).
std::string serialize(const NodeOutputs& outputs);
std::optional<NodeOutputs> deserialize(const std::string& bytes, std::string* why_not = nullptr);
} // namespace disk_cache

} // namespace atlas
