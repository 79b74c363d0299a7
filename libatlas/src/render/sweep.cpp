#include "atlas/render/sweep.h"

#include "atlas/core/error.h"

#include <chrono>
#include <cmath>

namespace atlas::render {

double image_rmse(const Field2D& a, const Field2D& b, int first, int count) {
    if (a.resolution() != b.resolution()) throw Error("render: RMSE of images of different sizes");
    if (first < 0 || count <= 0 || first + count > a.channels() || first + count > b.channels())
        throw Error("render: RMSE channel range outside the images");
    double sum = 0;
    for (int c = first; c < first + count; ++c) {
        auto x = a.channel(c), y = b.channel(c);
        for (size_t i = 0; i < x.size(); ++i) {
            const double d = double(x[i]) - double(y[i]);
            sum += d * d;
        }
    }
    return std::sqrt(sum / (double(a.voxel_count()) * count));
}

SweepResult quality_sweep(const CloudScene& scene, const RenderSettings& settings, const std::vector<double>& qualities,
                          const ProgressSink* progress) {
    if (qualities.empty()) throw Error("render: quality sweep needs at least one quality setting");
    using clock = std::chrono::steady_clock;
    SweepResult out;
    RenderSettings ref = settings;
    ref.mode = RenderMode::Reference;
    auto t0 = clock::now();
    out.reference = render_clouds(scene, ref, progress).image;
    out.reference_seconds = std::chrono::duration<double>(clock::now() - t0).count();
    for (double q : qualities) {
        RenderSettings f = settings;
        f.mode = RenderMode::Fast;
        f.quality = q;
        auto t1 = clock::now();
        Field2D img = render_clouds(scene, f, progress).image;
        SweepRow row;
        row.seconds = std::chrono::duration<double>(clock::now() - t1).count();
        row.quality = q;
        row.rmse = image_rmse(img, out.reference, 0, 3);
        row.transmittance_rmse = image_rmse(img, out.reference, 3, 1);
        out.rows.push_back(row);
    }
    return out;
}

} // namespace atlas::render
