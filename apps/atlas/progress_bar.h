// A progress line on stderr, redrawn in place on a terminal, silent otherwise.
#pragma once

#include "atlas/core/progress.h"

#include <atomic>
#include <chrono>
#include <mutex>

namespace atlas::cli {

class ProgressBar {
public:
    explicit ProgressBar(bool enabled);
    ~ProgressBar();
    // A sink whose callbacks draw this bar and honour Ctrl-C.
    ProgressSink sink();
    void finish();

private:
    void draw(const ProgressEvent& e);
    bool enabled_;
    bool drawn_ = false;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point last_;
};

// True once the user pressed Ctrl-C (SIGINT); installed by ProgressBar.
bool interrupted();

} // namespace atlas::cli
