#include "atlas/render/lights.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"

#include <algorithm>
#include <cmath>

namespace atlas::render {

void validate_light(const PointLight& l, const std::string& what) {
    auto bad = [&](const std::string& m) { throw Error("render: " + what + " " + m); };
    for (int a = 0; a < 3; ++a)
        if (!std::isfinite(l.position[a])) bad("position must be finite");
    for (int c = 0; c < 3; ++c)
        if (!(l.colour[c] >= 0) || !std::isfinite(l.colour[c])) bad("colour must be finite and >= 0");
    if (!(l.intensity >= 0) || !std::isfinite(l.intensity)) bad("intensity must be finite and >= 0");
    if (!(l.radius >= 0) || !std::isfinite(l.radius)) bad("radius must be finite and >= 0 metres (0 = unlimited)");
}

namespace {
// Uniform double in [0, 1) from 53 hash bits of two draws.
double unit53(uint32_t seed, int32_t flash, int32_t i, int32_t k) {
    const uint64_t hi = hash_coords(seed, flash, i, k, 0), lo = hash_coords(seed, flash, i, k, 1);
    return double(((hi << 32) | lo) >> 11) * (1.0 / 9007199254740992.0);
}
} // namespace

std::vector<PointLight> flash_lights(const LightField& f) {
    if (!f.probability) throw Error("render: light field probability is missing (expected a 3D field)");
    const Field3D& p = *f.probability;
    if (f.channel < 0 || f.channel >= p.channels())
        throw Error("render: light field channel " + std::to_string(f.channel) + " is out of range (the field has " +
                    std::to_string(p.channels()) + " channels)");
    if (f.count < 0 || f.count > 4096) throw Error("render: light field count must be 0..4096, got " + std::to_string(f.count));
    validate_light({p.bounds().min, f.colour, f.intensity, f.radius}, "light field");

    // Total weight (fixed order: x fastest), then the draws as cumulative
    // targets sorted so one pass over the voxels finds every one.
    auto values = p.channel(f.channel);
    auto weight = [](float v) { return std::isfinite(v) && v > 0 ? double(v) : 0.0; };
    double total = 0;
    for (float v : values) total += weight(v);
    std::vector<PointLight> lights;
    if (!(total > 0) || f.count == 0) return lights;
    struct Draw {
        double target;
        int index;
        size_t voxel;
    };
    std::vector<Draw> draws(size_t(f.count));
    for (int i = 0; i < f.count; ++i) draws[size_t(i)] = {unit53(f.seed, f.flash, i, 0) * total, i, 0};
    std::sort(draws.begin(), draws.end(), [](const Draw& a, const Draw& b) { return a.target < b.target || (a.target == b.target && a.index < b.index); });
    double acc = 0;
    size_t next = 0, last_nonzero = 0;
    for (size_t v = 0; v < values.size() && next < draws.size(); ++v) {
        const double w = weight(values[v]);
        if (w == 0) continue;
        last_nonzero = v;
        acc += w;
        while (next < draws.size() && draws[next].target < acc) draws[next++].voxel = v;
    }
    // Rounding can leave targets just above the final sum: the last voxel with weight.
    for (; next < draws.size(); ++next) draws[next].voxel = last_nonzero;
    std::sort(draws.begin(), draws.end(), [](const Draw& a, const Draw& b) { return a.index < b.index; });

    const Vec3i res = p.resolution();
    const Vec3d vox = p.voxel_size();
    lights.reserve(draws.size());
    for (const Draw& d : draws) {
        const size_t nx = size_t(res[0]), ny = size_t(res[1]);
        const size_t x = d.voxel % nx, y = (d.voxel / nx) % ny, z = d.voxel / (nx * ny);
        PointLight l;
        l.position = {{p.bounds().min[0] + (double(x) + unit53(f.seed, f.flash, d.index, 1)) * vox[0],
                       p.bounds().min[1] + (double(y) + unit53(f.seed, f.flash, d.index, 2)) * vox[1],
                       p.bounds().min[2] + (double(z) + unit53(f.seed, f.flash, d.index, 3)) * vox[2]}};
        l.colour = f.colour;
        l.intensity = f.intensity;
        l.radius = f.radius;
        lights.push_back(l);
    }
    return lights;
}

} // namespace atlas::render
