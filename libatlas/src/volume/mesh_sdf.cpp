// Mesh inside test and signed distance over a grid.
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/core/parallel.h"
#include "atlas/volume/mesh_repair.h"
#include "atlas/volume/mesh_voxelize.h"
#include "closest_point_flood.h"
#include "mesh_line_hits.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>

namespace atlas::volume {
namespace {

Vec3d to_d(const Vec3f& v) { return {{v[0], v[1], v[2]}}; }

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection 5.1.5).
Vec3d closest_on_triangle(const Vec3d& p, const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const Vec3d ab = b - a, ac = c - a, ap = p - a;
    const double d1 = dot(ab, ap), d2 = dot(ac, ap);
    if (d1 <= 0 && d2 <= 0) return a;
    const Vec3d bp = p - b;
    const double d3 = dot(ab, bp), d4 = dot(ac, bp);
    if (d3 >= 0 && d4 <= d3) return b;
    const double vc = d1 * d4 - d3 * d2;
    if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + ab * (d1 / (d1 - d3));
    const Vec3d cp = p - c;
    const double d5 = dot(ab, cp), d6 = dot(ac, cp);
    if (d6 >= 0 && d5 <= d6) return c;
    const double vb = d5 * d2 - d1 * d6;
    if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + ac * (d2 / (d2 - d6));
    const double va = d3 * d6 - d5 * d4;
    if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    const double den = va + vb + vc;
    if (!(den > 0)) return a; // degenerate (zero-area) triangle: fall back to a corner
    return a + ab * (vb / den) + ac * (vc / den);
}

double diagonal(const Box3d& b) { return length(b.size()); }

// A triangle at a voxel's distance (squared) in the exact band's outer layer.
struct BandRecord {
    uint64_t voxel;
    float e;
    uint32_t triangle;
};

// Exact band (voxels) around rims and near the grid's faces.
constexpr double kWideBandVoxels = 4;

Vec3d closest_on_segment(const Vec3d& p, const Vec3d& a, const Vec3d& b) {
    const Vec3d e = b - a;
    const double ee = dot(e, e);
    if (!(ee > 0)) return a;
    return a + e * std::clamp(dot(p - a, e) / ee, 0.0, 1.0);
}

} // namespace

namespace detail {

double straddling_squared_distance(const Mesh& m, const UnionSurface& us, uint32_t ti, const Vec3d& p, Vec3d* closest) {
    const auto& t = m.triangles[ti];
    const Vec3d v[3] = {to_d(m.vertices[t[0]]), to_d(m.vertices[t[1]]), to_d(m.vertices[t[2]])};
    double best = std::numeric_limits<double>::infinity();
    auto offer = [&](const Vec3d& q) {
        const double e = dot(q - p, q - p);
        if (e < best) {
            best = e;
            if (closest) *closest = q;
        }
    };
    const Vec3d q = closest_on_triangle(p, v[0], v[1], v[2]);
    if (!us.point_buried(m, ti, q)) offer(q);
    else {
        for (int k = 0; k < 3; ++k) {
            if (!us.corner_buried[ti][size_t(k)]) offer(v[k]);
            const Vec3d qe = closest_on_segment(p, v[k], v[(k + 1) % 3]);
            if (dot(qe - p, qe - p) < best && !us.point_buried(m, ti, qe)) offer(qe);
        }
        for (const auto& sg : us.segments[ti]) offer(closest_on_segment(p, sg[0], sg[1]));
    }
    return best;
}

} // namespace detail

double winding_number(const Mesh& m, Vec3d p) {
    validate_mesh(m, "winding_number");
    // Van Oosterom & Strackee: tan(omega/2) = det / (|a||b||c| + (a.b)|c| + (b.c)|a| + (c.a)|b|).
    double sum = 0;
    for (const auto& t : m.triangles) {
        const Vec3d a = to_d(m.vertices[t[0]]) - p, b = to_d(m.vertices[t[1]]) - p, c = to_d(m.vertices[t[2]]) - p;
        const double la = length(a), lb = length(b), lc = length(c);
        const double det = dot(a, cross(b, c));
        const double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
        sum += 2 * std::atan2(det, den);
    }
    return sum / (4 * std::numbers::pi);
}

Field3D mesh_winding_field(const Mesh& m, Vec3i res, Box3d bounds, const MemoryBudget* budget) {
    if (budget) budget->check(field_bytes(uint64_t(res[0]) * res[1] * res[2], 2), "mesh winding field");
    const detail::MeshLineHits hits = detail::mesh_line_hits(m, res, bounds);
    Field3D out(res, 1, bounds, {"winding"}, budget);
    const std::vector<float> w = detail::ray_winding_vote(hits, res, m, bounds);
    std::copy(w.begin(), w.end(), out.channel(0).begin());
    return out;
}

Field3D mesh_to_sdf(const Mesh& m, Vec3i res, Box3d bounds, const MeshSdfOptions& o, const MemoryBudget* budget, MeshSdfStats* stats) {
    const auto t0 = std::chrono::steady_clock::now();
    if (!(o.exact_band_voxels >= 0) || !std::isfinite(o.exact_band_voxels))
        throw Error("mesh_to_sdf: exact_band_voxels must be finite and >= 0");
    if (!std::isfinite(o.far_distance) || std::abs(o.far_distance) > kMaxMeshCoordinate)
        throw Error("mesh_to_sdf: far_distance must be finite and within 1e18 m");
    const uint64_t count = uint64_t(res[0]) * res[1] * res[2];
    if (budget) budget->check(field_bytes(count, 3), "mesh_to_sdf: output, EDT grid and ray counts");
    // The grid-line crossings and (overlapping parts: distances go to the union's surface
    // only) the union's surface, side by side: the latter's box intersection is serial.
    validate_mesh(m, "mesh voxelisation");
    detail::MeshLineHits hits;
    detail::UnionSurface us;
    parallel_invoke([&] { hits = detail::mesh_line_hits(m, res, bounds); }, [&] { us = detail::union_surface(m); });
    Field3D out(res, 1, bounds, {"sdf"}, budget);
    const Vec3d h = out.voxel_size();

    // Near field: exact distances to the union's surface within the band, lowering
    // the whole-grid EDT's squared distances (detail::mesh_signed_distance).
    // Triangles wholly on the surface: point-triangle distance (parallel over
    // triangles, an atomic min per voxel: the min is order-independent). Buried
    // triangles: none. Straddling triangles: the nearest point of their unburied part,
    // which is the triangle's closest point if unburied, else on an edge, a corner
    // or an intersection segment (parallel per triangle, merged in order).
    // Beyond the band: the grid-line crossings' EDT, lowered by the band's closest
    // points carried outwards (detail::flood_closest_points): the voxels of the band's
    // outer layer record which triangle is at their distance (every tied one, so the
    // records do not depend on which thread came first).
    const double vmin = std::min({h[0], h[1], h[2]});
    const double band = o.exact_band_voxels * vmin;
    // Where grid-line crossings are sparse - beyond an open rim, and where the
    // surface leaves the grid (no grid lines out there) - the EDT over-estimates
    // by up to ~0.8 voxel next to the band; triangles with a boundary edge or
    // near the grid's faces get a wider exact band, where the over-estimate
    // has decayed (roughly gap^2 / 2d) below 0.5 voxel (docs/volumes.md).
    const double wide = band > 0 ? std::max(band, kWideBandVoxels * vmin) : 0;
    std::vector<uint8_t> needs_wide(m.triangles.size(), 0);
    if (band > 0) {
        std::vector<std::pair<uint64_t, uint32_t>> edges;
        edges.reserve(m.triangles.size() * 3);
        for (uint32_t t = 0; t < m.triangles.size(); ++t)
            for (int e = 0; e < 3; ++e) {
                const uint64_t a = m.triangles[t][size_t(e)], b = m.triangles[t][size_t((e + 1) % 3)];
                edges.push_back({std::min(a, b) << 32 | std::max(a, b), t});
            }
        std::sort(edges.begin(), edges.end());
        for (size_t i = 0; i < edges.size(); ++i) {
            const bool alone = (i == 0 || edges[i - 1].first != edges[i].first) && (i + 1 == edges.size() || edges[i + 1].first != edges[i].first);
            if (alone) needs_wide[edges[i].second] = 1;
        }
        for (uint32_t t = 0; t < m.triangles.size(); ++t)
            for (uint32_t v : m.triangles[t])
                for (int k = 0; k < 3; ++k)
                    if (m.vertices[v][k] < bounds.min[k] + wide || m.vertices[v][k] > bounds.max[k] - wide) needs_wide[t] = 1;
    }
    uint64_t wide_triangles = 0;
    for (uint8_t w : needs_wide) wide_triangles += w;
    auto voxel_range = [&](const Vec3d& a, const Vec3d& b, const Vec3d& c, int lo[3], int hi[3], double bw) {
        bool empty = false;
        for (int k = 0; k < 3; ++k) {
            const double mn = std::min({a[k], b[k], c[k]}) - bw, mx = std::max({a[k], b[k], c[k]}) + bw;
            lo[k] = std::max(0, int(std::ceil((mn - bounds.min[k]) / h[k] - 0.5)));
            hi[k] = std::min(res[k] - 1, int(std::floor((mx - bounds.min[k]) / h[k] - 0.5)));
            empty |= lo[k] > hi[k];
        }
        return !empty;
    };
    std::vector<uint32_t> straddling;
    if (band > 0 && !us.trivial())
        for (uint32_t ti = 0; ti < m.triangles.size(); ++ti)
            if (us.state[ti] == detail::UnionSurface::kStraddling) straddling.push_back(ti);
    // Field3D::voxel_center's arithmetic, inline.
    auto centre_of = [&](int x, int y, int z) {
        return Vec3d{{bounds.min[0] + (x + 0.5) * h[0], bounds.min[1] + (y + 0.5) * h[1], bounds.min[2] + (z + 0.5) * h[2]}};
    };
    // Squared distance beyond which a voxel lies in the outer layer (the last voxel) of a
    // triangle's exact band bw: its closest point seeds the flood (closest_point_flood.h).
    auto outer_layer2 = [&](double bw) { return float(std::max(0.0, bw - vmin) * std::max(0.0, bw - vmin)); };
    std::vector<detail::ClosestPointSeed> seeds;
    auto exact_band = [&](float* d2) {
        if (!(band > 0)) return;
        // Triangles in z-order of their centres (voxel units, z, y, x ascending in
        // 16-voxel bricks), so that neighbours touch the same cache lines of the grid.
        std::vector<std::pair<uint64_t, uint32_t>> order(m.triangles.size());
        parallel_for_each(m.triangles.size(), 4096, [&](size_t ti) {
            const auto& t = m.triangles[ti];
            uint64_t key = 0;
            for (int k = 2; k >= 0; --k) {
                const double c = (double(m.vertices[t[0]][k]) + m.vertices[t[1]][k] + m.vertices[t[2]][k]) / 3.0;
                const double v = std::clamp((c - bounds.min[k]) / h[k], 0.0, double(res[k]));
                key = key << 21 | (uint64_t(v) >> 4);
            }
            order[ti] = {key, uint32_t(ti)};
        });
        std::sort(order.begin(), order.end());
        constexpr size_t kBlock = 256;
        std::vector<std::vector<BandRecord>> records(block_count(order.size(), kBlock) + 1);
        parallel_blocks(order.size(), kBlock, [&](size_t o0, size_t o1) {
            std::vector<BandRecord>& rec = records[o0 / kBlock];
            for (size_t oi = o0; oi < o1; ++oi) {
                const uint32_t ti = order[oi].second;
                if (!us.trivial() && us.state[ti] != detail::UnionSurface::kSurface) continue;
                const auto& t = m.triangles[ti];
                const Vec3d a = to_d(m.vertices[t[0]]), b = to_d(m.vertices[t[1]]), c = to_d(m.vertices[t[2]]);
                int lo[3], hi[3];
                const double bw = needs_wide[ti] ? wide : band;
                if (!voxel_range(a, b, c, lo, hi, bw)) continue;
                // Beyond its band a triangle writes nothing: the flood's points reach there
                // (a value written there without its point would stop the flood short).
                const float layer2 = outer_layer2(bw), top2 = float(bw * bw);
                // The distance to the triangle's plane is a lower bound of the distance to it:
                // where its square is already above the voxel's value (an upper bound: the
                // EDT's) or the band's, the triangle cannot lower it (with a margin for
                // rounding, so the result is that of the full loop).
                const Vec3d nrm = cross(b - a, c - a);
                const double nn = dot(nrm, nrm);
                const bool planar = nn > 0 && std::isfinite(nn);
                const Vec3d u = planar ? nrm / std::sqrt(nn) : Vec3d{{0, 0, 0}};
                for (int z = lo[2]; z <= hi[2]; ++z)
                    for (int y = lo[1]; y <= hi[1]; ++y)
                        for (int x = lo[0]; x <= hi[0]; ++x) {
                            const Vec3d p = centre_of(x, y, z);
                            std::atomic_ref<float> cur(d2[out.index(x, y, z)]);
                            float now = cur.load(std::memory_order_relaxed);
                            if (planar) {
                                const double pd = dot(p - a, u);
                                if (pd * pd * (1 - 1e-6) >= std::min(double(now), double(top2))) continue;
                            }
                            const Vec3d q = closest_on_triangle(p, a, b, c) - p;
                            const float e = float(dot(q, q));
                            if (e > now || e > top2) continue;
                            while (e < now && !cur.compare_exchange_weak(now, e, std::memory_order_relaxed)) {}
                            // Ties (e == now) too: whichever thread came first, every triangle
                            // at the voxel's final distance leaves a record.
                            if (e >= layer2) rec.push_back({out.index(x, y, z), e, ti});
                        }
            }
        });
        if (!straddling.empty()) {
            std::vector<std::vector<std::pair<size_t, float>>> found(straddling.size());
            parallel_for_each(straddling.size(), 1, [&](size_t si) {
                const uint32_t ti = straddling[si];
                const auto& t = m.triangles[ti];
                const Vec3d v[3] = {to_d(m.vertices[t[0]]), to_d(m.vertices[t[1]]), to_d(m.vertices[t[2]])};
                int lo[3], hi[3];
                const double bw = needs_wide[ti] ? wide : band;
                if (!voxel_range(v[0], v[1], v[2], lo, hi, bw)) return;
                for (int z = lo[2]; z <= hi[2]; ++z)
                    for (int y = lo[1]; y <= hi[1]; ++y)
                        for (int x = lo[0]; x <= hi[0]; ++x) {
                            const float e = float(detail::straddling_squared_distance(m, us, ti, out.voxel_center(x, y, z)));
                            if (e <= float(bw * bw)) found[si].push_back({out.index(x, y, z), e});
                        }
            });
            std::vector<BandRecord>& rec = records.back();
            for (size_t si = 0; si < straddling.size(); ++si) {
                const float layer2 = outer_layer2(needs_wide[straddling[si]] ? wide : band);
                for (const auto& [i, e] : found[si]) {
                    d2[i] = std::min(d2[i], e);
                    if (e >= layer2) rec.push_back({i, e, straddling[si]});
                }
            }
        }
        // The outer layer's closest points: each voxel's records at its final distance
        // (ties: all of them, in block order; equal points in practice, and the flood
        // takes them in a fixed order), then their points.
        parallel_for_each(records.size(), 1, [&](size_t bi) {
            std::erase_if(records[bi], [&](const BandRecord& r) { return r.e != d2[r.voxel]; });
        });
        size_t total = 0;
        for (const auto& r : records) total += r.size();
        seeds.resize(total);
        std::vector<size_t> start(records.size() + 1, 0);
        for (size_t bi = 0; bi < records.size(); ++bi) start[bi + 1] = start[bi] + records[bi].size();
        parallel_for_each(records.size(), 1, [&](size_t bi) {
            for (size_t k = 0; k < records[bi].size(); ++k) {
                const BandRecord& r = records[bi][k];
                const size_t v = r.voxel;
                const int x = int(v % size_t(res[0])), y = int(v / size_t(res[0]) % size_t(res[1])), z = int(v / (size_t(res[0]) * size_t(res[1])));
                const Vec3d p = centre_of(x, y, z);
                const auto& t = m.triangles[r.triangle];
                Vec3d q;
                if (!us.trivial() && us.state[r.triangle] == detail::UnionSurface::kStraddling)
                    detail::straddling_squared_distance(m, us, r.triangle, p, &q);
                else q = closest_on_triangle(p, to_d(m.vertices[t[0]]), to_d(m.vertices[t[1]]), to_d(m.vertices[t[2]]));
                seeds[start[bi] + k] = {v, q};
            }
        });
    };
    // Far field: exact EDT to the crossing points on the grid lines; sign from the vote.
    const float far = float(o.far_distance > 0 ? o.far_distance : diagonal(bounds));
    const uint64_t fallback = detail::mesh_signed_distance(hits, us, m, res, bounds, far, out.channel(0).data(), exact_band);
    // Beyond the band: the band's closest points carried outwards (no seeds without a band).
    detail::flood_closest_points(out.channel(0).data(), res, bounds, seeds);
    if (stats) {
        stats->line_hits = hits.total;
        stats->winding_fallback_voxels = fallback;
        stats->wide_band_triangles = wide_triangles;
        stats->buried_triangles = us.buried;
        stats->straddling_triangles = us.straddling;
        stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    return out;
}

Field3D density_from_sdf(const Field3D& sdf, int channel) {
    if (channel < 0 || channel >= sdf.channels()) throw Error("density_from_sdf: channel " + std::to_string(channel) + " does not exist");
    const Vec3d h = sdf.voxel_size();
    const double vmin = std::min({h[0], h[1], h[2]});
    Field3D out(sdf.resolution(), 1, sdf.bounds(), {"density"});
    auto s = sdf.channel(channel);
    auto d = out.channel(0);
    for (size_t i = 0; i < s.size(); ++i) d[i] = float(std::clamp(0.5 - double(s[i]) / vmin, 0.0, 1.0));
    return out;
}

} // namespace atlas::volume
