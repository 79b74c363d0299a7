// atlas/graph/param.h - node parameters: declared type, default, range, unit, doc.
#pragma once

#include "atlas/core/math.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace atlas {

class Hasher;

enum class ParamType {
    Float,  // double
    Int,    // int64
    Bool,
    String,
    Enum,   // one of a declared list of names
    Path,   // a file path, relative to the graph file's directory
    Float2, Float3,
    Int2, Int3,
};

std::string_view param_type_name(ParamType t);
// Number of components of a vector type (1 for scalars).
int param_components(ParamType t);

// A parameter value. Scalars use bool / int64_t / double / string; vector
// types use std::vector<double> (integer vectors hold integral values).
using ParamValue = std::variant<bool, int64_t, double, std::string, std::vector<double>>;

// "4", "0.5", "true", "'name'", "[1, 2, 3]" - as a graph file would spell it.
std::string format_param_value(const ParamValue& v);
void hash_param_value(Hasher& h, const ParamValue& v);

struct ParamDecl {
    std::string name;
    ParamType type = ParamType::Float;
    ParamValue default_value;
    std::optional<double> min, max; // inclusive; applies to every component
    std::string unit;               // "m", "1/m", "cells", "" for none
    std::string doc;                // one line
    std::vector<std::string> choices; // Enum only
    // String only: "" when the value is valid, else why not (a text option of a library
    // schema, atlas/graph/option_params.h). It gets the text, or a list of numbers a
    // host or graph gave for an option that takes numbers ([0.1, 0.2, 0.5]).
    std::function<std::string(const ParamValue&)> check_value;

    // Fluent setters for declarations.
    ParamDecl& range(double lo, double hi) { min = lo; max = hi; return *this; }
    ParamDecl& at_least(double lo) { min = lo; return *this; }
    ParamDecl& with_unit(std::string u) { unit = std::move(u); return *this; }
    ParamDecl& describe(std::string d) { doc = std::move(d); return *this; }

    // Checks type and range; returns an error message, or "" when valid.
    std::string check(const ParamValue& v) const;
};

} // namespace atlas
