// Internal: the live total behind a MemoryBudget (issue 17 item 6).
//
// A MemoryBudget alone checks each allocation against its limit. A session
// keeps one MemoryLedger across cooks and attaches it to the cook's budget:
// while attached, MemoryBudget::check() counts what the ledger holds (the
// cook's fields and values, the in-memory cache) plus the new allocation, and
// asks the ledger's evictor to free room before it refuses. Things are held
// through tokens that give their bytes back when destroyed, so a field held
// by a value, the cache and a node at once counts once and only while alive.
// (MemoryBudget's header stays as it is: it is part of nearly every file.)
#pragma once

#include "atlas/core/memory.h"

#include <cstdint>
#include <functional>
#include <memory>

namespace atlas::detail {

struct LedgerState;

class MemoryLedger {
public:
    MemoryLedger();
    // Bytes held by live tokens.
    uint64_t in_use() const;
    // Counts `bytes` of the object at `key` until the token dies; null when
    // `key` is already held (or null, or 0 bytes). Never refuses.
    std::shared_ptr<void> hold(const void* key, uint64_t bytes) const;
    // Called by check() with the bytes missing before it refuses (may be empty).
    void set_evictor(std::function<void(uint64_t missing)> evictor) const;

    // While alive, `budget` counts against this ledger.
    class Attachment {
    public:
        Attachment(const MemoryBudget& budget, const MemoryLedger& ledger);
        ~Attachment();
        Attachment(const Attachment&) = delete;
        Attachment& operator=(const Attachment&) = delete;

    private:
        const MemoryBudget* budget_;
    };

private:
    friend class Attachment;
    std::shared_ptr<LedgerState> state_;
};

// hold() on the ledger attached to `budget`; null when none is.
std::shared_ptr<void> hold_against(const MemoryBudget& budget, const void* key, uint64_t bytes);

} // namespace atlas::detail
