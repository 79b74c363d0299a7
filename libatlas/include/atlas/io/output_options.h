// atlas/io/output_options.h - typed reading of an output's option strings.
//
// Every format writer (writers.cpp, and any writer appended to the format
// table, such as DDS) reads its options through this class so that values
// are parsed the same way and bad ones fail with the same kind of message:
//   output 'x.png': option 'bits': expected 8 or 16, got '12'
// Parsing is locale-independent (std::from_chars). Not thread-safe to share
// while the map is modified; otherwise stateless.
#pragma once

#include <filesystem>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace atlas::io {

class OptionReader {
public:
    // `output` is the file (or DIR/STEM) being written, used in messages as
    // its file name only (so staging directories do not leak into them).
    OptionReader(const std::map<std::string, std::string>& options, const std::filesystem::path& output);

    // "output 'NAME': " - the prefix of every message about this output.
    const std::string& prefix() const { return prefix_; }
    bool has(const std::string& key) const { return options_.count(key) > 0; }
    const std::string& text(const std::string& key) const { return options_.at(key); }

    // Throws atlas::Error "output 'x': option 'key': expected <expected>, got '<value>'".
    [[noreturn]] void bad(const std::string& key, const std::string& expected) const;

    // Decimal integer in [lo, hi]; `fallback` when absent.
    int integer(const std::string& key, int fallback, int lo, int hi) const;
    // true/1/yes/on or false/0/no/off; false when absent.
    bool flag(const std::string& key) const;
    // Finite number in [lo, hi] (hi may be +infinity: no upper limit); `fallback` when absent.
    float number(const std::string& key, float fallback, float lo, float hi) const;
    // "lo,hi" with finite lo < hi; {lo, hi} defaults when absent.
    std::pair<float, float> range(const std::string& key, float lo, float hi) const;
    // Comma-separated non-empty names (spaces around them trimmed); empty when absent.
    std::vector<std::string> list(const std::string& key) const;

private:
    const std::map<std::string, std::string>& options_;
    std::string prefix_;
};

} // namespace atlas::io
