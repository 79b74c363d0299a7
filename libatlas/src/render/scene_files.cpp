#include "atlas/render/scene.h"

#include "atlas/core/error.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace atlas::render {

namespace {

Field3DPtr rebound(Field3DPtr f, double voxel) {
    if (voxel <= 0) return f;
    Box3d b{{{0, 0, 0}}, {{f->nx() * voxel, f->ny() * voxel, f->nz() * voxel}}};
    Field3D re(f->resolution(), f->channels(), b, f->channel_names());
    for (int c = 0; c < f->channels(); ++c) std::copy(f->channel(c).begin(), f->channel(c).end(), re.channel(c).begin());
    return std::make_shared<Field3D>(std::move(re));
}


// 1D squared distance transform along one line (Felzenszwalb & Huttenlocher):
// f holds 0 at occupied samples and +inf elsewhere, spacing w metres; out[i] =
// min_j f[j] + (w (i - j))^2.
void edt_line(const double* f, int n, double w, double* out, int* v, double* z) {
    const double w2 = w * w;
    int k = 0;
    v[0] = -1;
    for (int q = 0; q < n; ++q) {
        if (!std::isfinite(f[q])) continue;
        if (v[0] < 0) {
            v[0] = q;
            z[0] = -std::numeric_limits<double>::infinity();
            z[1] = std::numeric_limits<double>::infinity();
            continue;
        }
        double sq;
        while (true) {
            const int r = v[k];
            sq = ((f[q] / w2 + double(q) * q) - (f[r] / w2 + double(r) * r)) / (2.0 * (q - r));
            if (sq <= z[k] && k > 0) --k;
            else break;
        }
        if (sq <= z[k]) { // k == 0 and the new parabola hides the old one everywhere
            v[0] = q;
            z[0] = -std::numeric_limits<double>::infinity();
        } else {
            ++k;
            v[k] = q;
            z[k] = sq;
        }
        z[k + 1] = std::numeric_limits<double>::infinity();
    }
    if (v[0] < 0) {
        std::fill(out, out + n, std::numeric_limits<double>::infinity());
        return;
    }
    k = 0;
    for (int q = 0; q < n; ++q) {
        while (z[k + 1] < q) ++k;
        const double d = w * (q - v[k]);
        out[q] = f[v[k]] + d * d;
    }
}

// A plain density grid (one channel, e.g. the float grid "density" that
// vdb_render draws) as a scene the sampler reads as the same density:
// density_scene's mapping (profile D^(1/0.6) / S, detail type 0, density
// scale S = max(1, max D^(1/0.6))), the last two uniform (no channels of
// their own), the profile written over the grid's own storage, and an SDF
// that lets the march skip empty space. The distance is an exact Euclidean
// transform over blocks of B^3 voxels (block centres, to the nearest block
// holding a non-zero voxel), less B voxel diagonals: a lower bound L on the
// distance from a voxel centre to the nearest non-zero voxel centre. The SDF
// is L - 4 max voxel, clamped to at most -min voxel: a point of a cell with a
// non-zero corner is inside at every corner (so wherever the density is
// non-zero the picture is density_scene's), and the interpolated SDF
// elsewhere stays under the distance to the nearest cell with a non-zero
// corner. Peak memory: the grid plus the SDF's blocks (1/8 of the grid; it
// was the grid plus a 4-channel set, 4.9 times the grid, then the SDF
// broadcast to every voxel).
CloudScene density_grid_scene(std::shared_ptr<Field3D> grid) {
    Field3D& density = *grid;
    const Vec3i r = density.resolution();
    const Vec3d vox = density.voxel_size();
    const double vmin = std::min({vox[0], vox[1], vox[2]}), vmax = std::max({vox[0], vox[1], vox[2]});
    auto p = density.channel(0);
    const size_t nx = size_t(r[0]), ny = size_t(r[1]), nz = size_t(r[2]), sxy = nx * ny;
    constexpr int B = 2;
    const Vec3i cr{{(r[0] + B - 1) / B, (r[1] + B - 1) / B, (r[2] + B - 1) / B}};
    // The SDF is one value per block: stored so (CloudScene::sdf_block), not broadcast.
    auto sdf = std::make_shared<Field3D>(cr, 1, density.bounds(), std::vector<std::string>{"sdf"});
    auto block = sdf->channel(0);
    const size_t cx = size_t(cr[0]), cy = size_t(cr[1]), cz = size_t(cr[2]), cxy = cx * cy;
    std::vector<double> cd(cx * cy * cz, std::numeric_limits<double>::infinity());
    // 1. Check, maximum, block occupancy (a coarse z row belongs to one task).
    std::vector<float> row_max(cz, 0.0f);
    parallel_for_index(int(cz), [&](int bzi) {
        const size_t bz = size_t(bzi);
        float m = 0;
        for (size_t z = bz * B; z < std::min(nz, (bz + 1) * B); ++z)
            for (size_t y = 0; y < ny; ++y)
                for (size_t x = 0; x < nx; ++x) {
                    const size_t i = z * sxy + y * nx + x;
                    const float v = p[i];
                    if (!(v >= 0) || !std::isfinite(v)) throw Error("render: a density grid needs finite densities >= 0");
                    if (v > 0) {
                        cd[bz * cxy + (y / B) * cx + x / B] = 0;
                        m = std::max(m, v);
                    } else if (std::signbit(v)) {
                        p[i] = 0.0f; // -0: the profile is +0 where the density is 0
                    }
                }
        row_max[bz] = m;
    });
    const float dmax = *std::max_element(row_max.begin(), row_max.end());
    const double S = std::max(1.0, std::pow(double(dmax), 1.0 / 0.6));
    // 2. The profile in place, in the occupied blocks only (elsewhere it is the grid's 0).
    parallel_for_index(int(cz), [&](int bzi) {
        const size_t bz = size_t(bzi);
        for (size_t by = 0; by < cy; ++by)
            for (size_t bx = 0; bx < cx; ++bx) {
                if (cd[bz * cxy + by * cx + bx] != 0) continue;
                for (size_t z = bz * B; z < std::min(nz, (bz + 1) * B); ++z)
                    for (size_t y = by * B; y < std::min(ny, (by + 1) * B); ++y)
                        for (size_t x = bx * B; x < std::min(nx, (bx + 1) * B); ++x) {
                            const size_t i = z * sxy + y * nx + x;
                            const float v = p[i];
                            if (v > 0) p[i] = static_cast<float>(std::pow(double(v), 1.0 / 0.6) / S);
                        }
            }
    });
    density.set_channel_names({"dimensional_profile"});
    // Separable squared EDT over the blocks, one axis at a time, lines in parallel.
    auto pass = [&](int axis) {
        const size_t n = size_t(cr[axis]);
        const size_t stride = axis == 0 ? 1 : (axis == 1 ? cx : cxy);
        const size_t lines = (cx * cy * cz) / n;
        parallel_blocks(lines, 64, [&](size_t l0, size_t l1) {
            std::vector<double> f(n), out(n), zz(n + 1);
            std::vector<int> v(n);
            for (size_t l = l0; l < l1; ++l) {
                size_t base;
                if (axis == 0) base = l * cx;
                else if (axis == 1) base = (l / cx) * cxy + (l % cx);
                else base = l;
                for (size_t i = 0; i < n; ++i) f[i] = cd[base + i * stride];
                edt_line(f.data(), int(n), B * vox[axis], out.data(), v.data(), zz.data());
                for (size_t i = 0; i < n; ++i) cd[base + i * stride] = out[i];
            }
        });
    };
    for (int a = 0; a < 3; ++a) pass(a);
    const float inside = -static_cast<float>(vmin);
    const double margin = B * std::sqrt(vox[0] * vox[0] + vox[1] * vox[1] + vox[2] * vox[2]) + 4.0 * vmax;
    // One value per block.
    parallel_for_index(int(cz), [&](int bzi) {
        const size_t bz = size_t(bzi);
        for (size_t i = bz * cxy; i < (bz + 1) * cxy; ++i) {
            const double dist = std::sqrt(cd[i]);
            block[i] = !std::isfinite(dist)    ? static_cast<float>(1e30)
                       : dist - margin < inside ? inside
                                                : static_cast<float>(dist - margin);
        }
    });
    std::vector<double>().swap(cd);
    CloudScene s;
    s.modeling = std::move(grid);
    s.sdf = std::move(sdf);
    s.sdf_block = B;
    s.sdf_is_lower_bound = true; // see above: L - 4 max voxel, clamped below
    s.uniform_detail_type = 0.0f;
    s.uniform_density_scale = static_cast<float>(S);
    s.density_grid_max = dmax;
    validate_scene(s);
    return s;
}

} // namespace

CloudScene scene_from_fields(std::vector<SceneField> files, double voxel_size) {
    if (!(voxel_size >= 0) || !std::isfinite(voxel_size)) throw Error("render: voxel size must be finite and >= 0 metres");
    if (files.empty() || files.size() > 2) throw Error("render: expected one NVDF set file, or a modeling file and an SDF file");
    for (const SceneField& f : files)
        if (!f.field) throw Error("render: " + f.name + ": no field");
    Field3DPtr first = rebound(std::move(files[0].field), voxel_size);
    if (files.size() == 1) {
        try {
            // A plain density grid (density_grid_scene): the profile goes over
            // the grid's own storage when nothing else holds the grid (a field
            // the caller just read and moved in), else over a copy.
            if (first->find_channel("dimensional_profile") < 0 && first->channels() == 1) {
                std::shared_ptr<Field3D> grid =
                    first.use_count() == 1 ? std::const_pointer_cast<Field3D>(first) : std::make_shared<Field3D>(*first);
                first.reset();
                return density_grid_scene(std::move(grid));
            }
            return scene_from_nvdf_set(std::move(first));
        } catch (const Error& e) {
            throw Error(files[0].name + ": " + e.what());
        }
    }
    Field3DPtr second = rebound(std::move(files[1].field), voxel_size);
    if (first->channels() < 3) throw Error(files[0].name + ": the modeling NVDF needs 3 channels, got " + std::to_string(first->channels()));
    CloudScene s;
    s.modeling = first;
    int c = second->find_channel("sdf");
    auto sdf = std::make_shared<Field3D>(second->resolution(), 1, second->bounds(), std::vector<std::string>{"sdf"});
    if (c >= 0) {
        std::copy(second->channel(c).begin(), second->channel(c).end(), sdf->channel(0).begin());
    } else {
        // Encoded field data: the Nubis pack range [-256, 4096] m.
        c = second->find_channel("field_data");
        if (c < 0) c = 0;
        auto src = second->channel(c);
        auto dst = sdf->channel(0);
        for (size_t i = 0; i < src.size(); ++i) dst[i] = static_cast<float>(double(src[i]) * 4352.0 - 256.0);
    }
    s.sdf = sdf;
    try {
        validate_scene(s);
    } catch (const Error& e) {
        throw Error(files[0].name + ", " + files[1].name + ": " + e.what());
    }
    return s;
}

} // namespace atlas::render
