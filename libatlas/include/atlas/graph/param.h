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

// How a parameter follows a proxy cook (CookOptions::proxy = P: every world-space
// grid 1/P of its cells per axis over the same bounds). None: unchanged (fixed
// tile sets, LUTs, quality knobs). Cells: a grid's cell counts, divided by P and
// rounded up, kept in the declared range. CellLength: a length counted in cells
// (a blur's sigma), divided by P (an integer rounded to nearest). CellSize: metres
// per cell (a solver's dx), multiplied by P.
enum class ProxyScale { None, Cells, CellLength, CellSize };

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
    ProxyScale proxy = ProxyScale::None;

    // Fluent setters for declarations.
    ParamDecl& range(double lo, double hi) { min = lo; max = hi; return *this; }
    ParamDecl& at_least(double lo) { min = lo; return *this; }
    ParamDecl& with_unit(std::string u) { unit = std::move(u); return *this; }
    ParamDecl& describe(std::string d) { doc = std::move(d); return *this; }
    ParamDecl& follows_proxy(ProxyScale s) { proxy = s; return *this; }

    // Checks type and range; returns an error message, or "" when valid.
    std::string check(const ParamValue& v) const;
    // The value a proxy cook of factor `proxy` uses (v itself when proxy is 1 or
    // the parameter does not follow proxies).
    ParamValue at_proxy(const ParamValue& v, int proxy) const;
};

} // namespace atlas
