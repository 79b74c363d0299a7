// atlas/ndf/operators.h - 2D NDF operators: domain warp, curve, blur, threshold, composite.
//
// Inputs are never modified; results are new fields with the input's
// resolution, bounds and channel names. Pure, thread-safe, deterministic for
// any thread count. Remap / clamp / lerp are in atlas/core/field_math.h.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <string>
#include <vector>

namespace atlas::ndf {

// out(p) = in(p + amount * (2 * warp(p) - 1)), bilinear. `warp` has the
// input's resolution and 1 or 2 channels (channel 0 offsets x, channel 1 - or
// channel 0 again - offsets y); amount in metres. Wrap mode Wrap keeps a
// tileable map tileable.
Field2D domain_warp(const Field2D& in, const Field2D& warp, double amount, WrapMode wrap, const MemoryBudget* budget);
// The same on a window of a larger grid (a tiled cook): `in` and `warp` hold
// texels [x0, x0 + width) x [y0, y0 + height) of a `grid` of texels over
// `bounds`. Positions and taps are the whole grid's (so the bytes equal the
// whole map's there); a tap is then read from the window, clamped into it,
// so only texels in a halo band wider than the offsets differ.
struct WarpWindow {
    Box2d bounds;
    Vec2i grid;
    int x0 = 0, y0 = 0;
};
Field2D domain_warp(const Field2D& in, const Field2D& warp, double amount, WrapMode wrap, const WarpWindow& window,
                    const MemoryBudget* budget);

// A monotone cubic (Fritsch-Carlson) spline through (x, y) control points
// with strictly increasing x; constant beyond the ends. No overshoot between
// monotone points.
class Curve {
public:
    // Throws atlas::Error when fewer than 2 points, x not strictly increasing or not finite.
    explicit Curve(std::vector<Vec2d> points);
    // Parses "x y; x y; ...".
    static Curve parse(const std::string& text);
    double operator()(double x) const;

private:
    std::vector<Vec2d> p_;
    std::vector<double> m_; // tangents
};
Field2D apply_curve(const Field2D& in, const Curve& curve, const MemoryBudget* budget);

// Separable Gaussian blur, sigma in texels (>= 0; 0 copies), kernel radius
// ceil(3 sigma); Wrap keeps tileable maps tileable.
Field2D blur(const Field2D& in, double sigma, WrapMode wrap, const MemoryBudget* budget);

// 0/1 step at `level`, or smoothstep(level - width/2, level + width/2) when width > 0.
Field2D threshold(const Field2D& in, double level, double width, const MemoryBudget* budget);

enum class CompositeOp { Add, Multiply, Max, Min, Over, Lerp };
// Parses "add", "multiply", "max", "min", "over", "lerp".
CompositeOp parse_composite_op(const std::string& name);

// result = a + (op(a, b) - a) * opacity * mask. Over is b + a * (1 - b)
// (b's value as its own coverage, premultiplied "b over a"); Lerp is b (so the
// mask picks between a and b). `b` has a's resolution and a's channel count or
// 1 channel; `mask` may be null (1 everywhere) or 1 channel. Throws on
// mismatched resolutions.
Field2D composite(const Field2D& a, const Field2D& b, const Field2D* mask, CompositeOp op, double opacity, const MemoryBudget* budget);

} // namespace atlas::ndf
