// atlas/volume/shapes.h - analytic signed distance shapes (metres, negative inside).
// Exact Euclidean distances (sphere, box, capsule). Pure, thread-safe.
#pragma once

#include "atlas/core/field.h"

#include <string>

namespace atlas::volume {

enum class ShapeKind { Sphere, Box, Capsule };

// Parses "sphere", "box", "capsule"; throws atlas::Error otherwise.
ShapeKind parse_shape_kind(const std::string& name);

struct Shape {
    ShapeKind kind = ShapeKind::Sphere;
    Vec3d a{};          // sphere / box centre; capsule first end (metres)
    Vec3d b{};          // capsule second end (metres)
    Vec3d half_size{};  // box half extents (metres, >= 0)
    double radius = 1;  // sphere / capsule radius (metres, >= 0); box corner rounding
};

// Throws atlas::Error naming the parameter when a value is negative or not finite.
void validate_shape(const Shape& s);

// Exact signed distance from p to the shape.
double shape_distance(const Shape& s, Vec3d p);

// The shape's SDF sampled at the voxel centres; channel "sdf".
Field3D shape_sdf(const Shape& s, Vec3i res, Box3d bounds, const class MemoryBudget* budget = nullptr);

} // namespace atlas::volume
