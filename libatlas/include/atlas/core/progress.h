// atlas/core/progress.h - progress reporting and cancellation through callbacks.
//
// The library never writes to a terminal. Long work reports a fraction done
// through ProgressSink::on_progress and polls ProgressSink::is_cancelled; a
// host (the CLI's progress bar, an editor's status bar) supplies both.
// Callbacks may be invoked from worker threads, so hosts must make them
// thread-safe; Atlas serialises nothing for them.
#pragma once

#include <chrono>
#include <cstdint>
#include <functional>
#include <string>

namespace atlas {

// Wall seconds since t0 (the figures reports and progress print).
inline double seconds_since(std::chrono::steady_clock::time_point t0) {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

// This process's CPU seconds (user + system) and peak resident set so far: what a
// tile report records of its own cost.
double process_cpu_seconds();
uint64_t process_peak_rss_bytes();

struct ProgressEvent {
    std::string task;     // what is running, e.g. "node 'clouds'"
    double fraction = 0;  // 0..1 within the whole job
    int done = 0;         // units of work finished (e.g. nodes cooked)
    int total = 0;        // units of work in the job
};

struct ProgressSink {
    std::function<void(const ProgressEvent&)> on_progress; // may be empty
    std::function<bool()> is_cancelled;                     // may be empty

    bool cancelled() const { return is_cancelled && is_cancelled(); }
    // Throws CancelledError if the host asked to stop.
    void poll() const;
};

namespace detail {
// The cancellation check of the cook running on this thread, seen by the
// parallel loops it starts (parallel.h polls it between blocks and hands it to
// the threads that run them), so a long loop stops on Ctrl-C without polling
// of its own. Null when none.
const std::function<bool()>* current_cancel();
// Makes `check` the current one on this thread while alive (null: none).
class CancelScope {
public:
    explicit CancelScope(const std::function<bool()>* check);
    ~CancelScope();
    CancelScope(const CancelScope&) = delete;
    CancelScope& operator=(const CancelScope&) = delete;

private:
    const std::function<bool()>* previous_;
};
// Throws CancelledError when `check` says stop. Asks at most every 20 ms per
// thread: a host's check may take a lock (Python's takes the GIL).
void poll_cancel(const std::function<bool()>* check);
} // namespace detail

} // namespace atlas
