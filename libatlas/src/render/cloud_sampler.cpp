#include "cloud_sampler.h"
#include "render_common.h"

#include "atlas/core/error.h"

#include <algorithm>
#include <bit>

namespace atlas::render::detail {

namespace {

int channel_or(const Field3D& f, const char* name, int fallback) {
    int c = f.find_channel(name);
    return c >= 0 ? c : fallback;
}

} // namespace

CloudSampler::CloudSampler(const CloudScene& scene) {
    validate_scene(scene);
    const Field3D& m = *scene.modeling;
    const Field3D& s = *scene.sdf;
    int cp = channel_or(m, "dimensional_profile", 0);
    int ct = scene.uniform_detail_type ? -1 : channel_or(m, "detail_type", 1);
    int cs = scene.uniform_density_scale ? -1 : channel_or(m, "density_scale", 2);
    int cd = channel_or(s, "sdf", 0);
    grid_.ch = {m.channel(cp).data(), ct >= 0 ? m.channel(ct).data() : nullptr, cs >= 0 ? m.channel(cs).data() : nullptr,
                s.channel(cd).data()};
    grid_.nx = m.nx();
    grid_.ny = m.ny();
    grid_.nz = m.nz();
    bounds_ = m.bounds();
    voxel_ = m.voxel_size();
    for (int a = 0; a < 3; ++a) {
        grid_.min[a] = bounds_.min[a];
        grid_.inv_voxel[a] = 1.0 / voxel_[a];
    }
    // Uniform channels (the scene's, or one finite value in every voxel) are
    // not interpolated.
    if (scene.uniform_detail_type) grid_.value[1] = *scene.uniform_detail_type;
    if (scene.uniform_density_scale) grid_.value[2] = *scene.uniform_density_scale;
    sdf_shift_ = std::countr_zero(unsigned(scene.sdf_block)); // a power of two (validate_scene)
    sdf_nx_ = s.nx();
    sdf_ny_ = s.ny();
    for (size_t c = 0; c < 4; ++c) {
        const float* p = grid_.ch[c];
        if (!p) {
            grid_.uniform[c] = true;
            continue;
        }
        const size_t n = c == 3 ? s.voxel_count() : m.voxel_count();
        const float v0 = p[0];
        grid_.uniform[c] = std::isfinite(v0) && std::all_of(p, p + n, [v0](float v) { return v == v0; });
        grid_.value[c] = v0;
    }
    // Billowy branch only when some voxel asks for it.
    if (grid_.uniform[1]) {
        billowy_ = grid_.value[1] > 0.0f;
    } else {
        auto type = m.channel(ct);
        billowy_ = std::any_of(type.begin(), type.end(), [](float v) { return v > 0.0f; });
    }
    if (scene.noise) {
        const Field3D& n = *scene.noise;
        for (int c = 0; c < 4; ++c) noise_.ch[size_t(c)] = n.channel(std::min(c, n.channels() - 1)).data();
        noise_.nx = n.nx();
        noise_.ny = n.ny();
        noise_.nz = n.nz();
        noise_.scale[0] = n.nx() / scene.noise_tile;
        noise_.scale[1] = n.ny() / scene.noise_tile;
        noise_.scale[2] = n.nz() / scene.noise_tile;
    }
}

CloudSampler::Cell CloudSampler::cell(double x, double y, double z) const {
    Cell k;
    detail::axis_clamp((x - grid_.min[0]) * grid_.inv_voxel[0], grid_.nx, k.x0, k.x1, k.tx);
    detail::axis_clamp((y - grid_.min[1]) * grid_.inv_voxel[1], grid_.ny, k.y0, k.y1, k.ty);
    detail::axis_clamp((z - grid_.min[2]) * grid_.inv_voxel[2], grid_.nz, k.z0, k.z1, k.tz);
    const size_t sy = size_t(grid_.nx), sz = size_t(grid_.nx) * size_t(grid_.ny);
    k.i000 = size_t(k.z0) * sz + size_t(k.y0) * sy + size_t(k.x0);
    k.dx = size_t(k.x1 - k.x0);
    k.dy = size_t(k.y1 - k.y0) * sy;
    k.dz = size_t(k.z1 - k.z0) * sz;
    return k;
}

namespace {
// Trilinear blend of the eight values at i000 + {0, dx} + {0, dy} + {0, dz}.
inline float blend8(const float* p, size_t i000, size_t dx, size_t dy, size_t dz, float tx, float ty, float tz) {
    float a = p[i000] + (p[i000 + dx] - p[i000]) * tx;
    float b = p[i000 + dy] + (p[i000 + dy + dx] - p[i000 + dy]) * tx;
    float cc = p[i000 + dz] + (p[i000 + dz + dx] - p[i000 + dz]) * tx;
    float d = p[i000 + dz + dy] + (p[i000 + dz + dy + dx] - p[i000 + dz + dy]) * tx;
    float ab = a + (b - a) * ty;
    float cd = cc + (d - cc) * ty;
    return ab + (cd - ab) * tz;
}
} // namespace

float CloudSampler::channel(int c, const Cell& k) const {
    if (grid_.uniform[size_t(c)]) return grid_.value[size_t(c)];
    return blend8(grid_.ch[size_t(c)], k.i000, k.dx, k.dy, k.dz, k.tx, k.ty, k.tz);
}

float CloudSampler::sdf_of(const Cell& k) const {
    if (sdf_shift_ == 0 || grid_.uniform[3]) return channel(3, k);
    // The same cell over the block grid: its taps read their blocks' values, the same
    // eight values, blended in the same order, as the SDF broadcast to every voxel.
    const int b = sdf_shift_;
    const size_t sy = size_t(sdf_nx_), sz = sy * size_t(sdf_ny_);
    const size_t x0 = size_t(k.x0 >> b), y0 = size_t(k.y0 >> b), z0 = size_t(k.z0 >> b);
    return blend8(grid_.ch[3], z0 * sz + y0 * sy + x0, size_t(k.x1 >> b) - x0, (size_t(k.y1 >> b) - y0) * sy, (size_t(k.z1 >> b) - z0) * sz,
                  k.tx, k.ty, k.tz);
}

VoxelSample CloudSampler::voxel(double x, double y, double z) const {
    const Cell k = cell(x, y, z);
    const float sdf = sdf_of(k);
    if (!(sdf < 0)) return {0, 0, 0, sdf};
    return {channel(0, k), channel(1, k), channel(2, k), sdf};
}

float CloudSampler::sdf(double x, double y, double z) const { return sdf_of(cell(x, y, z)); }

std::array<float, 4> CloudSampler::noise(double x, double y, double z) const {
    int x0, x1, y0, y1, z0, z1;
    float tx, ty, tz;
    detail::axis_wrap(x * noise_.scale[0], noise_.nx, x0, x1, tx);
    detail::axis_wrap(y * noise_.scale[1], noise_.ny, y0, y1, ty);
    detail::axis_wrap(z * noise_.scale[2], noise_.nz, z0, z1, tz);
    const size_t sy = size_t(noise_.nx), sz = size_t(noise_.nx) * size_t(noise_.ny);
    const size_t r0 = size_t(z0) * sz + size_t(y0) * sy, r1 = size_t(z0) * sz + size_t(y1) * sy;
    const size_t r2 = size_t(z1) * sz + size_t(y0) * sy, r3 = size_t(z1) * sz + size_t(y1) * sy;
    std::array<float, 4> out{};
    for (int c = 0; c < 4; ++c) {
        const float* p = noise_.ch[size_t(c)];
        float a = p[r0 + size_t(x0)] + (p[r0 + size_t(x1)] - p[r0 + size_t(x0)]) * tx;
        float b = p[r1 + size_t(x0)] + (p[r1 + size_t(x1)] - p[r1 + size_t(x0)]) * tx;
        float cc = p[r2 + size_t(x0)] + (p[r2 + size_t(x1)] - p[r2 + size_t(x0)]) * tx;
        float d = p[r3 + size_t(x0)] + (p[r3 + size_t(x1)] - p[r3 + size_t(x0)]) * tx;
        float ab = a + (b - a) * ty;
        float cd = cc + (d - cc) * ty;
        out[size_t(c)] = ab + (cd - ab) * tz;
    }
    return out;
}

float CloudSampler::density(const VoxelSample& v, double x, double y, double z, double camera_distance) const {
    if (!(v.sdf < 0)) return 0.0f;
    const double dp = saturate(v.profile);
    const double type = saturate(v.type);
    double eroded = dp;
    if (has_noise()) {
        const auto n = noise(x, y, z);
        // Nubis³ up-rez: wispy low->high frequency over the profile ...
        double composite = n[0] + (n[1] - n[0]) * dp;
        if (billowy_ && type > 0) {
            // ... billowy high->low frequency toward the core, scaled down ...
            const double g = std::pow(dp, 0.25);
            const double billowy = 0.3 * (n[3] + (n[2] - n[3]) * g);
            composite += (billowy - composite) * type;
        }
        if (camera_distance < 198.0) {
            // ... twice-folded noise ("hhf") blended in near the camera.
            auto fold2 = [](double a) { return std::fabs(std::fabs(a * 2.0 - 1.0) * 2.0 - 1.0); };
            double hf = 1.0 - std::pow(fold2(n[1]), 4.0);
            if (billowy_ && type > 0) hf += (std::pow(fold2(n[3]), 2.0) - hf) * type;
            const double blend = 0.9 + 0.1 * saturate((camera_distance - 58.0) / 140.0);
            composite = saturate(hf + (composite - hf) * blend);
        }
        composite = saturate(composite);
        // Value erosion: remap the profile from [noise, 1] to [0, 1].
        eroded = composite >= 1.0 ? 0.0 : saturate((dp - composite) / (1.0 - composite));
    }
    const double scale = std::isfinite(v.scale) ? std::max(0.0f, v.scale) : 0.0;
    double d = eroded * scale;
    if (d <= 0) return 0.0f;
    // Sharpening power: stronger (lower exponent) where the scale is low.
    const double p4 = std::pow(saturate(scale), 4.0);
    d = std::pow(d, 0.3 + 0.3 * std::max(1e-6, p4));
    return static_cast<float>(d);
}

} // namespace atlas::render::detail
