// Point splatting into a density grid.
#include "atlas/volume/splat.h"

#include "atlas/core/error.h"
#include "atlas/core/memory.h"

#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>

namespace atlas::volume {

SplatKernel parse_splat_kernel(const std::string& n) {
    if (n == "metaball") return SplatKernel::Metaball;
    if (n == "sphere") return SplatKernel::Sphere;
    if (n == "linear") return SplatKernel::Linear;
    if (n == "gaussian") return SplatKernel::Gaussian;
    throw Error("unknown splat kernel '" + n + "' (expected metaball, sphere, linear or gaussian)");
}

SplatBlend parse_splat_blend(const std::string& n) {
    if (n == "add") return SplatBlend::Add;
    if (n == "max") return SplatBlend::Max;
    throw Error("unknown splat blend '" + n + "' (expected add or max)");
}

Field3D splat_points(const Points& pts, Vec3i res, Box3d bounds, const SplatOptions& o, const MemoryBudget* budget, const XYWindow* window) {
    if (!(o.default_radius > 0) || !std::isfinite(o.default_radius)) throw Error("splat: default_radius must be finite and > 0");
    if (!(o.radius_scale > 0) || !std::isfinite(o.radius_scale)) throw Error("splat: radius_scale must be finite and > 0");
    if (!std::isfinite(o.weight)) throw Error("splat: weight must be finite");
    const size_t n = pts.positions.size();
    const std::vector<float>* radii = nullptr;
    const std::vector<float>* weights = nullptr;
    if (auto it = pts.attributes.find(o.radius_attribute); it != pts.attributes.end()) radii = &it->second;
    if (auto it = pts.attributes.find(o.weight_attribute); it != pts.attributes.end()) weights = &it->second;
    if ((radii && radii->size() != n) || (weights && weights->size() != n))
        throw Error("splat: a point attribute's length differs from the number of points (" + std::to_string(n) + ")");
    // Positions are the whole grid's; a window keeps voxels [x0, x1) x [y0, y1) of it.
    const XYWindow win = window ? *window : XYWindow{0, 0, res[0], res[1]};
    if (win.x0 < 0 || win.y0 < 0 || win.x1 > res[0] || win.y1 > res[1] || win.x1 <= win.x0 || win.y1 <= win.y0)
        throw Error("splat: the window is not a part of the grid");
    const Vec3d h = GridFrame{res, bounds, {{0, 0, 0}}}.voxel_size();
    Field3D out({{win.x1 - win.x0, win.y1 - win.y0, res[2]}}, 1, window ? win.bounds(res, bounds) : bounds, {"density"}, budget);
    const double vmin = std::min({h[0], h[1], h[2]});
    struct Splat {
        Vec3d c;
        double r, w, support;
    };
    std::vector<Splat> splats;
    splats.reserve(n);
    for (size_t i = 0; i < n; ++i) {
        const Vec3f& p = pts.positions[i];
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]))
            throw Error("splat: point " + std::to_string(i) + " has a non-finite position");
        const double r = (radii ? double((*radii)[i]) : o.default_radius) * o.radius_scale;
        if (!(r > 0) || !std::isfinite(r)) throw Error("splat: point " + std::to_string(i) + " has radius " + std::to_string(r) + " (expected > 0)");
        const double w = (weights ? double((*weights)[i]) : 1.0) * o.weight;
        if (!std::isfinite(w)) throw Error("splat: point " + std::to_string(i) + " has a non-finite weight");
        splats.push_back({{{p[0], p[1], p[2]}}, r, w, o.kernel == SplatKernel::Sphere ? r + vmin : r});
    }
    auto kernel = [&](double r, double R) -> double {
        const double s = r / R;
        switch (o.kernel) {
        case SplatKernel::Metaball: { const double q = 1 - s * s; return s < 1 ? q * q * q : 0; }
        case SplatKernel::Sphere: return std::clamp(0.5 - (r - R) / vmin, 0.0, 1.0);
        case SplatKernel::Linear: return s < 1 ? 1 - s : 0;
        case SplatKernel::Gaussian: return s < 1 ? std::exp(-4.5 * s * s) : 0;
        }
        return 0;
    };
    // Parallel over z slices; each voxel visits points in input order.
    parallel_for_index(res[2], [&](int z) {
        const double zc = bounds.min[2] + (z + 0.5) * h[2];
        for (const Splat& s : splats) {
            const double dz = zc - s.c[2];
            if (std::abs(dz) >= s.support) continue;
            int lo[2], hi[2];
            const int wlo[2] = {win.x0, win.y0}, whi[2] = {win.x1, win.y1};
            for (int a = 0; a < 2; ++a) {
                // Clamped as doubles: a radius of 1e30 would overflow the int conversion (UB).
                lo[a] = int(std::clamp(std::floor((s.c[a] - s.support - bounds.min[a]) / h[a] - 0.5), double(wlo[a]), double(whi[a])));
                hi[a] = int(std::clamp(std::ceil((s.c[a] + s.support - bounds.min[a]) / h[a] - 0.5), double(wlo[a] - 1), double(whi[a] - 1)));
            }
            for (int y = lo[1]; y <= hi[1]; ++y) {
                const double dy = bounds.min[1] + (y + 0.5) * h[1] - s.c[1];
                for (int x = lo[0]; x <= hi[0]; ++x) {
                    const double dx = bounds.min[0] + (x + 0.5) * h[0] - s.c[0];
                    const double r = std::sqrt(dx * dx + dy * dy + dz * dz);
                    if (r >= s.support) continue;
                    const float v = float(s.w * kernel(r, s.r));
                    float& d = out.at(0, x - win.x0, y - win.y0, z);
                    d = o.blend == SplatBlend::Add ? d + v : std::max(d, v);
                }
            }
        }
    });
    return out;
}

} // namespace atlas::volume
