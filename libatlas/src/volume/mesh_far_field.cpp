// The whole-grid part of both mesh SDF methods: the exact EDT to the mesh's grid-line
// crossings, merged with the exact band, signed by the six-ray winding vote, in two
// passes over memory (see mesh_line_hits.h, mesh_signed_distance).
//
// The squared distance to the crossings is the minimum over the three crossing families
// (x, y, z: the axis of the fractional coordinate) of a separable transform: the 1D
// nearest crossing along the family's axis (S_a), then lower envelopes of parabolas
// (E_b, Felzenszwalb-Huttenlocher) along the two other axes. E is linear in the min-plus
// sense (E[min(f, g)] = min(E f, E g)), so the families x and y share their last
// envelope:
//   D = min( E_z[ min(E_y S_x, E_x S_y) ], E_y E_x S_z ).
// Pass 1, parallel over z-slabs (an x-y slab is in the L2 cache): S_x, E_y; S_y, E_x;
// their min to `work`; S_z, E_x, E_y to the output; the x and y ray counts of the vote.
// Pass 2, parallel over y, 16 x-columns at a time: E_z of `work`, min with the output
// (which the exact band has lowered in between), square root, the z ray counts and the
// sign. Every slab, column and voxel is computed the same way on any thread count.
#include "mesh_line_hits.h"

#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

namespace atlas::volume::detail {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int16_t kDisagree = std::numeric_limits<int16_t>::min();

// One site of the envelope's stack: its position, g = f/h2 + q^2, f, and its left
// boundary as a fraction zn / zd (zd > 0).
struct Site {
    double g, zn, zd;
    float f;
    int q;
};
struct Scratch {
    std::vector<Site> st;
};

// Lower envelope of parabolas (p - q)^2 * h2 + f(q) over integer sites q (f may be +inf:
// no site). f and out have strides fs and os and must not overlap. Returns false (out
// untouched) when f has no site. Felzenszwalb-Huttenlocher as in sdf_edt.cpp, without
// divisions: each boundary between neighbouring sites is kept as a fraction and compared
// by cross-multiplying. Rounding can only change which of two (nearly) tied sites is
// taken; out[q] is always the exact value of the site taken, e^2 h2 + f(p).
bool envelope(const float* f, size_t fs, float* out, size_t os, int n, double h2, Scratch& s) {
    s.st.resize(size_t(n));
    Site* st = s.st.data();
    const double inv_h2 = 1.0 / h2;
    int k = -1;
    for (int q = 0; q < n; ++q) {
        const float fv = f[size_t(q) * fs];
        if (fv == kInf) continue;
        const double gq = double(fv) * inv_h2 + double(q) * q;
        double num = 0, den = 1;
        while (k >= 0) {
            const Site& t = st[k];
            num = gq - t.g;
            den = 2.0 * (q - t.q);
            // Pop the top while the new parabola undercuts it before its left boundary
            // (the first site's boundary is -inf).
            if (k > 0 && num * t.zd <= t.zn * den) --k;
            else break;
        }
        st[++k] = {gq, num, den, fv, q};
    }
    if (k < 0) return false;
    int j = 0;
    for (int q = 0; q < n; ++q) {
        while (j < k && st[j + 1].zn < double(q) * st[j + 1].zd) ++j;
        const double e = double(q - st[j].q);
        out[size_t(q) * os] = float(e * e * h2 + double(st[j].f));
    }
    return true;
}

// 1D squared distance from samples 0..n-1 (stride os) to the nearest of the sorted seeds
// t[0..m) (voxel units along the line); false when there is none.
bool nearest_seed(const double* t, uint32_t m, float* out, size_t os, int n, double ha2) {
    if (m == 0) return false;
    uint32_t j = 0;
    for (int i = 0; i < n; ++i) {
        while (j + 1 < m && std::abs(i - t[j + 1]) <= std::abs(i - t[j])) ++j;
        const double e = i - t[j];
        out[size_t(i) * os] = float(e * e * ha2);
    }
    return true;
}

int16_t clamp16(int w) { return int16_t(std::clamp(w, -32000, 32000)); }

// The two ray counts (from -inf and from +inf) of every sample of line l along one axis,
// merged into cnt (stride cs): kDisagree once any count differs from the first.
template <bool First>
void ray_counts(const AxisHits& ah, uint32_t l, int n, int16_t* cnt, size_t cs) {
    const uint32_t k0 = ah.offsets[l], k1 = ah.offsets[l + 1];
    int total = 0;
    for (uint32_t k = k0; k < k1; ++k) total += ah.sign[k];
    int below = 0;
    uint32_t k = k0;
    for (int x = 0; x < n; ++x) {
        while (k < k1 && ah.t[k] <= x) below += ah.sign[k++];
        const int16_t a = clamp16(below), b = clamp16(-(total - below));
        int16_t& c = cnt[size_t(x) * cs];
        if constexpr (First) c = a == b ? a : kDisagree;
        else if (c != a || c != b) c = kDisagree;
    }
}

// Seeds of every line along one axis, CSR: the hits themselves on a single closed part,
// the union-boundary hits otherwise.
struct Seeds {
    const uint32_t* off = nullptr;
    const double* t = nullptr;
    std::vector<uint32_t> off_store;
    std::vector<double> t_store;
};

Seeds line_seeds(const AxisHits& ah, const UnionSurface& us) {
    Seeds s;
    if (us.trivial()) {
        s.off = ah.offsets.data();
        s.t = ah.t.data();
        return s;
    }
    const uint32_t lines = uint32_t(ah.offsets.size() - 1);
    std::vector<std::vector<double>> per(lines);
    parallel_blocks(lines, 256, [&](size_t l0, size_t l1) {
        for (size_t l = l0; l < l1; ++l) union_boundary_hits(ah, uint32_t(l), per[l]);
    });
    s.off_store.assign(size_t(lines) + 1, 0);
    for (uint32_t l = 0; l < lines; ++l) s.off_store[l + 1] = s.off_store[l] + uint32_t(per[l].size());
    s.t_store.reserve(s.off_store[lines]);
    for (const auto& p : per) s.t_store.insert(s.t_store.end(), p.begin(), p.end());
    s.off = s.off_store.data();
    s.t = s.t_store.data();
    return s;
}

} // namespace

uint64_t mesh_signed_distance(const MeshLineHits& hits, const UnionSurface& us, const Mesh& mesh, Vec3i res, Box3d bounds,
                              float far, float* out, const std::function<void(float*)>& band) {
    const int nx = res[0], ny = res[1], nz = res[2];
    const size_t sxy = size_t(nx) * size_t(ny), count = sxy * size_t(nz);
    Vec3d h;
    for (int a = 0; a < 3; ++a) h[a] = (bounds.max[a] - bounds.min[a]) / res[a];
    const double h2[3] = {h[0] * h[0], h[1] * h[1], h[2] * h[2]};
    const Seeds seeds[3] = {line_seeds(hits.axis[0], us), line_seeds(hits.axis[1], us), line_seeds(hits.axis[2], us)};
    // Every value is written by pass 1 before pass 2 reads it: no zero fill.
    const std::unique_ptr<float[]> work(new float[count]);
    const std::unique_ptr<int16_t[]> cnt(new int16_t[count]);

    // Pass 1: per z-slab.
    parallel_for_index(nz, [&](int z) {
        // The slab's buffers stay in the L2 cache; the grids get contiguous copies.
        std::vector<float> A(sxy), B(sxy), line(size_t(std::max(nx, ny)));
        std::vector<int16_t> K(sxy);
        std::vector<uint32_t> cj(size_t(nx), 0), ck(size_t(nx), 0);
        std::vector<int> cb(size_t(nx), 0), ct(size_t(nx), 0);
        Scratch sc;
        float* W = work.get() + size_t(z) * sxy;
        float* C = out + size_t(z) * sxy;
        // Family x: S_x along rows, then E_y down the columns.
        bool any_x = false;
        for (int y = 0; y < ny; ++y) {
            const uint32_t l = uint32_t(y) + uint32_t(z) * uint32_t(ny);
            float* row = A.data() + size_t(y) * size_t(nx);
            if (nearest_seed(seeds[0].t + seeds[0].off[l], seeds[0].off[l + 1] - seeds[0].off[l], row, 1, nx, h2[0])) any_x = true;
            else std::fill(row, row + nx, kInf);
            ray_counts<true>(hits.axis[0], l, nx, K.data() + size_t(y) * size_t(nx), 1);
        }
        if (any_x)
            for (int x = 0; x < nx; ++x) {
                float* col = A.data() + size_t(x);
                if (envelope(col, size_t(nx), line.data(), 1, ny, h2[1], sc))
                    for (int y = 0; y < ny; ++y) col[size_t(y) * size_t(nx)] = line[size_t(y)];
            }
        // Family y: S_y down the columns and their ray counts, computed row by row
        // with a cursor per column (the same arithmetic as nearest_seed / ray_counts).
        bool any_y = false;
        {
            const AxisHits& ah = hits.axis[1];
            for (int x = 0; x < nx; ++x) {
                const uint32_t l = uint32_t(x) + uint32_t(z) * uint32_t(nx);
                cj[size_t(x)] = seeds[1].off[l];
                ck[size_t(x)] = ah.offsets[l];
                cb[size_t(x)] = 0;
                int total = 0;
                for (uint32_t k = ah.offsets[l]; k < ah.offsets[l + 1]; ++k) total += ah.sign[k];
                ct[size_t(x)] = total;
                any_y |= seeds[1].off[l + 1] > seeds[1].off[l];
            }
            const double* t = seeds[1].t;
            for (int y = 0; y < ny; ++y) {
                float* row = B.data() + size_t(y) * size_t(nx);
                int16_t* krow = K.data() + size_t(y) * size_t(nx);
                for (int x = 0; x < nx; ++x) {
                    const uint32_t l = uint32_t(x) + uint32_t(z) * uint32_t(nx);
                    const uint32_t end = seeds[1].off[l + 1];
                    uint32_t& j = cj[size_t(x)];
                    if (j == end) row[x] = kInf; // no seed on this line
                    else {
                        while (j + 1 < end && std::abs(y - t[j + 1]) <= std::abs(y - t[j])) ++j;
                        const double e = y - t[j];
                        row[x] = float(e * e * h2[1]);
                    }
                    const uint32_t k1 = ah.offsets[l + 1];
                    uint32_t& k = ck[size_t(x)];
                    int& below = cb[size_t(x)];
                    while (k < k1 && ah.t[k] <= y) below += ah.sign[k++];
                    const int16_t a = clamp16(below), b = clamp16(-(ct[size_t(x)] - below));
                    int16_t& c = krow[x];
                    if (c != a || c != b) c = kDisagree;
                }
            }
        }
        if (any_y)
            for (int y = 0; y < ny; ++y) {
                float* row = B.data() + size_t(y) * size_t(nx);
                if (envelope(row, 1, line.data(), 1, nx, h2[0], sc)) std::copy(line.begin(), line.begin() + nx, row);
            }
        if (any_x && any_y)
            for (size_t i = 0; i < sxy; ++i) W[i] = std::min(A[i], B[i]);
        else if (any_x) std::copy(A.begin(), A.end(), W);
        else if (any_y) std::copy(B.begin(), B.end(), W);
        else std::fill(W, W + sxy, kInf);
        // Family z: S_z at this z for every z-line, then E_x along rows, E_y down the columns.
        const Seeds& sz = seeds[2];
        bool any_z = false;
        for (int y = 0; y < ny; ++y)
            for (int x = 0; x < nx; ++x) {
                const uint32_t l = uint32_t(x) + uint32_t(y) * uint32_t(nx);
                const double* t0 = sz.t + sz.off[l];
                const double* t1 = sz.t + sz.off[l + 1];
                float& a = A[size_t(y) * size_t(nx) + size_t(x)];
                if (t0 == t1) {
                    a = kInf;
                    continue;
                }
                any_z = true;
                const double* it = std::lower_bound(t0, t1, double(z));
                double e = std::numeric_limits<double>::infinity();
                if (it != t1) e = *it - z;
                if (it != t0 && z - *(it - 1) < e) e = z - *(it - 1);
                a = float(e * e * h2[2]);
            }
        bool any_c = false;
        if (any_z) {
            for (int y = 0; y < ny; ++y) {
                float* row = A.data() + size_t(y) * size_t(nx);
                if (!envelope(row, 1, B.data() + size_t(y) * size_t(nx), 1, nx, h2[0], sc))
                    std::fill(B.data() + size_t(y) * size_t(nx), B.data() + size_t(y + 1) * size_t(nx), kInf);
                else any_c = true;
            }
        }
        if (any_c) {
            for (int x = 0; x < nx; ++x) {
                float* col = A.data() + size_t(x);
                if (envelope(B.data() + size_t(x), size_t(nx), line.data(), 1, ny, h2[1], sc))
                    for (int y = 0; y < ny; ++y) col[size_t(y) * size_t(nx)] = line[size_t(y)];
                else
                    for (int y = 0; y < ny; ++y) col[size_t(y) * size_t(nx)] = kInf;
            }
            std::copy(A.begin(), A.end(), C);
        } else std::fill(C, C + sxy, kInf);
        std::copy(K.begin(), K.end(), cnt.get() + size_t(z) * sxy);
    });

    // The exact band lowers the squared distances (the family-z EDT is an upper bound).
    if (band) band(out);

    // Pass 2: per y, 16 z-columns at a time.
    constexpr int kBlock = 16;
    std::vector<std::vector<size_t>> disagree(static_cast<size_t>(ny));
    parallel_for_index(ny, [&](int y) {
        std::vector<float> bw(size_t(nz) * kBlock), bs(size_t(nz) * kBlock), line(static_cast<size_t>(nz));
        std::vector<int16_t> bk(size_t(nz) * kBlock);
        Scratch sc;
        for (int x0 = 0; x0 < nx; x0 += kBlock) {
            const int w = std::min(kBlock, nx - x0);
            const size_t base = size_t(y) * size_t(nx) + size_t(x0);
            for (int z = 0; z < nz; ++z) {
                const size_t o = base + size_t(z) * sxy;
                for (int k = 0; k < w; ++k) {
                    bw[size_t(z) * kBlock + size_t(k)] = work[o + size_t(k)];
                    bs[size_t(z) * kBlock + size_t(k)] = out[o + size_t(k)];
                    bk[size_t(z) * kBlock + size_t(k)] = cnt[o + size_t(k)];
                }
            }
            for (int k = 0; k < w; ++k) {
                float* s = bs.data() + size_t(k);
                if (envelope(bw.data() + size_t(k), kBlock, line.data(), 1, nz, h2[2], sc))
                    for (int z = 0; z < nz; ++z) s[size_t(z) * kBlock] = std::min(s[size_t(z) * kBlock], line[size_t(z)]);
                const uint32_t l = uint32_t(x0 + k) + uint32_t(y) * uint32_t(nx);
                int16_t* kk = bk.data() + size_t(k);
                ray_counts<false>(hits.axis[2], l, nz, kk, kBlock);
                for (int z = 0; z < nz; ++z) {
                    const float d2 = s[size_t(z) * kBlock];
                    const float d = d2 == kInf ? far : std::sqrt(d2);
                    const int16_t c = kk[size_t(z) * kBlock];
                    if (c == kDisagree) disagree[size_t(y)].push_back(base + size_t(k) + size_t(z) * sxy);
                    s[size_t(z) * kBlock] = c != kDisagree && c >= 1 ? -d : d;
                }
            }
            for (int z = 0; z < nz; ++z) {
                const size_t o = base + size_t(z) * sxy;
                for (int k = 0; k < w; ++k) out[o + size_t(k)] = bs[size_t(z) * kBlock + size_t(k)];
            }
        }
    });

    // Where the six counts disagree (holes, flipped faces): the fast generalized winding number.
    std::vector<size_t> todo;
    for (const auto& d : disagree) todo.insert(todo.end(), d.begin(), d.end());
    if (!todo.empty()) {
        const FastWindingNumber wn(mesh);
        parallel_blocks(todo.size(), 64, [&](size_t k0, size_t k1) {
            for (size_t k = k0; k < k1; ++k) {
                const size_t v = todo[k];
                const size_t x = v % size_t(nx), y = (v / size_t(nx)) % size_t(ny), z = v / sxy;
                const Vec3d p{{bounds.min[0] + (double(x) + 0.5) * h[0], bounds.min[1] + (double(y) + 0.5) * h[1],
                               bounds.min[2] + (double(z) + 0.5) * h[2]}};
                const float d = std::abs(out[v]);
                out[v] = float(wn(p)) > 0.5f ? -d : d;
            }
        });
    }
    return todo.size();
}

} // namespace atlas::volume::detail
