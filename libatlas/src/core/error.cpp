#include "atlas/core/error.h"

namespace atlas {

std::string SourceLocation::str() const {
    std::string s = file.empty() ? std::string("<input>") : file;
    if (line > 0) {
        s += ":" + std::to_string(line);
        if (column > 0) s += ":" + std::to_string(column);
    }
    return s;
}

ParseError::ParseError(SourceLocation where, const std::string& message)
    : Error(where.str() + ": error: " + message), where_(std::move(where)), detail_(message) {}

} // namespace atlas
