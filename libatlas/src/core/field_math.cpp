#include "atlas/core/field_math.h"

#include "atlas/core/error.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>

namespace atlas {

namespace {

constexpr size_t kBlock = 1 << 14; // voxels per parallel task: fixed, so the split never depends on threads

// A new field of a's shape with `channels` channels (a's names when equal).
Value clone_shape(const Value& a, int channels, const MemoryBudget* budget, std::vector<std::string> names = {}) {
    if (auto f2 = std::get_if<Field2DPtr>(&a)) {
        if (names.empty() && channels == (*f2)->channels()) names = (*f2)->channel_names();
        return Field2DPtr(std::make_shared<Field2D>((*f2)->resolution(), channels, (*f2)->bounds(), names, budget));
    }
    if (auto f3 = std::get_if<Field3DPtr>(&a)) {
        if (names.empty() && channels == (*f3)->channels()) names = (*f3)->channel_names();
        return Field3DPtr(std::make_shared<Field3D>((*f3)->resolution(), channels, (*f3)->bounds(), names, budget));
    }
    throw Error("expected a 2D or 3D field");
}

const detail::FieldStorage& storage(const Value& v) {
    if (auto f2 = std::get_if<Field2DPtr>(&v)) return **f2;
    if (auto f3 = std::get_if<Field3DPtr>(&v)) return **f3;
    throw Error("expected a 2D or 3D field");
}

detail::FieldStorage& mutable_storage(Value& v) {
    // Only used on fields this file just created.
    if (auto f2 = std::get_if<Field2DPtr>(&v)) return const_cast<Field2D&>(**f2);
    return const_cast<Field3D&>(*std::get<Field3DPtr>(v));
}

bool same_grid(const Value& a, const Value& b) {
    if (a.index() != b.index()) return false;
    if (auto f2 = std::get_if<Field2DPtr>(&a)) return (*f2)->resolution() == std::get<Field2DPtr>(b)->resolution();
    return std::get<Field3DPtr>(a)->resolution() == std::get<Field3DPtr>(b)->resolution();
}

// Checks that `b` can combine with `a`; returns b's channel step (0 = broadcast).
int operand_step(const Value& a, const Value& b, const char* name) {
    if (b.index() == 0) return 0;
    if (!same_grid(a, b))
        throw Error(std::string("input '") + name + "' must have the same dimensionality and resolution as input 'a'");
    int ca = storage(a).channels(), cb = storage(b).channels();
    if (cb != ca && cb != 1)
        throw Error(std::string("input '") + name + "' has " + std::to_string(cb) + " channels; expected 1 or " + std::to_string(ca));
    return cb == ca ? 1 : 0;
}


// One operand of a per-voxel operation: a field channel, or a constant when
// the operand is not connected.
struct Operand {
    const float* values = nullptr;
    float constant = 0.0f;
    float at(size_t i) const { return values ? values[i] : constant; }
};

Operand operand(const Value& v, int step, int c, double constant) {
    if (v.index() == 0) return {nullptr, float(constant)};
    return {storage(v).channel(step ? c : 0).data(), 0.0f};
}

// out[i] = op(a[i], x[i], y[i]) over every channel, where x and y are fields
// (same grid as a, 1 or N channels) or constants.
template <typename Op>
Value apply_per_voxel(const Value& a, const Value& x, double xc, const char* x_name, const Value& y, double yc, const char* y_name,
                      const MemoryBudget* budget, Op op) {
    const int step_x = operand_step(a, x, x_name);
    const int step_y = operand_step(a, y, y_name);
    Value out = clone_shape(a, storage(a).channels(), budget);
    auto& o = mutable_storage(out);
    const auto& sa = storage(a);
    for (int c = 0; c < sa.channels(); ++c) {
        auto pa = sa.channel(c);
        auto po = o.channel(c);
        const Operand ox = operand(x, step_x, c, xc), oy = operand(y, step_y, c, yc);
        parallel_blocks(pa.size(), kBlock, [&](size_t i0, size_t i1) {
            for (size_t i = i0; i < i1; ++i) po[i] = op(pa[i], ox.at(i), oy.at(i));
        });
    }
    return out;
}

const Value kNoOperand; // an unconnected operand (empty value); immutable

template <typename Op>
Value apply_binary(const Value& a, const Value& b, double bc, const MemoryBudget* budget, Op op) {
    return apply_per_voxel(a, b, bc, "b", kNoOperand, 0.0, "t", budget, [op](float x, float y, float) { return op(x, y); });
}

template <typename Op>
Value apply_unary(const Value& a, const MemoryBudget* budget, Op op) {
    return apply_per_voxel(a, kNoOperand, 0.0, "b", kNoOperand, 0.0, "t", budget, [op](float x, float, float) { return op(x); });
}

} // namespace

Value field_binary(const Value& a, const Value& b, double bc, BinaryOp op, const MemoryBudget* budget) {
    switch (op) {
    case BinaryOp::Add: return apply_binary(a, b, bc, budget, [](float x, float y) { return x + y; });
    case BinaryOp::Sub: return apply_binary(a, b, bc, budget, [](float x, float y) { return x - y; });
    case BinaryOp::Mul: return apply_binary(a, b, bc, budget, [](float x, float y) { return x * y; });
    case BinaryOp::Div: return apply_binary(a, b, bc, budget, [](float x, float y) { return x / y; });
    case BinaryOp::Min: return apply_binary(a, b, bc, budget, [](float x, float y) { return std::fmin(x, y); });
    case BinaryOp::Max: return apply_binary(a, b, bc, budget, [](float x, float y) { return std::fmax(x, y); });
    case BinaryOp::Pow: return apply_binary(a, b, bc, budget, [](float x, float y) { return std::pow(x, y); });
    }
    throw Error("unknown operation");
}

Value field_lerp(const Value& a, const Value& b, const Value& t, double tc, const MemoryBudget* budget) {
    if (b.index() == 0) throw Error("lerp needs input 'b'");
    return apply_per_voxel(a, b, 0.0, "b", t, tc, "t", budget, [](float x, float y, float k) { return x + (y - x) * k; });
}

Value field_remap(const Value& a, double in_min, double in_max, double out_min, double out_max, bool clamp_output,
                  const MemoryBudget* budget) {
    const double span = in_max - in_min;
    const float scale = span == 0.0 ? 0.0f : float((out_max - out_min) / span);
    const float lo = float(std::min(out_min, out_max)), hi = float(std::max(out_min, out_max));
    const float i0f = float(in_min), o0 = float(out_min);
    return apply_unary(a, budget, [=](float x) {
        float y = o0 + (x - i0f) * scale;
        if (clamp_output) y = std::isnan(y) ? lo : std::clamp(y, lo, hi);
        return y;
    });
}

Value field_clamp(const Value& a, double lo, double hi, const MemoryBudget* budget) {
    if (!(lo <= hi)) throw Error("clamp: 'min' must not be greater than 'max'");
    const float l = float(lo), h = float(hi);
    return apply_unary(a, budget, [=](float x) { return std::isnan(x) ? l : std::clamp(x, l, h); });
}

Field3D resample_field(const Field3D& src, Vec3i res, Box3d bounds, WrapMode wrap, const MemoryBudget* budget) {
    Field3D out(res, src.channels(), bounds, src.channel_names(), budget);
    const Vec3d svs = src.voxel_size();
    parallel_for_index(res[2], [&](int z) {
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) {
                Vec3d p = out.voxel_center(x, y, z);
                double u = (p[0] - src.bounds().min[0]) / svs[0], v = (p[1] - src.bounds().min[1]) / svs[1],
                       w = (p[2] - src.bounds().min[2]) / svs[2];
                for (int c = 0; c < src.channels(); ++c) out.at(c, x, y, z) = src.sample_voxel(c, u, v, w, wrap);
            }
    });
    return out;
}

Field2D resample_field(const Field2D& src, Vec2i res, Box2d bounds, WrapMode wrap, const MemoryBudget* budget) {
    Field2D out(res, src.channels(), bounds, src.channel_names(), budget);
    const Vec2d svs = src.voxel_size();
    parallel_for_index(res[1], [&](int y) {
        for (int x = 0; x < res[0]; ++x) {
            Vec2d p = out.texel_center(x, y);
            double u = (p[0] - src.bounds().min[0]) / svs[0], v = (p[1] - src.bounds().min[1]) / svs[1];
            for (int c = 0; c < src.channels(); ++c) out.at(c, x, y) = src.sample_texel(c, u, v, wrap);
        }
    });
    return out;
}

ChannelStats channel_stats(std::span<const float> values) {
    ChannelStats s;
    double sum = 0;
    uint64_t n = 0;
    bool first = true;
    for (float v : values) {
        if (std::isnan(v)) { ++s.nan_count; continue; }
        if (std::isinf(v)) { ++s.inf_count; continue; }
        if (first) { s.min = s.max = v; first = false; }
        s.min = std::min(s.min, double(v));
        s.max = std::max(s.max, double(v));
        sum += v;
        ++n;
    }
    s.mean = n ? sum / double(n) : 0.0;
    return s;
}

} // namespace atlas
