// 2.5D NDF set -> 3D dimensional profile.
#include "atlas/ndf/bake.h"
#include "atlas/ndf/ndf_set.h"

#include "atlas/core/error.h"

#include "atlas/core/parallel.h"

#include <cmath>

namespace atlas::ndf {

double bake_formula(BakeFormula formula, const VerticalProfile& profile, double coverage, double top_type, double bottom_type,
                    double min_height, double max_height, double z) {
    if (!(max_height > min_height)) return 0.0;
    const double f = (z - min_height) / (max_height - min_height);
    if (!(f >= 0.0 && f <= 1.0)) return 0.0;
    const double cov = std::isnan(coverage) ? 0.0 : std::clamp(coverage, 0.0, 1.0);
    if (formula == BakeFormula::Envelope) return cov * f * f * std::pow(1.0 - f, 1.5);
    return cov * profile.split(top_type, bottom_type, f);
}

Field3D bake_ndf_set(const Field2D& set, BakeFormula formula, const VerticalProfile& profile, Vec3i res, Box3d bounds,
                     const MemoryBudget* budget) {
    check_ndf_set(set);
    profile.validate();
    if (!bounds.valid()) throw Error("ndf bake: bounds must be finite with max > min");
    Field3D out(res, 1, bounds, {"dimensional_profile"}, budget);
    auto dst = out.channel(0);
    parallel_for_index(res[1], [&](int y) {
        for (int x = 0; x < res[0]; ++x) {
            const Vec3d c = out.voxel_center(x, y, 0);
            const Vec2d p{{c[0], c[1]}};
            const double cov = set.sample_world(Coverage, p, WrapMode::Clamp);
            const double tt = set.sample_world(TopType, p, WrapMode::Clamp);
            const double bt = set.sample_world(BottomType, p, WrapMode::Clamp);
            const double lo = set.sample_world(MinHeight, p, WrapMode::Clamp);
            const double hi = set.sample_world(MaxHeight, p, WrapMode::Clamp);
            for (int k = 0; k < res[2]; ++k)
                dst[out.index(x, y, k)] = float(bake_formula(formula, profile, cov, tt, bt, lo, hi, out.voxel_center(x, y, k)[2]));
        }
    });
    return out;
}

} // namespace atlas::ndf
