#include "atlas/core/memory.h"
#include "atlas/core/memory_ledger.h"

#include "atlas/core/error.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <mutex>
#include <unordered_map>
#include <cmath>
#include <cstdio>

namespace atlas {

std::string format_bytes(uint64_t bytes) {
    const char* units[] = {"B", "KiB", "MiB", "GiB", "TiB", "PiB"};
    double v = double(bytes);
    int u = 0;
    while (v >= 1024.0 && u < 5) { v /= 1024.0; ++u; }
    char buf[64];
    if (u == 0) std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
    else std::snprintf(buf, sizeof buf, "%.1f %s", v, units[u]);
    return buf;
}

namespace detail {
struct LedgerState {
    std::atomic<uint64_t> used{0};
    std::atomic<uint64_t> peak{0};
    void add(uint64_t bytes) {
        const uint64_t now = used.fetch_add(bytes) + bytes;
        uint64_t p = peak.load();
        while (now > p && !peak.compare_exchange_weak(p, now)) {
        }
    }
    std::mutex mutex; // guards held and evictor
    std::unordered_map<const void*, uint64_t> held;
    std::shared_ptr<std::function<void(uint64_t)>> evictor;
};
} // namespace detail

namespace {
// What a node's scratch scope holds (see MemoryLedger::ScratchScope).
struct ScratchState {
    std::atomic<uint64_t> held{0};
};
struct Attached {
    std::shared_ptr<detail::LedgerState> ledger;
    std::shared_ptr<ScratchState> scratch; // null for a cook's own budget
};
// Which budgets have a ledger attached (a session's, for the length of a
// cook; a node's, for the length of its cook). Keyed by the budget's
// address; entries live only while attached.
std::mutex g_attached_mutex;
std::unordered_map<const MemoryBudget*, Attached>& attached() {
    static std::unordered_map<const MemoryBudget*, Attached> m;
    return m;
}
Attached attachment_of(const MemoryBudget* b) {
    std::lock_guard<std::mutex> lock(g_attached_mutex);
    auto it = attached().find(b);
    return it == attached().end() ? Attached{} : it->second;
}
} // namespace

void MemoryBudget::check(uint64_t bytes, std::string_view what) const {
    const Attached at = attachment_of(this);
    const std::shared_ptr<detail::LedgerState>& st = at.ledger;
    // A node's scratch: what passes is counted until the node's cook ends.
    auto reserve = [&] {
        if (at.scratch && bytes) {
            at.scratch->held += bytes;
            st->add(bytes);
        }
    };
    auto used = [&]() -> uint64_t { return st ? st->used.load() : 0; };
    auto over = [&] { return bytes > limit_ || used() > limit_ - bytes; };
    if (!over()) return reserve();
    if (st && bytes <= limit_) {
        // The evictor runs without the lock: what it frees comes back through tokens.
        std::shared_ptr<std::function<void(uint64_t)>> evict;
        {
            std::lock_guard<std::mutex> lock(st->mutex);
            evict = st->evictor;
        }
        if (evict) (*evict)(used() + bytes - limit_);
        if (!over()) return reserve();
    }
    const uint64_t held = used();
    throw MemoryBudgetError(std::string(what) + " needs " + format_bytes(bytes) + ", over the memory budget of " + format_bytes(limit_) +
                            (held ? " (" + format_bytes(held) + " already held by the cook's values, cache and running nodes)" : std::string()) +
                            " (raise it with --memory-budget, or lower the resolution)");
}

namespace detail {

MemoryLedger::MemoryLedger() : state_(std::make_shared<LedgerState>()) {}

uint64_t MemoryLedger::in_use() const { return state_->used.load(); }
uint64_t MemoryLedger::peak() const { return state_->peak.load(); }
void MemoryLedger::reset_peak() const { state_->peak = state_->used.load(); }

void MemoryLedger::set_evictor(std::function<void(uint64_t)> evictor) const {
    std::lock_guard<std::mutex> lock(state_->mutex);
    state_->evictor = evictor ? std::make_shared<std::function<void(uint64_t)>>(std::move(evictor)) : nullptr;
}

namespace {
std::shared_ptr<void> hold_in(const std::shared_ptr<LedgerState>& st, const void* key, uint64_t bytes) {
    if (!st || !key || !bytes) return nullptr;
    {
        std::lock_guard<std::mutex> lock(st->mutex);
        if (!st->held.emplace(key, bytes).second) return nullptr;
    }
    st->add(bytes);
    // The token: a non-null pointer whose deleter gives the bytes back.
    return std::shared_ptr<void>(reinterpret_cast<void*>(uintptr_t(1)), [st, key, bytes](void*) {
        {
            std::lock_guard<std::mutex> lock(st->mutex);
            st->held.erase(key);
        }
        st->used -= bytes;
    });
}
} // namespace

std::shared_ptr<void> MemoryLedger::hold(const void* key, uint64_t bytes) const { return hold_in(state_, key, bytes); }

std::shared_ptr<void> hold_against(const MemoryBudget& budget, const void* key, uint64_t bytes) {
    const Attached at = attachment_of(&budget);
    if (!at.scratch) return hold_in(at.ledger, key, bytes);
    // The field's check() put its bytes into the node's scratch; from now on
    // its token counts them (and gives them back when it dies). Taken out of
    // the scratch first, so the high-water mark never counts them twice.
    uint64_t h = at.scratch->held.load();
    uint64_t moved = 0;
    while (true) {
        moved = std::min(h, bytes);
        if (at.scratch->held.compare_exchange_weak(h, h - moved)) break;
    }
    at.ledger->used -= moved;
    auto token = hold_in(at.ledger, key, bytes);
    if (!token) {
        // Already held (or nothing to hold): the scratch keeps counting it.
        at.scratch->held += moved;
        at.ledger->add(moved);
    }
    return token;
}

MemoryLedger::Attachment::Attachment(const MemoryBudget& budget, const MemoryLedger& ledger) : budget_(&budget) {
    std::lock_guard<std::mutex> lock(g_attached_mutex);
    attached()[budget_] = Attached{ledger.state_, nullptr};
}

MemoryLedger::ScratchScope::ScratchScope(const MemoryBudget& node_budget, const MemoryLedger& ledger) : budget_(&node_budget) {
    std::lock_guard<std::mutex> lock(g_attached_mutex);
    attached()[budget_] = Attached{ledger.state_, std::make_shared<ScratchState>()};
}

MemoryLedger::ScratchScope::~ScratchScope() {
    Attached at;
    {
        std::lock_guard<std::mutex> lock(g_attached_mutex);
        auto it = attached().find(budget_);
        if (it == attached().end()) return;
        at = it->second;
        attached().erase(it);
    }
    if (at.scratch) at.ledger->used -= at.scratch->held.exchange(0);
}

uint64_t MemoryLedger::ScratchScope::held() const {
    const Attached at = attachment_of(budget_);
    return at.scratch ? at.scratch->held.load() : 0;
}

MemoryLedger::Attachment::~Attachment() {
    std::lock_guard<std::mutex> lock(g_attached_mutex);
    attached().erase(budget_);
}

} // namespace detail

uint64_t parse_byte_size(std::string_view text) {
    size_t i = 0;
    while (i < text.size() && (std::isdigit(static_cast<unsigned char>(text[i])) || text[i] == '.')) ++i;
    std::string number(text.substr(0, i));
    std::string unit(text.substr(i));
    for (auto& ch : unit) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    double scale = 0;
    if (unit.empty() || unit == "b") scale = 1;
    else if (unit == "k" || unit == "kb" || unit == "kib") scale = 1024.0;
    else if (unit == "m" || unit == "mb" || unit == "mib") scale = 1024.0 * 1024;
    else if (unit == "g" || unit == "gb" || unit == "gib") scale = 1024.0 * 1024 * 1024;
    else if (unit == "t" || unit == "tb" || unit == "tib") scale = 1024.0 * 1024 * 1024 * 1024;
    double value = 0;
    try {
        size_t used = 0;
        value = number.empty() ? -1 : std::stod(number, &used);
        if (used != number.size()) value = -1;
    } catch (...) {
        value = -1;
    }
    if (scale == 0 || !(value >= 0) || !std::isfinite(value * scale) || value * scale > 1.8e19)
        throw Error("invalid byte size '" + std::string(text) + "': expected a number with an optional unit (B, KiB, MiB, GiB, TiB), e.g. 8GiB");
    return static_cast<uint64_t>(std::llround(value * scale));
}

} // namespace atlas
