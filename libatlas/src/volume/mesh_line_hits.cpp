// Mesh/grid-line crossings and the six-ray winding vote.
#include "mesh_line_hits.h"

#include "atlas/core/error.h"
#include "atlas/core/parallel.h"
#include "atlas/volume/mesh_repair.h"
#include "atlas/volume/mesh_voxelize.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>

namespace atlas::volume::detail {
namespace {

// Edge ownership for the top-left rule: antisymmetric, so an edge shared by
// two triangles projected on opposite sides belongs to exactly one.
bool owns_edge(double dx, double dy) { return dy > 0 || (dy == 0 && dx < 0); }

struct Candidate {
    uint32_t line;
    uint32_t tri;
};

AxisHits hits_along(const Mesh& m, const std::vector<Vec3d>& pv, Vec3i res, int a) {
    int b, c;
    other_axes(a, b, c);
    const uint32_t lines = uint32_t(res[b]) * uint32_t(res[c]);
    // Bin triangles onto the lines their projection covers (serial: deterministic order).
    std::vector<Candidate> cand;
    for (uint32_t t = 0; t < m.triangles.size(); ++t) {
        const Vec3d& p0 = pv[m.triangles[t][0]];
        const Vec3d& p1 = pv[m.triangles[t][1]];
        const Vec3d& p2 = pv[m.triangles[t][2]];
        const int b0 = std::max(0, int(std::ceil(std::min({p0[b], p1[b], p2[b]}))));
        const int b1 = std::min(res[b] - 1, int(std::floor(std::max({p0[b], p1[b], p2[b]}))));
        const int c0 = std::max(0, int(std::ceil(std::min({p0[c], p1[c], p2[c]}))));
        const int c1 = std::min(res[c] - 1, int(std::floor(std::max({p0[c], p1[c], p2[c]}))));
        for (int j = c0; j <= c1; ++j)
            for (int i = b0; i <= b1; ++i) cand.push_back({uint32_t(i) + uint32_t(j) * uint32_t(res[b]), t});
    }
    std::stable_sort(cand.begin(), cand.end(), [](const Candidate& x, const Candidate& y) { return x.line < y.line; });
    std::vector<uint32_t> cand_off(lines + 1, 0);
    for (const Candidate& cd : cand) ++cand_off[cd.line + 1];
    std::partial_sum(cand_off.begin(), cand_off.end(), cand_off.begin());

    // Per line: test candidates, keep hits sorted by t (ties: by sign, then triangle).
    struct Hit {
        double t;
        int8_t s;
        uint32_t tri;
    };
    std::vector<std::vector<Hit>> per_line(lines);
    parallel_blocks(lines, 256, [&](size_t l0, size_t l1) {
        for (uint32_t l = uint32_t(l0); l < l1; ++l) {
            const double qb = double(l % uint32_t(res[b])), qc = double(l / uint32_t(res[b]));
            auto& out = per_line[l];
            for (uint32_t k = cand_off[l]; k < cand_off[l + 1]; ++k) {
                const auto& tri = m.triangles[cand[k].tri];
                Vec3d p[3] = {pv[tri[0]], pv[tri[1]], pv[tri[2]]};
                double area = (p[1][b] - p[0][b]) * (p[2][c] - p[0][c]) - (p[1][c] - p[0][c]) * (p[2][b] - p[0][b]);
                if (area == 0) continue; // edge-on: the line grazes it
                const int8_t facing = area > 0 ? 1 : -1;
                if (area < 0) std::swap(p[1], p[2]), area = -area;
                double w[3];
                bool inside = true;
                for (int e = 0; e < 3 && inside; ++e) {
                    const Vec3d& u = p[(e + 1) % 3];
                    const Vec3d& v = p[(e + 2) % 3];
                    const double dx = v[b] - u[b], dy = v[c] - u[c];
                    w[e] = dx * (qc - u[c]) - dy * (qb - u[b]);
                    inside = w[e] > 0 || (w[e] == 0 && owns_edge(dx, dy));
                }
                if (!inside) continue;
                const double t = (w[0] * p[0][a] + w[1] * p[1][a] + w[2] * p[2][a]) / area;
                // facing: sign of the normal's a-component in (b, c, a) order;
                // for a right-handed (a, b, c) cycle that is the normal along +a.
                const bool cyclic = (b == (a + 1) % 3);
                const int8_t n_a = cyclic ? facing : int8_t(-facing);
                out.push_back({t, int8_t(n_a < 0 ? 1 : -1), cand[k].tri});
            }
            std::sort(out.begin(), out.end(), [](const Hit& x, const Hit& y) {
                return x.t != y.t ? x.t < y.t : (x.s != y.s ? x.s < y.s : x.tri < y.tri);
            });
        }
    });
    AxisHits h;
    h.offsets.assign(lines + 1, 0);
    for (uint32_t l = 0; l < lines; ++l) h.offsets[l + 1] = h.offsets[l] + uint32_t(per_line[l].size());
    h.t.resize(h.offsets[lines]);
    h.sign.resize(h.offsets[lines]);
    for (uint32_t l = 0; l < lines; ++l)
        for (size_t k = 0; k < per_line[l].size(); ++k) {
            h.t[h.offsets[l] + k] = per_line[l][k].t;
            h.sign[h.offsets[l] + k] = per_line[l][k].s;
        }
    return h;
}

} // namespace

MeshLineHits mesh_line_hits(const Mesh& m, Vec3i res, Box3d bounds) {
    validate_mesh(m, "mesh voxelisation");
    if (!bounds.valid()) throw Error("mesh voxelisation: bounds must be finite with max > min on every axis");
    for (int a = 0; a < 3; ++a)
        if (std::abs(bounds.min[a]) > kMaxMeshCoordinate || std::abs(bounds.max[a]) > kMaxMeshCoordinate)
            throw Error("mesh voxelisation: grid bounds must lie within +-1e18 m (distances beyond ~1.8e19 m overflow float)");
    for (int a = 0; a < 3; ++a)
        if (res[a] < 1) throw Error("mesh voxelisation: resolution must be >= 1 on every axis");
    // Vertices in continuous voxel index space: voxel centres at integers.
    std::vector<Vec3d> pv(m.vertices.size());
    Vec3d h;
    for (int a = 0; a < 3; ++a) h[a] = (bounds.max[a] - bounds.min[a]) / res[a];
    for (size_t i = 0; i < pv.size(); ++i)
        for (int a = 0; a < 3; ++a) pv[i][a] = (double(m.vertices[i][a]) - bounds.min[a]) / h[a] - 0.5;
    MeshLineHits out;
    for (int a = 0; a < 3; ++a) {
        out.axis[a] = hits_along(m, pv, res, a);
        out.total += out.axis[a].t.size();
    }
    return out;
}

std::vector<float> ray_winding_vote(const MeshLineHits& hits, Vec3i res, const Mesh& mesh, Box3d bounds, uint64_t* fallback_voxels) {
    const size_t stride[3] = {1, size_t(res[0]), size_t(res[0]) * size_t(res[1])};
    const size_t count = stride[2] * size_t(res[2]);
    std::vector<float> sum(count, 0.0f);
    // First count seen per voxel, and whether any later count differed.
    std::vector<int16_t> first(count, std::numeric_limits<int16_t>::min());
    std::vector<uint8_t> disagree(count, 0);
    auto record = [&](size_t v, int w) {
        const int16_t c = int16_t(std::clamp(w, -32000, 32000));
        if (first[v] == std::numeric_limits<int16_t>::min()) first[v] = c;
        else if (first[v] != c) disagree[v] = 1;
        sum[v] += float(w);
    };
    for (int a = 0; a < 3; ++a) {
        int b, c;
        other_axes(a, b, c);
        const AxisHits& ah = hits.axis[a];
        // Parallel over c: lines with different c touch disjoint voxels.
        parallel_for_index(res[c], [&](int j) {
            for (int i = 0; i < res[b]; ++i) {
                const uint32_t l = uint32_t(i) + uint32_t(j) * uint32_t(res[b]);
                const uint32_t k0 = ah.offsets[l], k1 = ah.offsets[l + 1];
                int total = 0;
                for (uint32_t k = k0; k < k1; ++k) total += ah.sign[k];
                const size_t base = size_t(i) * stride[b] + size_t(j) * stride[c];
                int below = 0; // sum of signs of hits with t <= x
                uint32_t k = k0;
                for (int x = 0; x < res[a]; ++x) {
                    while (k < k1 && ah.t[k] <= x) below += ah.sign[k++];
                    // From -inf: below. From +inf: -(sum of hits beyond x) = -(total - below).
                    const size_t v = base + size_t(x) * stride[a];
                    record(v, below);
                    record(v, -(total - below));
                }
            }
        });
    }
    for (float& s : sum) s /= 6.0f;
    uint64_t n_disagree = 0;
    for (uint8_t d : disagree) n_disagree += d;
    if (fallback_voxels) *fallback_voxels = n_disagree;
    if (n_disagree == 0) return sum;
    std::vector<size_t> todo;
    todo.reserve(n_disagree);
    for (size_t v = 0; v < count; ++v)
        if (disagree[v]) todo.push_back(v);
    Vec3d h;
    for (int a = 0; a < 3; ++a) h[a] = (bounds.max[a] - bounds.min[a]) / res[a];
    const FastWindingNumber wn(mesh);
    parallel_blocks(todo.size(), 64, [&](size_t k0, size_t k1) {
        for (size_t k = k0; k < k1; ++k) {
            const size_t v = todo[k];
            const size_t x = v % stride[1], y = (v / stride[1]) % size_t(res[1]), z = v / stride[2];
            const Vec3d p{{bounds.min[0] + (double(x) + 0.5) * h[0], bounds.min[1] + (double(y) + 0.5) * h[1],
                           bounds.min[2] + (double(z) + 0.5) * h[2]}};
            sum[v] = float(wn(p));
        }
    });
    return sum;
}

} // namespace atlas::volume::detail
