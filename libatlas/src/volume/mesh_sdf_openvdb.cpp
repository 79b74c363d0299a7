// Mesh SDF magnitude from OpenVDB (meshToUnsignedDistanceField), sign from the ray winding vote.
#include "atlas/core/error.h"
#include "atlas/core/memory.h"
#include "atlas/volume/mesh_io.h"
#include "atlas/volume/mesh_voxelize.h"
#include "mesh_line_hits.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/FastSweeping.h>
#include <openvdb/tools/MeshToVolume.h>

#include <chrono>
#include <cmath>

namespace atlas::volume {

Field3D mesh_to_sdf_openvdb(const Mesh& m, Vec3i res, Box3d bounds, const MemoryBudget* budget, MeshSdfStats* stats) {
    const auto t0 = std::chrono::steady_clock::now();
    validate_mesh(m, "mesh_to_sdf_openvdb");
    if (budget) budget->check(field_bytes(uint64_t(res[0]) * res[1] * res[2], 6), "mesh_to_sdf_openvdb: grids");
    const detail::MeshLineHits hits = detail::mesh_line_hits(m, res, bounds);
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
    // Overlapping parts: triangles wholly buried in another part are left out
    // (straddling ones are kept whole: near the seams distances may be short
    // by up to a triangle's size).
    const detail::UnionSurface us = detail::union_surface(m);
    std::vector<openvdb::Vec3I> tris;
    tris.reserve(m.triangles.size());
    for (size_t i = 0; i < m.triangles.size(); ++i)
        if (us.trivial() || us.state[i] != detail::UnionSurface::kBuried) tris.emplace_back(m.triangles[i][0], m.triangles[i][1], m.triangles[i][2]);
    std::vector<openvdb::Vec4I> quads;
    // Exact unsigned distances in a narrow band (3 voxels), signed by the
    // ray-winding vote (OpenVDB's own sign needs a watertight mesh), then
    // extended over the whole grid by OpenVDB's fast sweeping (maskSdf).
    const float bandwidth = 3.0f;
    auto grid = openvdb::tools::meshToUnsignedDistanceField<openvdb::FloatGrid>(*xf, pts, tris, quads, bandwidth);
    uint64_t fallback = 0;
    const std::vector<float> vote = detail::ray_winding_vote(hits, res, m, bounds, &fallback);
    const openvdb::CoordBBox box(openvdb::Coord(0, 0, 0), openvdb::Coord(res[0] - 1, res[1] - 1, res[2] - 1));
    for (auto it = grid->beginValueOn(); it; ++it) {
        const openvdb::Coord c = it.getCoord();
        if (!box.isInside(c)) {
            it.setValueOff(); // beyond the grid: no vote there
            continue;
        }
        if (vote[out.index(c.x(), c.y(), c.z())] > 0.5f) it.setValue(-std::abs(*it));
    }
    grid->setGridClass(openvdb::GRID_LEVEL_SET);
    auto s = out.channel(0);
    if (grid->activeVoxelCount() == 0) {
        const float far = float(length(bounds.size()));
        for (size_t i = 0; i < s.size(); ++i) s[i] = vote[i] > 0.5f ? -far : far;
    } else {
        openvdb::MaskGrid mask(false);
        mask.setTransform(xf);
        mask.tree().denseFill(box, true, true);
        auto full = openvdb::tools::maskSdf(*grid, mask);
        openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dst(box, s.data());
        openvdb::tools::copyToDense(*full, dst);
        for (size_t i = 0; i < s.size(); ++i) s[i] = vote[i] > 0.5f ? -std::abs(s[i]) : std::abs(s[i]);
    }
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
