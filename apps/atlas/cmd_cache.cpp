// atlas cache prune: keep an on-disk cache directory within a size.
#include "cli.h"

#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/graph/disk_cache.h"

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iostream>

namespace atlas::cli {

namespace {
std::string mib(uint64_t bytes) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.1f MiB", double(bytes) / (1024.0 * 1024.0));
    return buf;
}
} // namespace

int run_cache(const Args& a) {
    if (a.positional.empty() || a.positional[0] != "prune")
        throw UsageError{"expected 'atlas cache prune [DIR] --max-size SIZE'", "cache"};
    if (a.positional.size() > 2) throw UsageError{"expected at most one cache directory", "cache"};
    std::string dir = a.positional.size() == 2 ? a.positional[1] : "";
    if (dir.empty())
        if (const char* env = std::getenv("ATLAS_CACHE_DIR"); env && *env) dir = env;
    if (dir.empty()) throw UsageError{"no cache directory: give DIR or set ATLAS_CACHE_DIR", "cache"};
    if (!a.has("--max-size")) throw UsageError{"--max-size SIZE is required (e.g. 2GiB; 0 empties the cache)", "cache"};
    const uint64_t max = parse_byte_size(a.get("--max-size"));
    std::error_code ec;
    if (!std::filesystem::is_directory(dir, ec)) throw Error(dir + ": not a cache directory (no such directory)");
    const auto r = disk_cache::prune(dir, max);
    // stdout: data (one line); the sizes in bytes for scripts.
    std::cout << "removed " << r.removed_files << " entries (" << r.removed_bytes << " bytes), " << r.bytes_after << " bytes left in " << dir
              << "\n";
    if (!a.has("--quiet")) {
        std::cerr << "cache " << dir << ": " << mib(r.bytes_before) << " -> " << mib(r.bytes_after);
        if (r.stale_staging_bytes) std::cerr << "; removed " << mib(r.stale_staging_bytes) << " left by killed cooks";
        std::cerr << "\n";
    }
    return 0;
}

} // namespace atlas::cli
