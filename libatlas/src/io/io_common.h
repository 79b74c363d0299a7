// Private helpers shared by the io readers and writers.
#pragma once

#include "atlas/core/error.h"
#include "atlas/core/memory.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <string>

namespace atlas::io::detail {

namespace fs = std::filesystem;

// Readers check every allocation a file asks for against a budget, so a
// corrupt header claiming a 100000^2 image is refused instead of exhausting
// memory. Without a caller budget, the default limit applies.
inline const MemoryBudget& budget_or_default(const MemoryBudget* given, const MemoryBudget& fallback) {
    return given ? *given : fallback;
}

// Throws "PATH: cannot open KIND file (no such file | is a directory)".
inline void require_regular_file(const fs::path& path, const std::string& kind) {
    std::error_code ec;
    const auto st = fs::status(path, ec);
    if (ec || !fs::exists(st)) throw Error(path.string() + ": cannot open " + kind + " file (no such file)");
    if (fs::is_directory(st)) throw Error(path.string() + ": cannot open " + kind + " file (it is a directory)");
    // A device, FIFO or socket has no end (or blocks): refused before any read.
    if (!fs::is_regular_file(st)) throw Error(path.string() + ": cannot open " + kind + " file (not a regular file: a device, FIFO or socket)");
}

// Linear map of [lo, hi] onto 0..full (full = 2^bits - 1), clamped, rounded
// to nearest. The caller rejects NaN first; infinities clamp.
class Quantiser {
public:
    Quantiser(float lo, float hi, int bits) : lo_(lo), full_(std::ldexp(1.0, bits) - 1.0), scale_(full_ / (double(hi) - double(lo))) {}
    uint16_t operator()(float v) const {
        const double s = std::clamp((double(v) - lo_) * scale_, 0.0, full_);
        return static_cast<uint16_t>(std::lround(s));
    }

private:
    double lo_, full_, scale_;
};

// Value range options are valid when both ends are finite and hi > lo.
inline bool valid_range(float lo, float hi) { return std::isfinite(lo) && std::isfinite(hi) && hi > lo; }

} // namespace atlas::io::detail
