#include "progress_bar.h"

#include <algorithm>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <string>
#include <unistd.h>

namespace atlas::cli {

namespace {
volatile std::sig_atomic_t g_interrupted = 0; // the one piece of process state: a signal flag
extern "C" void on_sigint(int) { g_interrupted = 1; }

std::string clock_text(double seconds) {
    const long s = long(std::lround(std::max(0.0, seconds)));
    char buf[32];
    if (s >= 3600) std::snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, s / 60 % 60, s % 60);
    else std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
    return buf;
}
} // namespace

bool interrupted() { return g_interrupted != 0; }

ProgressBar::ProgressBar(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO)), start_(std::chrono::steady_clock::now()) {
    std::signal(SIGINT, on_sigint);
}

ProgressBar::~ProgressBar() { finish(); }

ProgressSink ProgressBar::sink() {
    ProgressSink s;
    s.is_cancelled = [] { return interrupted(); };
    if (enabled_) s.on_progress = [this](const ProgressEvent& e) { draw(e); };
    return s;
}

void ProgressBar::begin_part(int index, int count) {
    std::lock_guard<std::mutex> lock(mutex_);
    count = std::max(1, count);
    part_lo_ = double(index) / count;
    part_hi_ = double(index + 1) / count;
}

std::string ProgressBar::line(double fraction, double elapsed, int done, int total, const std::string& task) {
    fraction = std::clamp(fraction, 0.0, 1.0);
    const int width = 30;
    const int filled = int(fraction * width + 0.5);
    std::string bar(size_t(filled), '#');
    bar += std::string(size_t(width - filled), '.');
    // The time left, at the rate so far; only once a little is done (the
    // first seconds say nothing about the rest).
    std::string eta = "--:--";
    if (fraction >= 1.0) eta = "0:00";
    else if (fraction >= 0.02 && elapsed >= 1.0) eta = clock_text(elapsed * (1.0 - fraction) / fraction);
    const std::string t = task.size() > 32 ? task.substr(0, 29) + "..." : task;
    char buf[256];
    std::snprintf(buf, sizeof buf, "[%s] %3d%%  %d/%d  %s elapsed, %s left  %-32s", bar.c_str(), int(fraction * 100), done, total,
                  clock_text(elapsed).c_str(), eta.c_str(), t.c_str());
    return buf;
}

void ProgressBar::draw(const ProgressEvent& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto now = std::chrono::steady_clock::now();
    // Never backwards, whatever the parts report.
    shown_ = std::max(shown_, part_lo_ + (part_hi_ - part_lo_) * std::clamp(e.fraction, 0.0, 1.0));
    if (drawn_ && shown_ < 1.0 && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const double elapsed = std::chrono::duration<double>(now - start_).count();
    std::fprintf(stderr, "\r%s", line(shown_, elapsed, e.done, e.total, e.task).c_str());
    std::fflush(stderr);
    drawn_ = true;
}

void ProgressBar::finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (drawn_) std::fprintf(stderr, "\r%*s\r", 120, "");
    drawn_ = false;
}

} // namespace atlas::cli
