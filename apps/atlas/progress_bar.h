// A progress line on stderr, redrawn in place on a terminal, silent otherwise.
//
// One bar per command: it only moves forward (a cook of several graphs maps
// each graph's 0..1 into its share of the bar) and shows the elapsed time and,
// once there is enough to go on, an estimate of the time left.
#pragma once

#include "atlas/core/progress.h"

#include <atomic>
#include <chrono>
#include <mutex>
#include <string>

namespace atlas::cli {

class ProgressBar {
public:
    explicit ProgressBar(bool enabled);
    ~ProgressBar();
    // A sink whose callbacks draw this bar and honour Ctrl-C.
    ProgressSink sink();
    // Part `index` of `count` (0-based) begins: its fractions fill
    // [index/count, (index+1)/count] of the bar.
    void begin_part(int index, int count);
    void finish();

    // The line drawn for `fraction` after `elapsed` seconds (for tests).
    static std::string line(double fraction, double elapsed, int done, int total, const std::string& task);

private:
    void draw(const ProgressEvent& e);
    bool enabled_;
    bool drawn_ = false;
    std::mutex mutex_;
    std::chrono::steady_clock::time_point start_, last_;
    double part_lo_ = 0, part_hi_ = 1, shown_ = 0;
};

// True once the user pressed Ctrl-C (SIGINT); installed by ProgressBar.
bool interrupted();

} // namespace atlas::cli
