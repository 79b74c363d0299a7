// atlas/core/error.h - the exceptions every Atlas library call may throw.
//
// The library never prints and never exits: every failure is one of these,
// and its message names the place (file:line:col, node, parameter) and says
// what was expected. Hosts catch atlas::Error (or std::exception).
#pragma once

#include <stdexcept>
#include <string>

namespace atlas {

// Base class of every Atlas error. what() is the full, user-facing message.
class Error : public std::runtime_error {
public:
    explicit Error(const std::string& message) : std::runtime_error(message) {}
};

// A position in a text file; line and column are 1-based (0 = unknown).
struct SourceLocation {
    std::string file;
    int line = 0;
    int column = 0;

    // "file:line:col" (or fewer parts when unknown).
    std::string str() const;
};

// A graph file (or other text input) that cannot be used. what() is
// "file:line:col: error: <message>" as compilers print it.
class ParseError : public Error {
public:
    ParseError(SourceLocation where, const std::string& message);
    const SourceLocation& where() const { return where_; }
    // The message without the location prefix.
    const std::string& detail() const { return detail_; }

private:
    SourceLocation where_;
    std::string detail_;
};

// A request would allocate more memory than the configured budget allows.
class MemoryBudgetError : public Error {
public:
    using Error::Error;
};

// The host asked to stop (through the cancel callback).
class CancelledError : public Error {
public:
    CancelledError() : Error("cancelled") {}
};

} // namespace atlas
