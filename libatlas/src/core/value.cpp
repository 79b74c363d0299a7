#include "atlas/core/value.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"

namespace atlas {

std::string_view port_type_name(PortType t) {
    switch (t) {
    case PortType::Field2D: return "field2d";
    case PortType::Field3D: return "field3d";
    case PortType::Field: return "field";
    case PortType::Mesh: return "mesh";
    case PortType::Points: return "points";
    }
    return "?";
}

bool port_accepts(PortType accepted, PortType produced) {
    if (accepted == produced) return true;
    if (accepted == PortType::Field) return produced == PortType::Field2D || produced == PortType::Field3D;
    return false;
}

PortType value_type(const Value& v) {
    switch (v.index()) {
    case 1: return PortType::Field2D;
    case 2: return PortType::Field3D;
    case 3: return PortType::Mesh;
    case 4: return PortType::Points;
    default: throw Error("internal: empty value has no type");
    }
}

void hash_value(Hasher& h, const Value& v) {
    h.add(uint64_t(v.index()));
    std::visit([&](const auto& p) {
        if constexpr (!std::is_same_v<std::decay_t<decltype(p)>, std::monostate>) p->hash_into(h);
    }, v);
}

bool values_equal(const Value& a, const Value& b) {
    if (a.index() != b.index()) return false;
    return std::visit([&](const auto& pa) -> bool {
        using P = std::decay_t<decltype(pa)>;
        if constexpr (std::is_same_v<P, std::monostate>) return true;
        else return *pa == *std::get<P>(b);
    }, a);
}

uint64_t value_bytes(const Value& v) {
    return std::visit([](const auto& p) -> uint64_t {
        if constexpr (std::is_same_v<std::decay_t<decltype(p)>, std::monostate>) return 0;
        else return p->byte_size();
    }, v);
}

uint64_t value_storage_bytes(const Value& v) {
    return std::visit([](const auto& p) -> uint64_t {
        using P = std::decay_t<decltype(p)>;
        if constexpr (std::is_same_v<P, std::monostate>) return 0;
        else if constexpr (std::is_same_v<P, Field2DPtr> || std::is_same_v<P, Field3DPtr>) return p->owned_byte_size();
        else return p->byte_size();
    }, v);
}

} // namespace atlas
