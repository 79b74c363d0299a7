// Mesh SDF: OpenVDB's exact narrow band (meshToUnsignedDistanceField), the exact EDT to the
// grid-line crossings beyond it, sign from the ray winding vote.
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/core/parallel.h"
#include "atlas/volume/mesh_repair.h"
#include "atlas/volume/mesh_voxelize.h"
#include "mesh_line_hits.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <openvdb/tree/LeafManager.h>

#include <algorithm>

#include <chrono>
#include <cmath>

namespace atlas::volume {

Field3D mesh_to_sdf_openvdb(const Mesh& m, Vec3i res, Box3d bounds, const MemoryBudget* budget, MeshSdfStats* stats) {
    const auto t0 = std::chrono::steady_clock::now();
    validate_mesh(m, "mesh_to_sdf_openvdb");
    if (budget) budget->check(field_bytes(uint64_t(res[0]) * res[1] * res[2], 6), "mesh_to_sdf_openvdb: grids");
    // The grid-line crossings and the union's surface (below), side by side.
    detail::MeshLineHits hits;
    detail::UnionSurface us;
    parallel_invoke([&] { hits = detail::mesh_line_hits(m, res, bounds); }, [&] { us = detail::union_surface(m); });
    Field3D out(res, 1, bounds, {"sdf"}, budget);
    const Vec3d h = out.voxel_size();
    if (std::abs(h[0] - h[1]) > 1e-9 * h[0] || std::abs(h[0] - h[2]) > 1e-9 * h[0])
        throw Error("mesh_to_sdf_openvdb: OpenVDB needs cubic voxels");
    openvdb::initialize();
    auto xf = openvdb::math::Transform::createLinearTransform(h[0]);
    xf->postTranslate(openvdb::Vec3d(bounds.min[0] + 0.5 * h[0], bounds.min[1] + 0.5 * h[1], bounds.min[2] + 0.5 * h[2]));
    std::vector<openvdb::Vec3s> pts;
    pts.reserve(m.vertices.size());
    for (const Vec3f& v : m.vertices) pts.emplace_back(v[0], v[1], v[2]); // world space
    // Overlapping parts: OpenVDB gets the triangles wholly on the union's surface.
    // Buried ones are left out; straddling ones (partly buried: OpenVDB would measure
    // to their buried part too, short by up to a triangle's size near the seams) are
    // measured here, to their unburied part, and merged into OpenVDB's band.
    std::vector<openvdb::Vec3I> tris;
    std::vector<uint32_t> straddling;
    tris.reserve(m.triangles.size());
    for (size_t i = 0; i < m.triangles.size(); ++i) {
        if (us.trivial() || us.state[i] == detail::UnionSurface::kSurface) tris.emplace_back(m.triangles[i][0], m.triangles[i][1], m.triangles[i][2]);
        else if (us.state[i] == detail::UnionSurface::kStraddling) straddling.push_back(uint32_t(i));
    }
    std::vector<openvdb::Vec4I> quads;
    // Exact unsigned distances in a narrow band (3 voxels), signed by the
    // ray-winding vote (OpenVDB's own sign needs a watertight mesh), then
    // extended over the whole grid by the EDT below.
    const float bandwidth = 3.0f;
    auto grid = tris.empty() ? openvdb::FloatGrid::create(float(bandwidth * h[0]))
                             : openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(*xf, pts, tris, quads, bandwidth);
    grid->setTransform(xf);
    // Straddling triangles: exact distances to their unburied parts within the band
    // (parallel per triangle, merged in triangle order: the min is order-free).
    const double bw = bandwidth * h[0];
    std::vector<std::vector<std::pair<size_t, float>>> found(straddling.size());
    parallel_for_each(straddling.size(), 1, [&](size_t si) {
        const auto& t = m.triangles[straddling[si]];
        int lo[3], hi[3];
        for (int k = 0; k < 3; ++k) {
            const double mn = std::min({double(m.vertices[t[0]][k]), double(m.vertices[t[1]][k]), double(m.vertices[t[2]][k])}) - bw;
            const double mx = std::max({double(m.vertices[t[0]][k]), double(m.vertices[t[1]][k]), double(m.vertices[t[2]][k])}) + bw;
            lo[k] = std::max(0, int(std::ceil((mn - bounds.min[k]) / h[k] - 0.5)));
            hi[k] = std::min(res[k] - 1, int(std::floor((mx - bounds.min[k]) / h[k] - 0.5)));
            if (lo[k] > hi[k]) return;
        }
        for (int z = lo[2]; z <= hi[2]; ++z)
            for (int y = lo[1]; y <= hi[1]; ++y)
                for (int x = lo[0]; x <= hi[0]; ++x) {
                    const double d2 = detail::straddling_squared_distance(m, us, straddling[si], out.voxel_center(x, y, z));
                    if (d2 < bw * bw) found[si].push_back({out.index(x, y, z), float(d2)});
                }
    });
    // OpenVDB's band and the straddling triangles lower the exact EDT to the mesh's
    // (union-boundary) crossings with the grid lines, as `method: edt` (OpenVDB's
    // first-order fast sweeping, maskSdf, over-estimated by up to 0.69 voxel on the
    // CGAL bunny). Both are distances to surface points, never short, so the smaller
    // is the better. Sign from the ray winding vote.
    const openvdb::CoordBBox box(openvdb::Coord(0, 0, 0), openvdb::Coord(res[0] - 1, res[1] - 1, res[2] - 1));
    auto merge_band = [&](float* sq) {
        // Leaf by leaf in parallel (the manager's leaf array, by index): each voxel
        // belongs to one leaf.
        const openvdb::tree::LeafManager<const openvdb::FloatTree> leaves(grid->constTree());
        parallel_for_each(leaves.leafCount(), 1, [&](size_t li) {
            for (auto it = leaves.leaf(li).cbeginValueOn(); it; ++it) {
                const openvdb::Coord c = it.getCoord();
                if (!box.isInside(c)) continue; // beyond the grid
                const float v = std::abs(*it);
                float& e = sq[out.index(c.x(), c.y(), c.z())];
                e = std::min(e, v * v);
            }
        });
        // Active tiles (none in a narrow band in practice), serially.
        for (auto it = grid->cbeginValueOn(); it; ++it) {
            if (it.isVoxelValue()) continue;
            openvdb::CoordBBox tb;
            it.getBoundingBox(tb);
            tb.intersect(box);
            const float v = std::abs(*it);
            for (auto c = tb.begin(); c; ++c) {
                float& e = sq[out.index((*c).x(), (*c).y(), (*c).z())];
                e = std::min(e, v * v);
            }
        }
        for (const auto& f : found)
            for (const auto& [i, e] : f) sq[i] = std::min(sq[i], e);
    };
    const uint64_t fallback = detail::mesh_signed_distance(hits, us, m, res, bounds, float(length(bounds.size())), out.channel(0).data(), merge_band);
    if (stats) {
        stats->line_hits = hits.total;
        stats->winding_fallback_voxels = fallback;
        stats->buried_triangles = us.buried;
        stats->straddling_triangles = us.straddling;
        stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    return out;
}

} // namespace atlas::volume
