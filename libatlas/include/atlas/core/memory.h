// atlas/core/memory.h - memory estimates and the allocation budget.
//
// Every large allocation (a field, a grid, a scratch buffer) is estimated
// first and checked against a MemoryBudget, so that a graph asking for a
// 4096^3 volume is refused with a clear message instead of thrashing or
// being killed. The budget is a value owned by the caller, not global state.
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace atlas {

// Human-readable size: "512 B", "3.2 MiB", "8.0 GiB".
std::string format_bytes(uint64_t bytes);

class MemoryBudget {
public:
    static constexpr uint64_t kDefaultLimit = 8ull << 30; // 8 GiB

    explicit MemoryBudget(uint64_t limit_bytes = kDefaultLimit) : limit_(limit_bytes) {}
    uint64_t limit() const { return limit_; }

    // Throws MemoryBudgetError when `bytes` is over the limit. `what` names
    // the requester and the thing, e.g. "node 'clouds': a 512x512x64x4 field".
    void check(uint64_t bytes, std::string_view what) const;

private:
    uint64_t limit_;
};

// Parses "8GiB", "512MiB", "2G", "1000000" (bytes). Throws atlas::Error.
uint64_t parse_byte_size(std::string_view text);

} // namespace atlas
