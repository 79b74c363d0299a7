// atlas/core/option_schema.h - one description of a library options struct's numeric
// options (name, the member it fills, inclusive range, unit, doc), from which the
// library's validation, node declarations, CLI flags and docs are all built, so the
// front ends cannot drift apart (docs/architecture.md, "Option schemas").
//
// Defaults are not repeated here: they are the struct's default member initializers,
// read through `member` from a default-constructed T.
//
// Header-only.
#pragma once

#include "atlas/core/error.h"

#include <charconv>
#include <cmath>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

namespace atlas {

template <class T>
struct NumberOption {
    const char* name;
    double T::*member;
    double min = -std::numeric_limits<double>::infinity(); // inclusive
    double max = std::numeric_limits<double>::infinity();  // inclusive
    const char* unit = "";
    const char* doc = "";

    double default_value() const { return T{}.*member; }
    // "" when v is finite and in [min, max], else what was expected.
    std::string check(double v) const {
        if (std::isfinite(v) && v >= min && v <= max) return "";
        std::ostringstream os;
        os.precision(17);
        os << "'" << name << "' must be ";
        if (std::isfinite(min) && std::isfinite(max)) os << "in [" << min << ", " << max << "]";
        else if (std::isfinite(min)) os << ">= " << min;
        else if (std::isfinite(max)) os << "<= " << max;
        else os << "finite";
        os << " (got " << v << ")";
        return os.str();
    }
};

// Throws atlas::Error "<what>: '<name>' must be ..." for the first option of `value`
// outside its range or not finite.
template <class T>
void check_options(const T& value, std::span<const NumberOption<T>> schema, std::string_view what) {
    for (const NumberOption<T>& o : schema) {
        const std::string msg = o.check(value.*o.member);
        if (!msg.empty()) throw Error(std::string(what) + ": " + msg);
    }
}

// The option named `name`, or nullptr.
template <class T>
const NumberOption<T>* find_option(std::span<const NumberOption<T>> schema, std::string_view name) {
    for (const NumberOption<T>& o : schema)
        if (name == o.name) return &o;
    return nullptr;
}

// ---------------------------------------------------------------------------
// Options given as text (a graph output's `options` map, a CLI flag): one
// TextOption<T> per option says what text it takes and how it fills T, and every
// front end parses through parse_text_option, so they accept the same values.

enum class OptionKind {
    Number,  // a finite decimal number in [min, max] (a leading '+' and surrounding blanks allowed),
             // or one of `words`; with count > 1, `count` of them separated by `separator`
    Integer, // a whole decimal number in [min, max], or one of `words`; with count > 1, `count`
             // of them separated by `separator` (no words)
    Flag,    // true/1/yes/on or false/0/no/off; a CLI flag takes no value and means true
    Choice,  // one of `words`
    List,    // comma-separated non-empty items, each one of `words` (any name when `words` is empty)
    Range,   // "lo,hi": two finite numbers in [min, max] with hi > lo
    Text,    // free text that `check_text` accepts (e.g. a list of point lights)
};

// What parse_text_option made of an option's text.
struct OptionValue {
    double number = 0;              // Number; Integer when no word was given (the first of `numbers`)
    std::vector<double> numbers;    // Number, Integer: the `count` numbers (empty when a word was given)
    std::string text;               // Text: the text as given
    std::string word;               // Choice; Integer when one of its words was given
    std::vector<std::string> items; // List
    double lo = 0, hi = 0;          // Range
    bool flag = false;              // Flag
};

struct TextOptionSpec {
    const char* name;     // graph output option ("max_error")
    const char* cli_flag; // the `atlas` flag taking it ("--max-error"), or nullptr
    const char* metavar;  // the value's form in help ("E", "N|full", "LO,HI"); "" for a Flag
    OptionKind kind;
    std::string doc;      // one line, with the default
    double min = -std::numeric_limits<double>::infinity(); // Number, Integer, Range: inclusive
    double max = std::numeric_limits<double>::infinity();
    std::vector<std::string> words; // see OptionKind
    // Number, Integer: how many numbers the value has, and what separates them in text.
    int count = 1;
    char separator = ',';
    // The value when the option is not given, as text this option parses ("" when the
    // struct's own default applies and is described in `doc`); node parameters declared
    // from the schema take it as their default.
    std::string default_text;
    // Text: "" when the text is a valid value, else why not; `metavar` says its form.
    std::string (*check_text)(std::string_view text) = nullptr;
    // A CLI flag that may be given more than once; its values are joined with ';'.
    bool repeatable = false;
    const char* unit = "";

    // What a value must be ("an integer in [1, 16] or 'full'"), for messages and docs.
    std::string expected() const;
};

namespace detail {
inline std::string_view trim_blanks(std::string_view s) {
    const size_t a = s.find_first_not_of(" \t");
    if (a == std::string_view::npos) return {};
    return s.substr(a, s.find_last_not_of(" \t") - a + 1);
}
// The whole (trimmed, optionally '+'-signed) text as a finite double; locale-independent.
inline bool parse_finite(std::string_view text, double& out) {
    std::string_view s = trim_blanks(text);
    const bool plus = !s.empty() && s[0] == '+';
    if (plus) s.remove_prefix(1);
    if (s.empty() || (plus && s[0] == '-')) return false; // from_chars refuses a '+' itself
    const auto r = std::from_chars(s.data(), s.data() + s.size(), out);
    return r.ec == std::errc() && r.ptr == s.data() + s.size() && std::isfinite(out);
}
inline std::string number_text(double v) {
    if (v == std::floor(v) && std::fabs(v) < 1e15) return std::to_string(static_cast<long long>(v)); // integers whole: 4294967295
    std::ostringstream os;
    os.precision(9);
    os << v;
    return os.str();
}
inline std::string quoted_words(const std::vector<std::string>& words, const char* last_sep) {
    std::string s;
    for (size_t i = 0; i < words.size(); ++i)
        s += (i == 0 ? "" : i + 1 == words.size() ? last_sep : ", ") + ("'" + words[i] + "'");
    return s;
}
inline bool is_word(const std::vector<std::string>& words, std::string_view w) {
    for (const std::string& x : words)
        if (w == x) return true;
    return false;
}
} // namespace detail

inline std::string TextOptionSpec::expected() const {
    // A bound at the float limit (a member stored as float) reads "a 32-bit float".
    constexpr double kFloatMax = std::numeric_limits<float>::max();
    const bool lo = std::isfinite(min) && min > -kFloatMax, hi = std::isfinite(max) && max < kFloatMax;
    const bool as_float = min == -kFloatMax || max == kFloatMax;
    const std::string bounds = (lo && hi ? " in [" + detail::number_text(min) + ", " + detail::number_text(max) + "]"
                                : lo     ? " >= " + detail::number_text(min)
                                : hi     ? " <= " + detail::number_text(max)
                                         : "") +
                               (as_float ? " (a 32-bit float)" : "");
    switch (kind) {
    case OptionKind::Number:
    case OptionKind::Integer: {
        const bool integer = kind == OptionKind::Integer;
        const std::string n = count > 1 ? std::to_string(count) + (integer ? " integers" : " finite numbers") + bounds + " separated by '" +
                                              std::string(1, separator) + "'"
                                        : (integer ? "an integer" : "a finite number") + bounds;
        return n + (words.empty() ? "" : " or " + detail::quoted_words(words, " or "));
    }
    case OptionKind::Text: return std::string("text of the form ") + metavar;
    case OptionKind::Flag: return "true or false";
    case OptionKind::Choice: return detail::quoted_words(words, " or ");
    case OptionKind::List:
        return words.empty() ? "a comma-separated list of names without empty entries"
                             : "a comma-separated list of " + detail::quoted_words(words, ", ") + " without empty entries";
    case OptionKind::Range: return "'lo,hi': two finite numbers" + bounds + " with hi > lo";
    }
    return "";
}

// Parses `text` as option `o` takes it; false (out unspecified) when it does not.
inline bool parse_text_option(const TextOptionSpec& o, std::string_view text, OptionValue& out) {
    const std::string_view s = detail::trim_blanks(text);
    switch (o.kind) {
    case OptionKind::Number:
    case OptionKind::Integer: {
        out.numbers.clear();
        if (detail::is_word(o.words, s)) {
            out.word = std::string(s);
            return true;
        }
        out.word.clear();
        size_t start = 0;
        for (int i = 0; i < o.count; ++i) {
            const size_t sep = i + 1 < o.count ? s.find(o.separator, start) : s.size();
            if (sep == std::string_view::npos) return false;
            const std::string_view part = detail::trim_blanks(s.substr(start, sep - start));
            double v = 0;
            if (o.kind == OptionKind::Number) {
                if (!detail::parse_finite(part, v)) return false;
            } else {
                long long n = 0;
                const auto r = std::from_chars(part.data(), part.data() + part.size(), n);
                if (part.empty() || r.ec != std::errc() || r.ptr != part.data() + part.size()) return false;
                v = double(n);
            }
            if (v < o.min || v > o.max) return false;
            out.numbers.push_back(v);
            start = sep + 1;
        }
        out.number = out.numbers.front();
        return true;
    }
    case OptionKind::Text:
        out.text = std::string(text);
        return !o.check_text || o.check_text(text).empty();
    case OptionKind::Flag:
        out.flag = s == "true" || s == "1" || s == "yes" || s == "on";
        return out.flag || s == "false" || s == "0" || s == "no" || s == "off";
    case OptionKind::Choice:
        out.word = std::string(s);
        return detail::is_word(o.words, s);
    case OptionKind::List: {
        out.items.clear();
        size_t start = 0;
        while (true) {
            const size_t comma = text.find(',', start);
            const std::string_view item = detail::trim_blanks(text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
            if (item.empty() || (!o.words.empty() && !detail::is_word(o.words, item))) return false;
            out.items.emplace_back(item);
            if (comma == std::string_view::npos) return true;
            start = comma + 1;
        }
    }
    case OptionKind::Range: {
        const size_t comma = text.find(',');
        if (comma == std::string_view::npos || text.find(',', comma + 1) != std::string_view::npos) return false;
        return detail::parse_finite(text.substr(0, comma), out.lo) && detail::parse_finite(text.substr(comma + 1), out.hi) && out.hi > out.lo &&
               out.lo >= o.min && out.hi <= o.max;
    }
    }
    return false;
}

// `v` as the text option `o` parses back to the same value (numbers exactly, in their
// shortest round-trip form; locale-independent): a library struct's own value as text.
inline std::string option_value_text(const TextOptionSpec& o, const OptionValue& v) {
    auto number = [&](double x) {
        char buf[64];
        const auto r = o.kind == OptionKind::Integer ? std::to_chars(buf, buf + sizeof buf, static_cast<long long>(x))
                                                     : std::to_chars(buf, buf + sizeof buf, x);
        return std::string(buf, r.ptr);
    };
    auto joined = [](const std::vector<std::string>& parts, char sep) {
        std::string s;
        for (size_t i = 0; i < parts.size(); ++i) s += (i == 0 ? "" : std::string(1, sep)) + parts[i];
        return s;
    };
    switch (o.kind) {
    case OptionKind::Number:
    case OptionKind::Integer: {
        if (!v.word.empty()) return v.word;
        if (o.count == 1) return number(v.number);
        std::vector<std::string> parts;
        for (double x : v.numbers) parts.push_back(number(x));
        return joined(parts, o.separator);
    }
    case OptionKind::Flag: return v.flag ? "true" : "false";
    case OptionKind::Choice: return v.word;
    case OptionKind::List: return joined(v.items, ',');
    case OptionKind::Range: return number(v.lo) + "," + number(v.hi);
    case OptionKind::Text: return v.text;
    }
    return "";
}

template <class T>
struct TextOption : TextOptionSpec {
    void (*apply)(T& out, const OptionValue& value) = nullptr; // fills T from a parsed value
    // Optional, apply's inverse: this option's value in a T. A schema that has it takes its
    // defaults from T{} (default_text = option_value_text(value_of(T{}))) and the library
    // checks a T against the bounds the front ends parse with (e.g. sim::sim_options()).
    OptionValue (*value_of)(const T& from) = nullptr;
};

// Parses `text` as option `o` and applies it to `out`; false (out untouched) when
// the text is not what `o.expected()` says.
template <class T>
bool set_text_option(const TextOption<T>& o, std::string_view text, T& out) {
    OptionValue v;
    if (!parse_text_option(o, text, v)) return false;
    o.apply(out, v);
    return true;
}

// The option named `name` (graph option name), or nullptr.
template <class T>
const TextOption<T>* find_option(std::span<const TextOption<T>> schema, std::string_view name) {
    for (const TextOption<T>& o : schema)
        if (name == o.name) return &o;
    return nullptr;
}

} // namespace atlas
