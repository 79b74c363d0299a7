// atlas/core/field_math.h - per-voxel arithmetic and resampling on fields.
//
// Every function takes Field2D or Field3D values (as atlas::Value) and
// returns a new field of the same dimensionality; inputs are never modified.
// Work is split into fixed blocks (TBB), so results are identical for any
// thread count. `budget` (may be null) is checked before allocating.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"
#include "atlas/core/value.h"

namespace atlas {

enum class BinaryOp { Add, Sub, Mul, Div, Min, Max, Pow };

// a (op) b. `b` may be empty (the scalar `b_constant` is used), have the same
// resolution and channel count as `a`, or the same resolution and 1 channel
// (broadcast over a's channels). Div by zero gives +-Inf or NaN as IEEE says;
// Pow of a negative base to a non-integer exponent gives NaN - nodes check.
Value field_binary(const Value& a, const Value& b, double b_constant, BinaryOp op, const MemoryBudget* budget);

// Linear interpolation a + (b - a) * t, with t a field (1 or N channels) or
// the constant t_constant when `t` is empty.
Value field_lerp(const Value& a, const Value& b, const Value& t, double t_constant, const MemoryBudget* budget);

// Maps [in_min, in_max] linearly to [out_min, out_max] ("fit range"), then
// optionally clamps to the output range. in_min == in_max maps everything to
// out_min (no division by zero).
Value field_remap(const Value& a, double in_min, double in_max, double out_min, double out_max, bool clamp_output,
                  const MemoryBudget* budget);

// Clamps every value into [lo, hi]; NaN becomes lo.
Value field_clamp(const Value& a, double lo, double hi, const MemoryBudget* budget);

// Trilinear resampling onto a new resolution and bounds (defaults: the
// source's bounds). Points outside the source are clamped or wrapped.
Field3D resample_field(const Field3D& src, Vec3i resolution, Box3d bounds, WrapMode wrap, const MemoryBudget* budget);
Field2D resample_field(const Field2D& src, Vec2i resolution, Box2d bounds, WrapMode wrap, const MemoryBudget* budget);

// Statistics of one channel (NaN and Inf counted separately, excluded from min/max/mean).
struct ChannelStats {
    double min = 0, max = 0, mean = 0;
    uint64_t nan_count = 0, inf_count = 0;
};
ChannelStats channel_stats(std::span<const float> values);

} // namespace atlas
