#include "atlas/core/memory.h"
#include "memory_ledger.h"

#include "atlas/core/error.h"

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
    std::mutex mutex; // guards held and evictor
    std::unordered_map<const void*, uint64_t> held;
    std::shared_ptr<std::function<void(uint64_t)>> evictor;
};
} // namespace detail

namespace {
// Which budgets have a ledger attached (a session's, for the length of a
// cook). Keyed by the budget's address; entries live only while attached.
std::mutex g_attached_mutex;
std::unordered_map<const MemoryBudget*, std::shared_ptr<detail::LedgerState>>& attached() {
    static std::unordered_map<const MemoryBudget*, std::shared_ptr<detail::LedgerState>> m;
    return m;
}
std::shared_ptr<detail::LedgerState> ledger_of(const MemoryBudget* b) {
    std::lock_guard<std::mutex> lock(g_attached_mutex);
    auto it = attached().find(b);
    return it == attached().end() ? nullptr : it->second;
}
} // namespace

void MemoryBudget::check(uint64_t bytes, std::string_view what) const {
    const std::shared_ptr<detail::LedgerState> st = ledger_of(this);
    auto used = [&]() -> uint64_t { return st ? st->used.load() : 0; };
    auto over = [&] { return bytes > limit_ || used() > limit_ - bytes; };
    if (!over()) return;
    if (st && bytes <= limit_) {
        // The evictor runs without the lock: what it frees comes back through tokens.
        std::shared_ptr<std::function<void(uint64_t)>> evict;
        {
            std::lock_guard<std::mutex> lock(st->mutex);
            evict = st->evictor;
        }
        if (evict) (*evict)(used() + bytes - limit_);
        if (!over()) return;
    }
    const uint64_t held = used();
    throw MemoryBudgetError(std::string(what) + " needs " + format_bytes(bytes) + ", over the memory budget of " + format_bytes(limit_) +
                            (held ? " (" + format_bytes(held) + " already held by the cook's values and cache)" : std::string()) +
                            " (raise it with --memory-budget, or lower the resolution)");
}

namespace detail {

MemoryLedger::MemoryLedger() : state_(std::make_shared<LedgerState>()) {}

uint64_t MemoryLedger::in_use() const { return state_->used.load(); }

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
    st->used += bytes;
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
    return hold_in(ledger_of(&budget), key, bytes);
}

MemoryLedger::Attachment::Attachment(const MemoryBudget& budget, const MemoryLedger& ledger) : budget_(&budget) {
    std::lock_guard<std::mutex> lock(g_attached_mutex);
    attached()[budget_] = ledger.state_;
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
