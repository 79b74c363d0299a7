#include "atlas/compress/block.h"

#include "atlas/core/error.h"

#include <string>

namespace atlas::compress {

const char* quality_name(Quality q) {
    switch (q) {
    case Quality::Fast: return "fast";
    case Quality::Normal: return "normal";
    case Quality::Best: return "best";
    }
    return "?";
}

Quality parse_quality(const char* name) {
    const std::string n = name ? name : "";
    if (n == "fast") return Quality::Fast;
    if (n == "normal") return Quality::Normal;
    if (n == "best") return Quality::Best;
    throw Error("unknown quality '" + n + "' (expected fast, normal or best)");
}

} // namespace atlas::compress
