#include "atlas/volume/cumulus.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <string>
#include <vector>

namespace atlas::volume {

namespace {
struct Ball {
    double c[3];
    double r;
};

double smoothstep(double a, double b, double x) {
    if (b <= a) return x >= b ? 1.0 : 0.0;
    const double t = std::clamp((x - a) / (b - a), 0.0, 1.0);
    return t * t * (3 - 2 * t);
}

// A unit direction from hash bits, pulled toward +z by `up_bias`.
void direction(uint32_t seed, int32_t a, int32_t b, double up_bias, double d[3]) {
    const double u = hash_to_unit(hash_coords(seed, a, b, 0));
    const double v = hash_to_unit(hash_coords(seed, a, b, 1));
    double z = 2 * u - 1;
    z += (std::fabs(z) - z) * up_bias; // mirror the lower half up, partly
    const double s = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * 3.14159265358979323846 * v;
    d[0] = s * std::cos(phi), d[1] = s * std::sin(phi), d[2] = z;
}

bool inside_other(const std::vector<Ball>& balls, size_t skip, const double p[3], double shrink) {
    for (size_t k = 0; k < balls.size(); ++k) {
        if (k == skip) continue;
        const Ball& o = balls[k];
        const double dx = p[0] - o.c[0], dy = p[1] - o.c[1], dz = p[2] - o.c[2];
        const double r = o.r * shrink;
        if (dx * dx + dy * dy + dz * dz < r * r) return true;
    }
    return false;
}

void check(const BillowSpec& s) {
    auto finite = [](double v) { return std::isfinite(v); };
    if (s.levels < 0 || s.levels > 6) throw Error("billow_spheres: 'levels' must be in [0, 6]");
    if (s.children < 0 || s.children > 64) throw Error("billow_spheres: 'children' must be in [0, 64]");
    if (!(s.ratio > 0 && s.ratio < 1)) throw Error("billow_spheres: 'ratio' must be in (0, 1)");
    if (!(s.jitter >= 0 && s.jitter <= 1)) throw Error("billow_spheres: 'jitter' must be in [0, 1]");
    if (!(s.up_bias >= 0 && s.up_bias <= 1)) throw Error("billow_spheres: 'up_bias' must be in [0, 1]");
    if (!(s.min_up >= -1 && s.min_up <= 1)) throw Error("billow_spheres: 'min_up' must be in [-1, 1]");
    if (!(s.sink >= 0 && s.sink <= 1.5)) throw Error("billow_spheres: 'sink' must be in [0, 1.5]");
    if (!(s.min_radius > 0) || !finite(s.min_radius)) throw Error("billow_spheres: 'min_radius' must be finite and > 0");
    if (!finite(s.base_height)) throw Error("billow_spheres: 'base_height' must be finite");
    if (s.towers < 0 || s.towers > 64) throw Error("billow_spheres: 'towers' must be in [0, 64]");
    if (!(s.tower_height >= 0) || !finite(s.tower_height)) throw Error("billow_spheres: 'tower_height' must be finite and >= 0");
    if (!(s.tower_taper > 0.3 && s.tower_taper <= 1)) throw Error("billow_spheres: 'tower_taper' must be in (0.3, 1]");
    if (!(s.tower_lean >= 0 && s.tower_lean <= 1)) throw Error("billow_spheres: 'tower_lean' must be in [0, 1]");
}
} // namespace

Points billow_spheres(const Points& shape, const BillowSpec& spec) {
    check(spec);
    const auto rit = shape.attributes.find("radius");
    if (rit == shape.attributes.end() || rit->second.size() != shape.positions.size())
        throw Error("billow_spheres: the shape's points need a 'radius' attribute, one value per point");
    std::vector<Ball> balls;
    for (size_t i = 0; i < shape.positions.size(); ++i) {
        const Vec3f& p = shape.positions[i];
        const double r = rit->second[i];
        if (!std::isfinite(p[0]) || !std::isfinite(p[1]) || !std::isfinite(p[2]) || !(r > 0) || !std::isfinite(r))
            throw Error("billow_spheres: shape point " + std::to_string(i) + " has a non-finite position or a radius <= 0");
        balls.push_back({{p[0], p[1], p[2]}, r});
    }
    // Towers: stacks of tapering spheres on the highest spheres (by top).
    if (spec.towers > 0 && !balls.empty()) {
        std::vector<size_t> order(balls.size());
        std::iota(order.begin(), order.end(), size_t(0));
        std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return balls[a].c[2] + balls[a].r > balls[b].c[2] + balls[b].r; });
        const size_t shape_count = balls.size();
        for (int t = 0; t < spec.towers; ++t) {
            const Ball root = balls[order[size_t(t) % shape_count]];
            const double top = root.c[2] + root.r + spec.tower_height;
            Ball b = root;
            for (int step = 0; step < 64; ++step) {
                const double r = b.r * spec.tower_taper;
                double lean[3];
                direction(spec.seed ^ 0x70e3u, t, step, 0, lean);
                // Overlapping by about half: a column of lobes, not a string of beads.
                b = {{b.c[0] + lean[0] * spec.tower_lean * r, b.c[1] + lean[1] * spec.tower_lean * r, b.c[2] + 0.5 * (b.r + r)}, r};
                if (b.c[2] + b.r > top || b.r < spec.min_radius) break;
                balls.push_back(b);
            }
        }
    }
    // Billows: each generation on the exposed surface of everything before it.
    size_t gen_begin = 0, gen_end = balls.size();
    for (int level = 1; level <= spec.levels; ++level) {
        for (size_t i = gen_begin; i < gen_end; ++i) {
            const Ball parent = balls[i];
            for (int k = 0; k < spec.children; ++k) {
                double d[3];
                direction(spec.seed + uint32_t(level) * 0x9E37u, int32_t(i), k, spec.up_bias, d);
                if (d[2] < spec.min_up) continue;
                const double jit = 1 + spec.jitter * (2 * hash_to_unit(hash_coords(spec.seed, int32_t(i), k, level, 7)) - 1);
                const double r = parent.r * spec.ratio * jit;
                if (r < spec.min_radius) continue;
                const Ball child{{parent.c[0] + d[0] * parent.r * spec.sink, parent.c[1] + d[1] * parent.r * spec.sink,
                                  parent.c[2] + d[2] * parent.r * spec.sink},
                                 r};
                if (child.c[2] - 0.5 * r < spec.base_height) continue;
                // Its outer tip must be exposed: not inside any other sphere.
                const double tip[3] = {child.c[0] + d[0] * r, child.c[1] + d[1] * r, child.c[2] + d[2] * r};
                if (inside_other(balls, i, tip, 0.98)) continue;
                balls.push_back(child);
            }
        }
        gen_begin = gen_end;
        gen_end = balls.size();
    }
    Points out;
    out.positions.reserve(balls.size());
    std::vector<float> radius;
    radius.reserve(balls.size());
    for (const Ball& b : balls) {
        out.positions.push_back({{float(b.c[0]), float(b.c[1]), float(b.c[2])}});
        radius.push_back(float(b.r));
    }
    out.attributes["radius"] = std::move(radius);
    return out;
}

Points spheres_from_sdf(const Field3D& sdf, const SphereFillSpec& s) {
    if (!(s.min_radius > 0) || !std::isfinite(s.min_radius)) throw Error("spheres_from_sdf: 'min_radius' must be finite and > 0");
    if (!(s.max_radius >= s.min_radius)) throw Error("spheres_from_sdf: 'max_radius' must be at least 'min_radius'");
    if (!(s.cover > 0 && s.cover <= 1)) throw Error("spheres_from_sdf: 'cover' must be in (0, 1]");
    if (s.max_spheres < 1) throw Error("spheres_from_sdf: 'max_spheres' must be >= 1");
    if (sdf.channels() < 1) throw Error("spheres_from_sdf: the SDF has no channel");
    const Vec3i r = sdf.resolution();
    const Vec3d h = sdf.voxel_size();
    auto d = sdf.channel(0);
    std::vector<size_t> order;
    for (size_t i = 0; i < d.size(); ++i)
        if (std::isfinite(d[i]) && -double(d[i]) >= s.min_radius) order.push_back(i);
    // Deepest first; ties by index, so the result never depends on the sort's stability.
    std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return d[a] != d[b] ? d[a] < d[b] : a < b; });
    std::vector<uint8_t> claimed(d.size(), 0);
    Points out;
    std::vector<float> radius;
    const size_t sx = 1, sy = size_t(r[0]), sz = size_t(r[0]) * size_t(r[1]);
    for (size_t i : order) {
        if (claimed[i]) continue;
        const int x = int(i % sy), y = int((i / sy) % size_t(r[1])), z = int(i / sz);
        const double rad = std::min(-double(d[i]), s.max_radius);
        const Vec3d c = sdf.voxel_center(x, y, z);
        out.positions.push_back({{float(c[0]), float(c[1]), float(c[2])}});
        radius.push_back(float(rad));
        if (int(out.positions.size()) >= s.max_spheres) break;
        const double claim = s.cover * rad;
        int lo[3], hi[3];
        const int at[3] = {x, y, z};
        for (int a = 0; a < 3; ++a) {
            const int k = int(std::ceil(claim / h[a]));
            lo[a] = std::max(0, at[a] - k);
            hi[a] = std::min(r[a] - 1, at[a] + k);
        }
        for (int zz = lo[2]; zz <= hi[2]; ++zz)
            for (int yy = lo[1]; yy <= hi[1]; ++yy)
                for (int xx = lo[0]; xx <= hi[0]; ++xx) {
                    const double dx = (xx - x) * h[0], dy = (yy - y) * h[1], dz = (zz - z) * h[2];
                    if (dx * dx + dy * dy + dz * dz <= claim * claim) claimed[size_t(zz) * sz + size_t(yy) * sy + size_t(xx) * sx] = 1;
                }
    }
    out.attributes["radius"] = std::move(radius);
    return out;
}

CumulusChannels cumulus_channels(const Field3D& sdf, const CumulusPaintSpec& s, const MemoryBudget* budget, const GridFrame* frame) {
    for (double v : {s.base_height, s.billow_depth, s.facing_low, s.facing_high, s.skirt, s.scale_floor, s.scale_ramp, s.outside_voxels})
        if (!std::isfinite(v)) throw Error("cumulus_channels: every setting must be finite");
    if (!(s.billow_depth > 0)) throw Error("cumulus_channels: 'billow_depth' must be > 0");
    if (!(s.facing_high > s.facing_low)) throw Error("cumulus_channels: 'facing_high' must be above 'facing_low'");
    if (s.skirt < 0 || s.scale_ramp < 0) throw Error("cumulus_channels: 'skirt' and 'scale_ramp' must be >= 0");
    if (s.scale_floor < 0 || s.scale_floor > 1) throw Error("cumulus_channels: 'scale_floor' must be in [0, 1]");
    if (s.outside_voxels < 0) throw Error("cumulus_channels: 'outside_voxels' must be >= 0");
    if (sdf.channels() < 1) throw Error("cumulus_channels: the SDF has no channel");
    const Vec3i r = sdf.resolution();
    CumulusChannels out{Field3D(r, 1, sdf.bounds(), {"detail_type"}, budget), Field3D(r, 1, sdf.bounds(), {"density_scale"}, budget)};
    // Differences one-sided at the grid's own faces; a tiled cook's crop (grown by a voxel) has the rest as neighbours.
    const GridFrame fr = frame ? *frame : sdf.frame();
    const Vec3d h = fr.voxel_size();
    const double reach = s.outside_voxels * std::max({h[0], h[1], h[2]});
    parallel_for_index(r[2], [&](int z) {
        for (int y = 0; y < r[1]; ++y)
            for (int x = 0; x < r[0]; ++x) {
                const double d = sdf.at(0, x, y, z);
                if (d > reach) {
                    out.detail_type.at(0, x, y, z) = 0.0f;
                    out.density_scale.at(0, x, y, z) = 0.0f;
                    continue;
                }
                // Outward normal: the SDF's gradient (central differences, one-sided at the grid's faces).
                auto diff = [&](int a) {
                    int lo[3] = {x, y, z}, hi[3] = {x, y, z};
                    lo[a] = std::max(0, lo[a] - 1);
                    hi[a] = std::min(r[a] - 1, hi[a] + 1);
                    if (hi[a] == lo[a]) return 0.0;
                    return (double(sdf.at(0, hi[0], hi[1], hi[2])) - sdf.at(0, lo[0], lo[1], lo[2])) / ((hi[a] - lo[a]) * h[a]);
                };
                const double g[3] = {diff(0), diff(1), diff(2)};
                const double len = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
                const double up = len > 1e-9 ? g[2] / len : 0.0;
                const double zc = fr.voxel_center(x, y, z)[2];
                const double height = zc - s.base_height;
                double type = smoothstep(s.facing_low, s.facing_high, up) * std::clamp(1.0 - std::max(0.0, -d) / s.billow_depth, 0.0, 1.0);
                type *= smoothstep(s.skirt * 0.5, s.skirt, height);
                out.detail_type.at(0, x, y, z) = float(std::clamp(type, 0.0, 1.0));
                const double ramp = s.scale_ramp > 0 ? smoothstep(0, s.scale_ramp, height) : (height >= 0 ? 1.0 : 0.0);
                out.density_scale.at(0, x, y, z) = float(s.scale_floor + (1 - s.scale_floor) * ramp);
            }
    });
    return out;
}

} // namespace atlas::volume
