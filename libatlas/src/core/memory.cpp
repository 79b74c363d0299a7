#include "atlas/core/memory.h"

#include "atlas/core/error.h"

#include <cctype>
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

void MemoryBudget::check(uint64_t bytes, std::string_view what) const {
    if (bytes > limit_) {
        throw MemoryBudgetError(std::string(what) + " needs " + format_bytes(bytes) +
                                ", over the memory budget of " + format_bytes(limit_) +
                                " (raise it with --memory-budget, or lower the resolution)");
    }
}

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
