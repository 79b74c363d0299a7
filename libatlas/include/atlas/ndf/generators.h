// atlas/ndf/generators.h - 2D NDF generators: gradients, painted shapes, tileable noise.
//
// Every function returns a new 1-channel Field2D over `bounds` (metres) at
// `res` texels (cell-centred). Pure, thread-safe, deterministic for any thread
// count (rows are independent). `budget` may be null. Bad parameters throw
// atlas::Error naming the parameter.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <cstdint>
#include <string>
#include <vector>

namespace atlas::ndf {

// Linear ramp: 0 at world point p0, 1 at p1, clamped to [0,1] beyond them
// (projection onto p0->p1). Throws when p0 == p1 or not finite.
Field2D gradient_linear(Vec2i res, Box2d bounds, Vec2d p0, Vec2d p1, const MemoryBudget* budget);

// Radial ramp: 1 at `center`, falling linearly to 0 at distance `radius`
// metres and beyond. Throws when radius <= 0 or not finite.
Field2D gradient_radial(Vec2i res, Box2d bounds, Vec2d center, double radius, const MemoryBudget* budget);

// A shape painted into a map. Distances in metres.
struct Shape {
    enum class Kind { Ellipse, Polygon, Stroke };
    Kind kind = Kind::Ellipse;
    std::vector<Vec2d> points; // Ellipse: {centre}; Polygon: >= 3 vertices; Stroke: >= 2 polyline points
    Vec2d radii{{1, 1}};       // Ellipse radii (> 0)
    double width = 1;          // Stroke width (> 0)
    double value = 1;          // value inside the shape
    double falloff = 0;        // smoothstep ramp width outside the edge, metres (>= 0)
};

// Parses "ellipse CX CY RX RY VALUE FALLOFF; polygon VALUE FALLOFF X Y X Y ...;
// stroke WIDTH VALUE FALLOFF X Y X Y ...". Throws atlas::ParseError-like
// atlas::Error naming the entry on malformed text.
std::vector<Shape> parse_shapes(const std::string& text);

// Paints the shapes over a zero background: each texel takes the max over
// shapes of value * weight, weight 1 inside, 1 - smoothstep(0, falloff, d) at
// distance d outside (0 beyond falloff; a hard edge when falloff = 0).
Field2D paint_shapes(Vec2i res, Box2d bounds, const std::vector<Shape>& shapes, const MemoryBudget* budget);

// Tileable FBM of value noise in [0, 1]: `period` lattice cells across the
// map per axis (>= 1), octave k has period * 2^k and amplitude gain^k. The map
// tiles exactly: texel (W-1) is followed by texel 0 without a seam.
Field2D noise2d(Vec2i res, Box2d bounds, Vec2i period, int octaves, double gain, uint32_t seed, const MemoryBudget* budget);

} // namespace atlas::ndf
