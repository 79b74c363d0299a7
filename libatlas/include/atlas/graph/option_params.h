// atlas/graph/option_params.h - node parameters declared from, and read into, a
// library option schema (atlas/core/option_schema.h): a node never restates a
// default, range, unit or doc the library owns.
#pragma once

#include "atlas/core/option_schema.h"
#include "atlas/graph/node.h"

#include <cmath>
#include <initializer_list>
#include <span>
#include <string_view>

namespace atlas {

namespace detail {
inline bool option_selected(std::initializer_list<std::string_view> only, std::string_view name) {
    if (only.size() == 0) return true;
    for (std::string_view n : only)
        if (n == name) return true;
    return false;
}
} // namespace detail

// Declares one float parameter per option (all of them, or those named in `only`, in
// the schema's order): default from `defaults` (a node family whose defaults differ
// from the library's passes its own, named preset), the schema's inclusive range,
// unit and doc.
template <class T>
void declare_options(NodeDeclaration& d, std::span<const NumberOption<T>> schema, const T& defaults,
                     std::initializer_list<std::string_view> only = {}) {
    for (const NumberOption<T>& o : schema) {
        if (!detail::option_selected(only, o.name)) continue;
        ParamDecl& p = d.param_float(o.name, defaults.*o.member).with_unit(o.unit).describe(o.doc);
        if (std::isfinite(o.min)) p.min = o.min;
        if (std::isfinite(o.max)) p.max = o.max;
    }
}

// The same with the library's defaults, T{}.
template <class T>
void declare_options(NodeDeclaration& d, std::span<const NumberOption<T>> schema, std::initializer_list<std::string_view> only = {}) {
    declare_options(d, schema, T{}, only);
}

// Reads the parameters declare_options declared (same `only`) into `out`.
template <class T>
void read_options(const CookContext& ctx, std::span<const NumberOption<T>> schema, T& out, std::initializer_list<std::string_view> only = {}) {
    for (const NumberOption<T>& o : schema)
        if (detail::option_selected(only, o.name)) out.*o.member = ctx.get_float(o.name);
}

} // namespace atlas
