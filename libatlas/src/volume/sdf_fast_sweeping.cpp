// SDF by OpenVDB's fast sweeping (tools::fogToSdf) over a fully active dense grid.
#include "atlas/core/memory.h"
#include "atlas/volume/sdf.h"
#include "surface_crossings.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/FastSweeping.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace atlas::volume {

Field3D sdf_from_density_fast_sweeping(const Field3D& density, const SdfOptions& o, int sweeps, const MemoryBudget* budget,
                                       SdfStats* stats) {
    const auto t0 = std::chrono::steady_clock::now();
    detail::check_density(density, o, "sdf (fast sweeping)");
    if (!std::isfinite(o.max_distance) || o.max_distance < 0)
        throw Error("sdf (fast sweeping): max_distance must be finite and >= 0, got " + std::to_string(o.max_distance));
    if (sweeps < 1) throw Error("sdf (fast sweeping): sweeps must be >= 1, got " + std::to_string(sweeps));
    const Vec3d h = density.voxel_size();
    if (std::abs(h[0] - h[1]) > 1e-9 * h[0] || std::abs(h[0] - h[2]) > 1e-9 * h[0])
        throw Error("sdf (fast sweeping): OpenVDB needs cubic voxels; this grid's voxels are " + std::to_string(h[0]) + " x " +
                    std::to_string(h[1]) + " x " + std::to_string(h[2]) + " m (use the edt method)");
    const Vec3i res = density.resolution();
    const size_t count = density.voxel_count();
    // A sparse copy costs about as much as the dense input again, plus the output.
    if (budget) budget->check(field_bytes(count, 4), "sdf (fast sweeping): VDB copies of the grid");
    openvdb::initialize();
    Field3D out(res, 1, density.bounds(), {"sdf"}, budget);
    const float iso = float(o.iso);
    auto dens = density.channel(o.channel);

    uint64_t crossings = 0;
    bool any_inside = false, any_outside = false;
    for (size_t i = 0; i < count; ++i) (detail::is_inside(dens[i], iso) ? any_inside : any_outside) = true;
    if (!any_outside) {
        // fogToSdf refuses a grid with no outside voxel; its answer would be the
        // distance to the grid faces, which the EDT gives exactly.
        SdfOptions faces = o;
        faces.border_is_outside = true;
        return sdf_from_density_edt(density, faces, budget, stats);
    }
    if (!any_inside) {
        // No surface: fogToSdf has nothing to sweep from; same answer as the EDT.
        const float far = o.max_distance > 0 ? float(o.max_distance) : float(detail::far_value(density, o));
        std::fill(out.channel(0).begin(), out.channel(0).end(), far);
    } else {
        const openvdb::CoordBBox box(openvdb::Coord(0, 0, 0), openvdb::Coord(res[0] - 1, res[1] - 1, res[2] - 1));
        // LayoutXYZ: x fastest, matching Field3D.
        openvdb::tools::Dense<const float, openvdb::tools::LayoutXYZ> in(box, dens.data());
        auto fog = openvdb::FloatGrid::create(0.0f);
        // OpenVDB's sweep treats any neighbour distance >= 1000 (world units)
        // as unknown (FastSweeping.h, NN::operator bool), so in metres every
        // distance beyond ~1000 m was left at its initial value. Sweep in
        // scaled index units instead - a power of two small enough that the
        // grid diagonal stays below 500 - and scale to metres afterwards. The
        // scheme is homogeneous in the voxel size, so only rounding changes.
        const double diag_voxels = std::sqrt(double(res[0]) * res[0] + double(res[1]) * res[1] + double(res[2]) * res[2]);
        double unit = 1.0;
        while (diag_voxels * unit >= 500.0) unit *= 0.5;
        auto xf = openvdb::math::Transform::createLinearTransform(unit);
        fog->setTransform(xf);
        // Negative tolerance keeps every voxel active (no value equals background within it).
        openvdb::tools::copyFromDense(in, *fog, -1.0f);
        auto sdf = openvdb::tools::fogToSdf(*fog, iso, sweeps);
        openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dst(box, out.channel(0).data());
        openvdb::tools::copyToDense(*sdf, dst);
        // Back to metres; keep the sign convention exact (density > iso is
        // inside) even where the sweep left a zero.
        auto s = out.channel(0);
        const double to_metres = h[0] / unit;
        for (size_t i = 0; i < count; ++i) {
            const bool inside = detail::is_inside(dens[i], iso);
            if (!std::isfinite(s[i]) || std::abs(double(s[i])) >= 1000.0)
                throw Error("sdf (fast sweeping): OpenVDB left voxel (" + std::to_string(i % size_t(res[0])) + ", " +
                            std::to_string((i / size_t(res[0])) % size_t(res[1])) + ", " + std::to_string(i / (size_t(res[0]) * size_t(res[1]))) +
                            ") without a distance (use the edt method)");
            float m = float(double(std::abs(s[i])) * to_metres);
            if (o.max_distance > 0) m = std::min(m, float(o.max_distance));
            s[i] = inside ? -m : m;
        }
        for (int z = 0; z < res[2]; ++z)
            for (int y = 0; y < res[1]; ++y)
                for (int x = 0; x + 1 < res[0]; ++x) {
                    const size_t i = density.index(x, y, z);
                    crossings += detail::is_inside(dens[i], iso) != detail::is_inside(dens[i + 1], iso);
                }
    }
    if (stats) {
        stats->crossings = crossings; // x-edges only: a statistic, not a guarantee
        stats->seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    }
    return out;
}

} // namespace atlas::volume
