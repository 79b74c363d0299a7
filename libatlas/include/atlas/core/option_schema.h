// atlas/core/option_schema.h - one description of a library options struct's numeric
// options (name, the member it fills, inclusive range, unit, doc), from which the
// library's validation, node declarations, CLI flags and docs are all built, so the
// front ends cannot drift apart (docs/architecture.md, "Option schemas").
//
// Defaults are not repeated here: they are the struct's default member initializers,
// read through `member` from a default-constructed T.
#pragma once

#include "atlas/core/error.h"

#include <cmath>
#include <limits>
#include <span>
#include <sstream>
#include <string>
#include <string_view>

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

} // namespace atlas
