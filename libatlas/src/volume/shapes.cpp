// Analytic signed distance shapes.
#include "atlas/volume/shapes.h"

#include "atlas/core/error.h"
#include "atlas/core/memory.h"

#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>

namespace atlas::volume {

ShapeKind parse_shape_kind(const std::string& n) {
    if (n == "sphere") return ShapeKind::Sphere;
    if (n == "box") return ShapeKind::Box;
    if (n == "capsule") return ShapeKind::Capsule;
    throw Error("unknown shape '" + n + "' (expected sphere, box or capsule)");
}

void validate_shape(const Shape& s) {
    auto finite = [](const Vec3d& v) { return std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]); };
    if (!finite(s.a)) throw Error("shape: centre / first end must be finite");
    if (!finite(s.b)) throw Error("shape: second end must be finite");
    if (!finite(s.half_size) || s.half_size[0] < 0 || s.half_size[1] < 0 || s.half_size[2] < 0)
        throw Error("shape: box half size must be finite and >= 0");
    if (!std::isfinite(s.radius) || s.radius < 0) throw Error("shape: radius must be finite and >= 0");
}

double shape_distance(const Shape& s, Vec3d p) {
    switch (s.kind) {
    case ShapeKind::Sphere: return length(p - s.a) - s.radius;
    case ShapeKind::Box: {
        // Rounded box: the box shrunk by radius, then offset by radius.
        Vec3d q, outside;
        for (int i = 0; i < 3; ++i) {
            const double hs = std::max(0.0, s.half_size[i] - s.radius);
            q[i] = std::abs(p[i] - s.a[i]) - hs;
            outside[i] = std::max(q[i], 0.0);
        }
        return length(outside) + std::min(std::max({q[0], q[1], q[2]}), 0.0) - std::min(s.radius, std::min({s.half_size[0], s.half_size[1], s.half_size[2]}));
    }
    case ShapeKind::Capsule: {
        const Vec3d ab = s.b - s.a, ap = p - s.a;
        const double len2 = dot(ab, ab);
        const double t = len2 > 0 ? std::clamp(dot(ap, ab) / len2, 0.0, 1.0) : 0.0;
        return length(ap - ab * t) - s.radius;
    }
    }
    return 0;
}

Field3D shape_sdf(const Shape& s, Vec3i res, Box3d bounds, const MemoryBudget* budget) {
    validate_shape(s);
    Field3D out(res, 1, bounds, {"sdf"}, budget);
    parallel_for_index(res[2], [&](int z) {
        for (int y = 0; y < res[1]; ++y)
            for (int x = 0; x < res[0]; ++x) out.at(0, x, y, z) = float(shape_distance(s, out.voxel_center(x, y, z)));
    });
    return out;
}

} // namespace atlas::volume
