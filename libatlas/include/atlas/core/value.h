// atlas/core/value.h - the values that flow along graph edges.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/geometry.h"

#include <string_view>
#include <variant>

namespace atlas {

// The type of a port. `Field` accepts either a Field2D or a Field3D (nodes
// such as math work on both and return the dimensionality they were given).
enum class PortType { Field2D, Field3D, Field, Mesh, Points };

std::string_view port_type_name(PortType t);
// True when a value of type `produced` may feed an input of type `accepted`.
bool port_accepts(PortType accepted, PortType produced);

using Value = std::variant<std::monostate, Field2DPtr, Field3DPtr, MeshPtr, PointsPtr>;

// The concrete type held by a (non-empty) value.
PortType value_type(const Value& v);
void hash_value(Hasher& h, const Value& v);
bool values_equal(const Value& a, const Value& b);
uint64_t value_bytes(const Value& v);
// The bytes the value allocated itself: a field's shared channels belong to their owners (memory budgets).
uint64_t value_storage_bytes(const Value& v);

} // namespace atlas
