#include "light_grid.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace atlas::render::detail {

namespace {

// Trilinear blend at lattice coordinates q (samples at the integers, clamped
// to [0, n - 1]) of at(i, j, k): the grid's and the sun map's lookups.
template <class At>
float trilinear(const double q[3], const int n[3], const At& at) {
    int i0[3], i1[3];
    float w[3];
    for (int e = 0; e < 3; ++e) {
        const double r = std::clamp(q[e], 0.0, double(n[e] - 1));
        i0[e] = std::min(static_cast<int>(r), n[e] - 1);
        i1[e] = std::min(i0[e] + 1, n[e] - 1);
        w[e] = static_cast<float>(r - i0[e]);
    }
    const float c00 = at(i0[0], i0[1], i0[2]) + (at(i1[0], i0[1], i0[2]) - at(i0[0], i0[1], i0[2])) * w[0];
    const float c10 = at(i0[0], i1[1], i0[2]) + (at(i1[0], i1[1], i0[2]) - at(i0[0], i1[1], i0[2])) * w[0];
    const float c01 = at(i0[0], i0[1], i1[2]) + (at(i1[0], i0[1], i1[2]) - at(i0[0], i0[1], i1[2])) * w[0];
    const float c11 = at(i0[0], i1[1], i1[2]) + (at(i1[0], i1[1], i1[2]) - at(i0[0], i1[1], i1[2])) * w[0];
    const float c0 = c00 + (c10 - c00) * w[1], c1 = c01 + (c11 - c01) * w[1];
    return c0 + (c1 - c0) * w[2];
}

} // namespace

double exit_distance(const Box3d& b, const Vec3d& p, const Vec3d& d) {
    double t1 = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (d[a] > 1e-12) t1 = std::min(t1, (b.max[a] - p[a]) / d[a]);
        else if (d[a] < -1e-12) t1 = std::min(t1, (b.min[a] - p[a]) / d[a]);
    }
    return std::isfinite(t1) ? std::max(0.0, t1) : 0.0;
}

LightGrid::LightGrid(const CloudSampler& cloud, Vec3i res, Vec3d sun_dir)
    : LightGrid(cloud.bounds(), res, sun_dir, [&cloud](double x, double y, double z) { return cloud.density_at(x, y, z, 1e30); }) {}

LightGrid::LightGrid(const Box3d& bounds, Vec3i res, Vec3d sun_dir, const DensityFn& density) : res_(res), bounds_(bounds), sun_dir_(sun_dir) {
    for (int a = 0; a < 3; ++a) voxel_[a] = bounds_.size()[a] / res_[a];
    const size_t n = size_t(res_[0]) * size_t(res_[1]) * size_t(res_[2]);
    const size_t row = size_t(res_[0]), slab = row * size_t(res_[1]);
    // 1. The density at the grid's voxel centres (voxels: no near-camera detail).
    dens_.assign(n, 0.0f);
    std::vector<float>& dens = dens_;
    parallel_for_index(res_[2], [&](int z) {
        for (int y = 0; y < res_[1]; ++y)
            for (int x = 0; x < res_[0]; ++x) {
                const double px = bounds_.min[0] + (x + 0.5) * voxel_[0];
                const double py = bounds_.min[1] + (y + 0.5) * voxel_[1];
                const double pz = bounds_.min[2] + (z + 0.5) * voxel_[2];
                dens[size_t(z) * slab + size_t(y) * row + size_t(x)] = density(px, py, pz);
            }
    });
    // 2. Toward the sun: march the coarse density from each voxel centre.
    //    A sample whose trilinear cell has eight zero corners adds exactly 0,
    //    so it is skipped after a one-byte test (most of a sparse cloud's
    //    grid is empty; same bytes as sampling it).
    std::vector<unsigned char> occupied(n, 0);
    parallel_for_index(res_[2], [&](int z) {
        const int z1 = std::min(z + 1, res_[2] - 1);
        for (int y = 0; y < res_[1]; ++y) {
            const int y1 = std::min(y + 1, res_[1] - 1);
            for (int x = 0; x < res_[0]; ++x) {
                const int x1 = std::min(x + 1, res_[0] - 1);
                bool any = false;
                for (int zz : {z, z1})
                    for (int yy : {y, y1})
                        for (int xx : {x, x1}) any = any || dens[size_t(zz) * slab + size_t(yy) * row + size_t(xx)] != 0.0f;
                occupied[size_t(z) * slab + size_t(y) * row + size_t(x)] = any ? 1 : 0;
            }
        }
    });
    // The occupied cells' index box: along a ray each cell index moves one
    // way, so once one leaves the box toward the sun, nothing follows.
    int lo[3] = {res_[0], res_[1], res_[2]}, hi[3] = {-1, -1, -1};
    for (int z = 0; z < res_[2]; ++z)
        for (int y = 0; y < res_[1]; ++y)
            for (int x = 0; x < res_[0]; ++x)
                if (occupied[size_t(z) * slab + size_t(y) * row + size_t(x)]) {
                    const int c[3] = {x, y, z};
                    for (int a = 0; a < 3; ++a) {
                        lo[a] = std::min(lo[a], c[a]);
                        hi[a] = std::max(hi[a], c[a]);
                    }
                }
    // 1 = the sample's cell is occupied, 0 = not, -1 = neither is any later one.
    auto cell_occupied = [&](const Vec3d& q) {
        size_t i = 0;
        const size_t stride[3] = {1, row, slab};
        for (int a = 0; a < 3; ++a) {
            const double v = std::clamp((q[a] - bounds_.min[a]) / voxel_[a] - 0.5, 0.0, double(res_[a] - 1));
            const int k = std::min(static_cast<int>(v), res_[a] - 1);
            if ((sun_dir[a] > 0 && k > hi[a]) || (sun_dir[a] < 0 && k < lo[a])) return -1;
            i += size_t(k) * stride[a];
        }
        return occupied[i] != 0 ? 1 : 0;
    };
    sun_.assign(n, 0.0f);
    const double step = 0.75 * std::min({voxel_[0], voxel_[1], voxel_[2]});
    parallel_for_index(res_[2], [&](int z) {
        for (int y = 0; y < res_[1]; ++y)
            for (int x = 0; x < res_[0]; ++x) {
                const Vec3d p{{bounds_.min[0] + (x + 0.5) * voxel_[0], bounds_.min[1] + (y + 0.5) * voxel_[1],
                               bounds_.min[2] + (z + 0.5) * voxel_[2]}};
                const double len = exit_distance(bounds_, p, sun_dir);
                const int steps = static_cast<int>(std::ceil(len / step));
                double acc = 0;
                for (int s = 0; s < steps; ++s) {
                    const double t0 = s * step, dt = std::min(step, len - t0);
                    const Vec3d q = p + sun_dir * (t0 + 0.5 * dt);
                    const int o = cell_occupied(q);
                    if (o < 0) break;
                    if (o) acc += sample(dens, q[0], q[1], q[2]) * dt;
                }
                sun_[size_t(z) * slab + size_t(y) * row + size_t(x)] = static_cast<float>(acc);
            }
    });
}

SunDepthMap::SunDepthMap(const Box3d& bounds, Vec3d voxel, Vec3d sun_dir, const LightGrid::DensityFn& density, double across,
                         const LightGrid::DensityFn* distance) {
    // The march axis: any the sun is not parallel to works; the one with the
    // fewest columns keeps the table small (a flat cloudscape under a low sun
    // marches along z: along y its sheared columns would span 5x its height).
    double best = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
        if (std::abs(sun_dir[a]) < 0.1) continue; // a near-grazing axis shears without bound
        const int b = (a + 1) % 3, c = (a + 2) % 3;
        const double la = bounds.max[a] - bounds.min[a];
        const double cols = (bounds.size()[b] + std::abs(sun_dir[b] / sun_dir[a]) * la) / voxel[b] *
                            ((bounds.size()[c] + std::abs(sun_dir[c] / sun_dir[a]) * la) / voxel[c]);
        if (cols < best) {
            best = cols;
            a_ = a;
        }
    }
    b_ = (a_ + 1) % 3;
    c_ = (a_ + 2) % 3;
    voxel_ = voxel;
    voxel_[b_] /= across;
    voxel_[c_] /= across;
    const double sa = sun_dir[a_];
    sb_ = sun_dir[b_] / sa;
    sc_ = sun_dir[c_] / sa;
    a0_ = bounds.min[a_];
    const double la = bounds.max[a_] - bounds.min[a_];
    // Across the rays: every (b, c) the bounds reach at some a, shifted back to a0.
    const double u_lo = bounds.min[b_] - std::max(0.0, sb_ * la), u_hi = bounds.max[b_] - std::min(0.0, sb_ * la);
    const double v_lo = bounds.min[c_] - std::max(0.0, sc_ * la), v_hi = bounds.max[c_] - std::min(0.0, sc_ * la);
    n_[0] = std::max(1, static_cast<int>(std::ceil(la / voxel_[a_] - 1e-9)));
    n_[1] = std::max(1, static_cast<int>(std::ceil((u_hi - u_lo) / voxel_[b_] - 1e-9)));
    n_[2] = std::max(1, static_cast<int>(std::ceil((v_hi - v_lo) / voxel_[c_] - 1e-9)));
    u0_ = u_lo;
    v0_ = v_lo;
    const double da = la / n_[0];
    voxel_[a_] = da;
    toward_plus_ = sa > 0;
    // Each column keeps only the samples inside the bounds (a sheared table
    // is mostly outside them): [first, first + count) along a, stored from
    // `offset`; beyond that the depth is 0 toward the sun, the column's total away.
    const size_t ncol = size_t(n_[1]) * size_t(n_[2]);
    cols_.assign(ncol, Column{});
    for (int k = 0; k < n_[2]; ++k)
        for (int j = 0; j < n_[1]; ++j) {
            const double u = u0_ + (j + 0.5) * voxel_[b_], v = v0_ + (k + 0.5) * voxel_[c_];
            double lo = 0, hi = la; // along a, relative to a0
            auto clip = [&](double base, double s, double mn, double mx) {
                if (std::abs(s) < 1e-12) {
                    if (base < mn || base > mx) hi = -1;
                    return;
                }
                double t1 = (mn - base) / s, t2 = (mx - base) / s;
                if (t1 > t2) std::swap(t1, t2);
                lo = std::max(lo, t1);
                hi = std::min(hi, t2);
            };
            clip(u, sb_, bounds.min[b_], bounds.max[b_]);
            clip(v, sc_, bounds.min[c_], bounds.max[c_]);
            Column& col = cols_[size_t(k) * size_t(n_[1]) + size_t(j)];
            if (hi < lo) continue;
            col.first = std::max(0, static_cast<int>(std::floor(lo / da - 0.5)));
            col.count = std::min(n_[0] - 1, static_cast<int>(std::ceil(hi / da - 0.5))) - col.first + 1;
        }
    // Path length per sample: the ray advances da along a in da / |sun_a| metres.
    const double ds = da / std::abs(sa);
    // A column keeps only the samples from its first to its last cloud sample: on the sun's
    // side of them the depth is exactly 0, beyond them exactly the column's total, which is
    // what at() answers outside the kept range (a cloudscape's table is mostly such runs).
    std::vector<std::vector<float>> slabs(static_cast<size_t>(n_[2]));
    parallel_for_index(n_[2], [&](int k) {
        const double v = v0_ + (k + 0.5) * voxel_[c_];
        std::vector<float> d;
        std::vector<float>& kept = slabs[size_t(k)];
        for (int j = 0; j < n_[1]; ++j) {
            Column& col = cols_[size_t(k) * size_t(n_[1]) + size_t(j)];
            if (col.count <= 0) continue;
            const double u = u0_ + (j + 0.5) * voxel_[b_];
            d.resize(size_t(col.count));
            int lo = col.count, hi = -1; // the first and last samples with density
            for (int m = 0; m < col.count; ++m) {
                const double t = (col.first + m + 0.5) * da;
                Vec3d p;
                p[a_] = a0_ + t;
                p[b_] = u + sb_ * t;
                p[c_] = v + sc_ * t;
                if (distance) {
                    const double r = (*distance)(p[0], p[1], p[2]);
                    if (r > 0) { // this sample and the next ones closer than r hold no cloud
                        const int ahead = static_cast<int>(std::min(double(col.count), std::ceil(r / ds))); // r may be 1e30
                        const int last = std::min(col.count - 1, m + ahead - 1);
                        std::fill(d.begin() + m, d.begin() + last + 1, 0.0f);
                        m = last;
                        continue;
                    }
                }
                d[size_t(m)] = density(p[0], p[1], p[2]);
                if (d[size_t(m)] != 0.0f) {
                    lo = std::min(lo, m);
                    hi = m;
                }
            }
            // Midpoint rule toward the sun: half the own sample, all beyond it.
            double acc = 0;
            for (int s = 0; s < col.count; ++s) {
                const int m = toward_plus_ ? col.count - 1 - s : s;
                const double dm = d[size_t(m)];
                d[size_t(m)] = static_cast<float>(acc + 0.5 * dm * ds);
                acc += dm * ds;
            }
            col.total = static_cast<float>(acc);
            if (hi < 0) {
                col.count = 0; // no cloud on this ray: 0 toward the sun and (total =) 0 away
                continue;
            }
            col.offset = kept.size();
            kept.insert(kept.end(), d.begin() + lo, d.begin() + hi + 1);
            col.first += lo;
            col.count = hi - lo + 1;
        }
    });
    // One array, slab after slab (offsets were per slab).
    size_t total = 0;
    for (int k = 0; k < n_[2]; ++k) {
        for (int j = 0; j < n_[1]; ++j) cols_[size_t(k) * size_t(n_[1]) + size_t(j)].offset += total;
        total += slabs[size_t(k)].size();
    }
    depth_.reserve(total);
    for (auto& slab : slabs) {
        depth_.insert(depth_.end(), slab.begin(), slab.end());
        std::vector<float>().swap(slab);
    }
}

float SunDepthMap::at(int i, int j, int k) const {
    const Column& col = cols_[size_t(k) * size_t(n_[1]) + size_t(j)];
    const int m = i - col.first;
    if (m < 0) return toward_plus_ ? col.total : 0.0f;
    if (m >= col.count) return toward_plus_ ? 0.0f : col.total;
    return depth_[col.offset + size_t(m)];
}

float SunDepthMap::sun(double x, double y, double z) const {
    const double p[3] = {x, y, z};
    const double t = p[a_] - a0_;
    const double q[3] = {t / voxel_[a_] - 0.5, (p[b_] - sb_ * t - u0_) / voxel_[b_] - 0.5, (p[c_] - sc_ * t - v0_) / voxel_[c_] - 0.5};
    return trilinear(q, n_, [this](int i, int j, int k) { return at(i, j, k); });
}

float LightGrid::sample(const std::vector<float>& g, double x, double y, double z) const {
    const double u[3] = {(x - bounds_.min[0]) / voxel_[0] - 0.5, (y - bounds_.min[1]) / voxel_[1] - 0.5, (z - bounds_.min[2]) / voxel_[2] - 0.5};
    const size_t row = size_t(res_[0]), slab = row * size_t(res_[1]);
    return trilinear(u, res_.v.data(), [&](int xx, int yy, int zz) { return g[size_t(zz) * slab + size_t(yy) * row + size_t(xx)]; });
}

} // namespace atlas::render::detail
