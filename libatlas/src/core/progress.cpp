#include "atlas/core/progress.h"

#include "atlas/core/error.h"

#include <chrono>

namespace atlas {

void ProgressSink::poll() const {
    if (cancelled()) throw CancelledError();
}

namespace detail {
namespace {
thread_local const std::function<bool()>* t_cancel = nullptr;
}

const std::function<bool()>* current_cancel() { return t_cancel; }

CancelScope::CancelScope(const std::function<bool()>* check) : previous_(t_cancel) { t_cancel = check && *check ? check : nullptr; }
CancelScope::~CancelScope() { t_cancel = previous_; }

void poll_cancel(const std::function<bool()>* check) {
    if (!check || !*check) return;
    thread_local std::chrono::steady_clock::time_point last{};
    const auto now = std::chrono::steady_clock::now();
    if (now - last < std::chrono::milliseconds(20)) return;
    last = now;
    if ((*check)()) throw CancelledError();
}
} // namespace detail

} // namespace atlas
