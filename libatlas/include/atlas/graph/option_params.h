// atlas/graph/option_params.h - node parameters declared from, and read into, a
// library option schema (atlas/core/option_schema.h): a node never restates a
// default, range, unit or doc the library owns.
//
// Header-only.
#pragma once

#include "atlas/core/option_schema.h"
#include "atlas/graph/node.h"

#include <charconv>
#include <cmath>
#include <initializer_list>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <variant>

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

// ---------------------------------------------------------------------------
// Node parameters from text options (TextOption<T>): the type follows the kind
// (Number: float, float2, float3 by count; Integer: int, int2, int3; Choice: enum;
// Flag: bool; anything else, and options that also take words such as 'auto': a
// string the schema checks when the graph loads), with the schema's default,
// bounds, unit and doc. A parameter's value is read back by formatting it as the
// option's text and parsing it as every front end does (parse_text_option), so a
// node accepts exactly what the CLI flag of the same option accepts.

// The parameter type declare_text_options gives option `o`.
inline ParamType text_option_param_type(const TextOptionSpec& o) {
    const bool plain = o.words.empty();
    if (o.kind == OptionKind::Number && plain && o.count <= 3) return o.count == 1 ? ParamType::Float : o.count == 2 ? ParamType::Float2 : ParamType::Float3;
    if (o.kind == OptionKind::Integer && plain && o.count <= 3) return o.count == 1 ? ParamType::Int : o.count == 2 ? ParamType::Int2 : ParamType::Int3;
    if (o.kind == OptionKind::Choice) return ParamType::Enum;
    if (o.kind == OptionKind::Flag) return ParamType::Bool;
    return ParamType::String;
}

// A parameter value as option `o`'s text ("" for a value of the wrong type).
inline std::string text_option_text(const TextOptionSpec& o, const ParamValue& v) {
    auto number = [](double x) { // printf's "%.17g" in the C locale, whatever the host's locale is
        char buf[64];
        const auto r = std::to_chars(buf, buf + sizeof buf, x, std::chars_format::general, 17);
        return std::string(buf, r.ptr);
    };
    if (const auto* d = std::get_if<double>(&v)) return number(*d);
    if (const auto* i = std::get_if<int64_t>(&v)) return std::to_string(*i);
    if (const auto* b = std::get_if<bool>(&v)) return *b ? "true" : "false";
    if (const auto* s = std::get_if<std::string>(&v)) return *s;
    std::string t;
    for (double x : std::get<std::vector<double>>(v)) t += (t.empty() ? "" : std::string(1, o.separator)) + number(x);
    return t;
}

namespace detail {
// Option `o`'s value given as `text` as a parameter value of text_option_param_type(o).
inline ParamValue text_option_param_value(const TextOptionSpec& o, const std::string& text) {
    OptionValue v;
    if (!parse_text_option(o, text, v)) throw Error(std::string("option '") + o.name + "': default '" + text + "' is not " + o.expected());
    switch (text_option_param_type(o)) {
    case ParamType::Float: return v.number;
    case ParamType::Int: return int64_t(v.number);
    case ParamType::Float2:
    case ParamType::Float3:
    case ParamType::Int2:
    case ParamType::Int3: return v.numbers;
    case ParamType::Enum: return v.word;
    case ParamType::Bool: return v.flag;
    default: return text;
    }
}
} // namespace detail

// Declares one parameter per option of `schema` (in its order) named as the option,
// its default the option's default_text, or the text `node_defaults` gives for it
// (a node family's named preset of the library).
template <class T>
void declare_text_options(NodeDeclaration& d, std::span<const TextOption<T>> schema,
                          std::span<const std::pair<const char*, const char*>> node_defaults = {}) {
    for (const TextOption<T>& o : schema) {
        std::string def = o.default_text;
        for (const auto& [name, text] : node_defaults)
            if (std::string_view(name) == o.name) def = text;
        const ParamValue value = detail::text_option_param_value(o, def);
        ParamDecl* p = nullptr;
        switch (text_option_param_type(o)) {
        case ParamType::Float: p = &d.param_float(o.name, std::get<double>(value)); break;
        case ParamType::Int: p = &d.param_int(o.name, std::get<int64_t>(value)); break;
        case ParamType::Float2: {
            const auto& x = std::get<std::vector<double>>(value);
            p = &d.param_float2(o.name, Vec2d{{x[0], x[1]}});
            break;
        }
        case ParamType::Float3: {
            const auto& x = std::get<std::vector<double>>(value);
            p = &d.param_float3(o.name, Vec3d{{x[0], x[1], x[2]}});
            break;
        }
        case ParamType::Int2: {
            const auto& x = std::get<std::vector<double>>(value);
            p = &d.param_int2(o.name, Vec2i{{int(x[0]), int(x[1])}});
            break;
        }
        case ParamType::Int3: {
            const auto& x = std::get<std::vector<double>>(value);
            p = &d.param_int3(o.name, Vec3i{{int(x[0]), int(x[1]), int(x[2])}});
            break;
        }
        case ParamType::Enum: p = &d.param_enum(o.name, o.words, std::get<std::string>(value)); break;
        case ParamType::Bool: p = &d.param_bool(o.name, std::get<bool>(value)); break;
        default: {
            p = &d.param_string(o.name, def);
            const TextOptionSpec spec = o;
            p->check_value = [spec](const ParamValue& given) {
                const std::string text = text_option_text(spec, given);
                OptionValue v;
                return parse_text_option(spec, text, v) ? std::string() : "expected " + spec.expected() + ", got '" + text + "'";
            };
        }
        }
        p->with_unit(o.unit).describe(o.doc);
        const ParamType t = p->type;
        if (t != ParamType::String && t != ParamType::Enum && t != ParamType::Bool) {
            if (std::isfinite(o.min)) p->min = o.min;
            if (std::isfinite(o.max)) p->max = o.max;
        }
    }
}

// Reads the parameters declare_text_options declared into `out` through the schema's
// parser; throws atlas::Error "parameter 'x': expected ..., got '...'" when one is
// not what the option takes (the graph's load-time check makes that rare).
template <class T>
void read_text_options(const CookContext& ctx, std::span<const TextOption<T>> schema, T& out) {
    for (const TextOption<T>& o : schema) {
        const std::string text = text_option_text(o, ctx.params().get(o.name));
        if (!set_text_option(o, text, out)) throw Error(std::string("parameter '") + o.name + "': expected " + o.expected() + ", got '" + text + "'");
    }
}

} // namespace atlas
