// The in-memory cache of node results (value_cache.h); the on-disk cache is disk_cache.cpp.
#include "value_cache.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>

namespace atlas {

std::shared_ptr<const NodeOutputs> ValueCache::find(const Hash128& h) const {
    auto it = entries_.find(h);
    return it == entries_.end() ? nullptr : it->second;
}

void ValueCache::put(const Hash128& h, std::shared_ptr<const NodeOutputs> v) { entries_[h] = std::move(v); }

void ValueCache::evict(uint64_t bytes) {
    std::lock_guard<std::mutex> lock(evict_mutex_);
    const uint64_t start = ledger_.in_use();
    auto freed = [&] { return ledger_.in_use() + bytes <= start; };
    for (int pass = 0; pass < 2 && !freed(); ++pass)
        for (auto it = entries_.begin(); it != entries_.end() && !freed();) {
            // First pass: only what nothing else holds (dropping it frees memory).
            if (pass == 0 && it->second.use_count() > 1) ++it;
            else it = entries_.erase(it);
        }
}

std::shared_ptr<const NodeOutputs> held_outputs(NodeOutputs outputs, const detail::MemoryLedger& ledger) {
    std::vector<std::shared_ptr<void>> tokens;
    for (const auto& [port, v] : outputs) {
        const void* key = std::visit([](const auto& p) -> const void* {
            if constexpr (std::is_same_v<std::decay_t<decltype(p)>, std::monostate>) return nullptr;
            else return p.get();
        }, v);
        if (auto t = ledger.hold(key, value_storage_bytes(v))) tokens.push_back(std::move(t));
    }
    auto* raw = new NodeOutputs(std::move(outputs));
    return std::shared_ptr<const NodeOutputs>(raw, [tokens = std::move(tokens)](const NodeOutputs* p) mutable {
        delete p;
        tokens.clear();
    });
}

void ValueCache::retain_only(const std::unordered_set<Hash128, Hash128Hasher>& keep) {
    for (auto it = entries_.begin(); it != entries_.end();) {
        if (keep.count(it->first)) ++it;
        else it = entries_.erase(it);
    }
}

} // namespace atlas
