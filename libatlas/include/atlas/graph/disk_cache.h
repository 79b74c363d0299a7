// atlas/graph/disk_cache.h - maintenance of an on-disk cache directory (disk_cache.cpp).
//
// A cache directory (`atlas cook --cache DIR`) holds one checksummed file per
// node result (<hash>.atlascache) and per encoded output (<key>.atlasout).
// Loading an entry refreshes its mtime, so the mtime is its last use.
#pragma once

#include <cstdint>
#include <filesystem>

namespace atlas::disk_cache {

struct PruneResult {
    uint64_t bytes_before = 0;        // entry bytes found
    uint64_t bytes_after = 0;         // entry bytes left
    uint64_t removed_bytes = 0;
    uint64_t removed_files = 0;
    uint64_t stale_staging_bytes = 0; // staging folders of killed processes, removed
};

// Removes entries, least recently used first (ties by name), until at most
// `max_bytes` of entries remain, and the staging folders killed processes
// left. Files other than cache entries are never touched. Never throws;
// safe while other processes cook with the same directory (an entry removed
// under a reader is a miss for it).
PruneResult prune(const std::filesystem::path& dir, uint64_t max_bytes);

} // namespace atlas::disk_cache
