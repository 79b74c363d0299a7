#include "atlas/io/output_options.h"

#include "atlas/core/error.h"

#include <charconv>
#include <cmath>

namespace atlas::io {

namespace {

std::string trim(const std::string& s) {
    const size_t a = s.find_first_not_of(" \t");
    if (a == std::string::npos) return {};
    const size_t b = s.find_last_not_of(" \t");
    return s.substr(a, b - a + 1);
}

// The whole (trimmed) text as a finite float, or false.
bool parse_float(const std::string& text, float& out) {
    const std::string s = trim(text);
    if (s.empty()) return false;
    const char* begin = s.data() + (s[0] == '+' ? 1 : 0);
    const auto r = std::from_chars(begin, s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(out);
}

std::string shortest(float v) {
    char buf[32];
    const auto r = std::to_chars(buf, buf + sizeof buf, v);
    return std::string(buf, r.ptr);
}

} // namespace

OptionReader::OptionReader(const std::map<std::string, std::string>& options, const std::filesystem::path& output)
    : options_(options), prefix_("output '" + output.filename().string() + "': ") {}

void OptionReader::bad(const std::string& key, const std::string& expected) const {
    throw Error(prefix_ + "option '" + key + "': expected " + expected + ", got '" + (has(key) ? text(key) : std::string()) + "'");
}

int OptionReader::integer(const std::string& key, int fallback, int lo, int hi) const {
    if (!has(key)) return fallback;
    const std::string s = trim(text(key));
    int v = 0;
    const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || r.ec != std::errc() || r.ptr != s.data() + s.size() || v < lo || v > hi)
        bad(key, "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
    return v;
}

bool OptionReader::flag(const std::string& key) const {
    if (!has(key)) return false;
    const std::string s = trim(text(key));
    if (s == "true" || s == "1" || s == "yes" || s == "on") return true;
    if (s == "false" || s == "0" || s == "no" || s == "off") return false;
    bad(key, "true or false");
}

float OptionReader::number(const std::string& key, float fallback, float lo, float hi) const {
    if (!has(key)) return fallback;
    float v = 0;
    if (!parse_float(text(key), v) || v < lo || v > hi) {
        if (std::isinf(hi)) bad(key, "a finite number >= " + shortest(lo));
        bad(key, "a number in [" + shortest(lo) + ", " + shortest(hi) + "]");
    }
    return v;
}

std::pair<float, float> OptionReader::range(const std::string& key, float lo, float hi) const {
    if (!has(key)) return {lo, hi};
    const std::string& s = text(key);
    const size_t comma = s.find(',');
    float a = 0, b = 0;
    if (comma == std::string::npos || s.find(',', comma + 1) != std::string::npos || !parse_float(s.substr(0, comma), a) ||
        !parse_float(s.substr(comma + 1), b) || !(b > a))
        bad(key, "'lo,hi': two finite numbers with hi > lo");
    return {a, b};
}

std::vector<std::string> OptionReader::list(const std::string& key) const {
    std::vector<std::string> v;
    if (!has(key)) return v;
    const std::string& s = text(key);
    size_t start = 0;
    while (true) {
        const size_t comma = s.find(',', start);
        const std::string item = trim(s.substr(start, comma == std::string::npos ? std::string::npos : comma - start));
        if (item.empty()) bad(key, "a comma-separated list of names without empty entries");
        v.push_back(item);
        if (comma == std::string::npos) break;
        start = comma + 1;
    }
    return v;
}

} // namespace atlas::io
