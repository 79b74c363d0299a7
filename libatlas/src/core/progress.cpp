#include "atlas/core/progress.h"

#include "atlas/core/error.h"

#include <chrono>

#include <sys/resource.h>

namespace atlas {

double process_cpu_seconds() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return double(u.ru_utime.tv_sec + u.ru_stime.tv_sec) + 1e-6 * double(u.ru_utime.tv_usec + u.ru_stime.tv_usec);
}

uint64_t process_peak_rss_bytes() {
    rusage u{};
    getrusage(RUSAGE_SELF, &u);
    return uint64_t(u.ru_maxrss) * 1024; // Linux: kilobytes
}

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
