#include "progress_bar.h"

#include <csignal>
#include <cstdio>
#include <string>
#include <unistd.h>

namespace atlas::cli {

namespace {
volatile std::sig_atomic_t g_interrupted = 0; // the one piece of process state: a signal flag
extern "C" void on_sigint(int) { g_interrupted = 1; }
} // namespace

bool interrupted() { return g_interrupted != 0; }

ProgressBar::ProgressBar(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO)) {
    std::signal(SIGINT, on_sigint);
}

ProgressBar::~ProgressBar() { finish(); }

ProgressSink ProgressBar::sink() {
    ProgressSink s;
    s.is_cancelled = [] { return interrupted(); };
    if (enabled_) s.on_progress = [this](const ProgressEvent& e) { draw(e); };
    return s;
}

void ProgressBar::draw(const ProgressEvent& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    auto now = std::chrono::steady_clock::now();
    if (drawn_ && e.fraction < 1.0 && now - last_ < std::chrono::milliseconds(100)) return;
    last_ = now;
    const int width = 30;
    int filled = int(e.fraction * width + 0.5);
    std::string bar(size_t(filled), '#');
    bar += std::string(size_t(width - filled), '.');
    std::string task = e.task.size() > 40 ? e.task.substr(0, 37) + "..." : e.task;
    std::fprintf(stderr, "\r[%s] %3d%%  %d/%d  %-40s", bar.c_str(), int(e.fraction * 100 + 0.5), e.done, e.total, task.c_str());
    std::fflush(stderr);
    drawn_ = true;
}

void ProgressBar::finish() {
    std::lock_guard<std::mutex> lock(mutex_);
    if (drawn_) std::fprintf(stderr, "\r%*s\r", 100, "");
    drawn_ = false;
}

} // namespace atlas::cli
