#include "atlas/graph/param.h"

#include "atlas/core/hash.h"

#include <algorithm>
#include <charconv>
#include <cmath>

namespace atlas {

std::string_view param_type_name(ParamType t) {
    switch (t) {
    case ParamType::Float: return "float";
    case ParamType::Int: return "int";
    case ParamType::Bool: return "bool";
    case ParamType::String: return "string";
    case ParamType::Enum: return "enum";
    case ParamType::Path: return "path";
    case ParamType::Float2: return "float2";
    case ParamType::Float3: return "float3";
    case ParamType::Int2: return "int2";
    case ParamType::Int3: return "int3";
    }
    return "?";
}

int param_components(ParamType t) {
    switch (t) {
    case ParamType::Float2:
    case ParamType::Int2: return 2;
    case ParamType::Float3:
    case ParamType::Int3: return 3;
    default: return 1;
    }
}

namespace {
// Shortest spelling that reads back to the same double ("1000", "0.1", "1e+21").
std::string format_number(double d) {
    char buf[64];
    auto r = std::to_chars(buf, buf + sizeof buf, d);
    return std::string(buf, r.ptr);
}
} // namespace

std::string format_param_value(const ParamValue& v) {
    struct Visitor {
        std::string operator()(bool b) const { return b ? "true" : "false"; }
        std::string operator()(int64_t i) const { return std::to_string(i); }
        std::string operator()(double d) const { return format_number(d); }
        std::string operator()(const std::string& s) const { return "'" + s + "'"; }
        std::string operator()(const std::vector<double>& v) const {
            std::string s = "[";
            for (size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + format_number(v[i]);
            return s + "]";
        }
    };
    return std::visit(Visitor{}, v);
}

void hash_param_value(Hasher& h, const ParamValue& v) {
    h.add(uint64_t(v.index()));
    std::visit([&](const auto& x) {
        using T = std::decay_t<decltype(x)>;
        if constexpr (std::is_same_v<T, std::vector<double>>) {
            h.add(uint64_t(x.size()));
            for (double d : x) h.add(d);
        } else {
            h.add(x);
        }
    }, v);
}

std::string ParamDecl::check(const ParamValue& v) const {
    // A float parameter without bounds of its own still has one: 3.5e38 is
    // infinity as a float and 1e30 squared overflows, so a field would be
    // infinities. 1e9 is far past any length, rate or weight Atlas uses.
    constexpr double kFloatLimit = 1e9;
    const bool floating = type == ParamType::Float || type == ParamType::Float2 || type == ParamType::Float3;
    auto in_range = [&](double d) -> std::string {
        if (!std::isfinite(d)) return "must be a finite number";
        if (floating && std::abs(d) > kFloatLimit && !(min && max))
            return "value " + format_number(d) + " is beyond +-1e9, where float fields overflow to infinity";
        if (min && max && (d < *min || d > *max))
            return "value " + format_number(d) + " is out of range [" + format_number(*min) + ", " + format_number(*max) + "]";
        if (min && d < *min) return "value " + format_number(d) + " is below the minimum " + format_number(*min);
        if (max && d > *max) return "value " + format_number(d) + " is above the maximum " + format_number(*max);
        return "";
    };
    switch (type) {
    case ParamType::Float:
        if (!std::holds_alternative<double>(v)) return "expected a number";
        return in_range(std::get<double>(v));
    case ParamType::Int:
        if (!std::holds_alternative<int64_t>(v)) return "expected an integer";
        return in_range(double(std::get<int64_t>(v)));
    case ParamType::Bool:
        return std::holds_alternative<bool>(v) ? "" : "expected true or false";
    case ParamType::String:
    case ParamType::Path:
        if (type == ParamType::String && check_value && (std::holds_alternative<std::string>(v) || std::holds_alternative<std::vector<double>>(v)))
            return check_value(v);
        if (!std::holds_alternative<std::string>(v)) return "expected a string";
        return "";
    case ParamType::Enum: {
        if (!std::holds_alternative<std::string>(v)) return "expected one of the names listed for it";
        const auto& s = std::get<std::string>(v);
        if (std::find(choices.begin(), choices.end(), s) != choices.end()) return "";
        std::string list;
        for (const auto& c : choices) list += (list.empty() ? "" : ", ") + c;
        return "'" + s + "' is not one of: " + list;
    }
    case ParamType::Float2:
    case ParamType::Float3:
    case ParamType::Int2:
    case ParamType::Int3: {
        const int n = param_components(type);
        const bool integral = type == ParamType::Int2 || type == ParamType::Int3;
        std::string expect = "expected a list of " + std::to_string(n) + (integral ? " integers" : " numbers");
        if (!std::holds_alternative<std::vector<double>>(v)) return expect;
        const auto& xs = std::get<std::vector<double>>(v);
        if (int(xs.size()) != n) return expect + ", got " + std::to_string(xs.size());
        for (double d : xs) {
            if (integral && std::isfinite(d) && d != std::floor(d)) return expect + ", got " + format_number(d);
            // Int2/Int3 components become ints: past int's range the conversion is undefined behaviour.
            if (integral && std::isfinite(d) && (d < -2147483648.0 || d > 2147483647.0))
                return expect + " within +-2^31, got " + format_number(d);
            if (auto e = in_range(d); !e.empty()) return e;
        }
        return "";
    }
    }
    return "unknown parameter type";
}

ParamValue ParamDecl::at_proxy(const ParamValue& v, int factor) const {
    if (factor <= 1 || proxy == ProxyScale::None) return v;
    const double p = factor;
    auto one = [&](double x) {
        switch (proxy) {
        case ProxyScale::Cells: x = std::ceil(x / p); break;
        case ProxyScale::CellLength: x = x / p; break;
        case ProxyScale::CellSize: x = x * p; break;
        case ProxyScale::None: break;
        }
        if (min) x = std::max(x, *min);
        if (max) x = std::min(x, *max);
        return x;
    };
    if (const auto* d = std::get_if<double>(&v)) return one(*d);
    if (const auto* i = std::get_if<int64_t>(&v)) return int64_t(std::llround(one(double(*i))));
    if (const auto* xs = std::get_if<std::vector<double>>(&v)) {
        const bool integral = type == ParamType::Int2 || type == ParamType::Int3;
        std::vector<double> out;
        for (double x : *xs) out.push_back(integral ? std::round(one(x)) : one(x));
        return out;
    }
    return v;
}

} // namespace atlas
