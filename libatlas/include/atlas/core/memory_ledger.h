// atlas/core/memory_ledger.h - the live total behind a MemoryBudget (issue 17 item 6), for the
// evaluator (graph) and its tests; hosts use Session and MemoryBudget, not this.
//
// Implemented in memory.cpp, beside MemoryBudget::check, which reads the attached ledger.
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
    // Bytes held by live tokens and open scratch scopes.
    uint64_t in_use() const;
    // The most in_use() has been since construction or reset_peak().
    uint64_t peak() const;
    void reset_peak() const;
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

    // A node's cook (issue 17 item 6: scratch counts). While alive, every
    // allocation `node_budget` passes in check() is counted against the
    // ledger until the scope ends (a node's scratch fields and buffers live
    // at most as long as its cook), so the live total includes what running
    // nodes hold, not only finished values. A field made through a
    // CookContext is handed from the scope to its own token (hold_against),
    // so it stops counting when it dies, and an output is counted once.
    // `node_budget` must have the same limit as the cook's budget and must
    // not be attached otherwise.
    class ScratchScope {
    public:
        ScratchScope(const MemoryBudget& node_budget, const MemoryLedger& ledger);
        ~ScratchScope();
        ScratchScope(const ScratchScope&) = delete;
        ScratchScope& operator=(const ScratchScope&) = delete;
        // Bytes the scope holds now (checked allocations not handed to a token).
        uint64_t held() const;

    private:
        const MemoryBudget* budget_;
    };

private:
    friend class Attachment;
    friend class ScratchScope;
    std::shared_ptr<LedgerState> state_;
};

// hold() on the ledger attached to `budget`; null when none is.
std::shared_ptr<void> hold_against(const MemoryBudget& budget, const void* key, uint64_t bytes);

} // namespace atlas::detail
