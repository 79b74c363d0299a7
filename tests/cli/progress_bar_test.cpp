// The progress line's text (issue 17 item 8): a 30-cell bar filled in
// proportion, the percentage, the elapsed time and, once 2% and a second are
// behind, the time left at the rate so far. The expected text is built here
// from the definitions (m:ss, h:mm:ss), not copied from a run.
#include "progress_bar.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

using atlas::cli::ProgressBar;

namespace {
std::string mmss(double seconds) {
    const long s = std::lround(seconds);
    char b[32];
    if (s >= 3600) std::snprintf(b, sizeof b, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
    else std::snprintf(b, sizeof b, "%ld:%02ld", s / 60, s % 60);
    return b;
}
} // namespace

TEST(ProgressBarLine, ShowsBarPercentElapsedAndTimeLeft) {
    for (double f : {0.0, 0.1, 0.25, 0.5, 0.9, 1.0})
        for (double elapsed : {0.4, 5.0, 75.0, 4000.0}) {
            const std::string l = ProgressBar::line(f, elapsed, 3, 12, "node 'sdf'");
            SCOPED_TRACE(l);
            const size_t open = l.find('['), close = l.find(']');
            ASSERT_EQ(open, 0u);
            ASSERT_EQ(close, 31u);
            const std::string bar = l.substr(1, 30);
            EXPECT_EQ(long(std::count(bar.begin(), bar.end(), '#')), std::lround(f * 30));
            EXPECT_NE(l.find(std::to_string(int(f * 100)) + "%"), std::string::npos);
            EXPECT_NE(l.find("3/12"), std::string::npos);
            EXPECT_NE(l.find(mmss(elapsed) + " elapsed"), std::string::npos);
            std::string left = "--:--";
            if (f >= 1.0) left = "0:00";
            else if (f >= 0.02 && elapsed >= 1.0) left = mmss(elapsed * (1 - f) / f);
            EXPECT_NE(l.find(left + " left"), std::string::npos);
            EXPECT_NE(l.find("node 'sdf'"), std::string::npos);
        }
}

TEST(ProgressBarLine, LongTasksAreCut) {
    const std::string task(100, 'x');
    const std::string l = ProgressBar::line(0.5, 2, 1, 2, task);
    EXPECT_EQ(l.find(task), std::string::npos);
    EXPECT_NE(l.find(std::string(29, 'x') + "..."), std::string::npos);
}
