// A superstorm's lightning schedule (lightning.h).
#include "atlas/ndf/lightning.h"

#include "atlas/core/error.h"
#include "atlas/core/option_schema.h"
#include "atlas/core/hash.h"

#include <algorithm>
#include <cmath>

namespace atlas::ndf {

namespace {


void check(bool ok, const std::string& what, double v, const std::string& range) {
    if (!ok) throw Error("lightning: " + what + " = " + detail::number_text(v) + " is out of range " + range);
}

// A uniform number in [0, 1) for slot k, draw `what` (hash chain over the 64-bit slot index).
double draw(uint32_t seed, int64_t k, uint32_t what) {
    const auto lo = int32_t(uint32_t(uint64_t(k))), hi = int32_t(uint32_t(uint64_t(k) >> 32));
    return double(hash_to_unit(hash_coords(seed, lo, hi, int32_t(what), 0x11a7u)));
}

// The columns flashes can come from: the storm's channel, as a cumulative sum over texels.
struct Columns {
    const Field2D* set = nullptr;
    int channel = -1, min_height = -1, max_height = -1;
    std::vector<double> cdf; // running sum of the channel, texel order
};

Columns storm_columns(const Field2D& set) {
    Columns c;
    c.set = &set;
    c.min_height = set.find_channel("min_height");
    c.max_height = set.find_channel("max_height");
    if (c.min_height < 0 || c.max_height < 0) throw Error("lightning: the NDF set has no min_height/max_height channels to place flashes in");
    for (const char* name : {"superstorm_coverage", "precipitation", "coverage"}) {
        const int ch = set.find_channel(name);
        if (ch < 0) continue;
        const auto d = set.channel(ch);
        if (std::any_of(d.begin(), d.end(), [](float v) { return v > 0; })) {
            c.channel = ch;
            break;
        }
    }
    if (c.channel < 0) return c; // nothing to flash in
    c.cdf.resize(set.voxel_count());
    double sum = 0;
    const auto d = set.channel(c.channel);
    // Weighted by the column's depth squared: flash rates climb steeply with convective depth
    // (Price and Rind 1992: about the 5th power of the cloud top), so the deep tower flashes and
    // the anvil sheet, storm channel too but 2-3 km thin, rarely does.
    const auto lo = set.channel(c.min_height), hi = set.channel(c.max_height);
    for (size_t i = 0; i < d.size(); ++i) {
        const double depth_km = std::max(0.0, double(hi[i]) - double(lo[i])) * 1e-3;
        c.cdf[i] = sum += std::max(0.0, double(d[i])) * depth_km * depth_km;
    }
    return c;
}

} // namespace

std::vector<Flash> lightning_schedule(const Field2D& set, const LightningOptions& o) {
    check(std::isfinite(o.time) && std::abs(o.time) <= 1e9, "time", o.time, "[-1e9, 1e9] s");
    check(o.window > 0 && o.window <= 86400, "window", o.window, "(0, 86400] s");
    check(o.rate >= 0 && o.rate <= 60, "rate", o.rate, "[0, 60] per minute");
    check(o.intra_flashes >= 0 && o.intra_flashes <= 16, "intra_flashes", o.intra_flashes, "[0, 16]");
    check(o.ground_max >= 0 && o.ground_max <= 4, "ground_max", o.ground_max, "[0, 4]");
    check(o.spacing > 0 && o.spacing <= 10, "spacing", o.spacing, "(0, 10] s");
    check(o.duration > 0 && o.duration <= 10, "duration", o.duration, "(0, 10] s");
    check(o.intensity >= 0 && std::isfinite(o.intensity), "intensity", o.intensity, "[0, inf)");
    const Columns cols = storm_columns(set);
    std::vector<Flash> out;
    if (cols.channel < 0 || cols.cdf.back() <= 0 || o.rate == 0 || o.intra_flashes + o.ground_max == 0) return out;
    // Slots whose sequences can reach into the window: started up to a sequence's length before it.
    const double length = (o.intra_flashes + o.ground_max) * o.spacing;
    const int64_t k0 = int64_t(std::floor(o.time - length)) - 1, k1 = int64_t(std::floor(o.time + o.window));
    const double end = o.time + o.window;
    for (int64_t k = k0; k <= k1; ++k) {
        if (draw(o.seed, k, 0) >= o.rate / 60) continue;
        const double start = double(k) + draw(o.seed, k, 1);
        // The sequence's column: texel i with probability channel(i) / sum.
        const double pick = draw(o.seed, k, 2) * cols.cdf.back();
        const size_t i = size_t(std::upper_bound(cols.cdf.begin(), cols.cdf.end(), pick) - cols.cdf.begin());
        const size_t texel = std::min(i, cols.cdf.size() - 1);
        const int x = int(texel % size_t(set.width())), y = int(texel / size_t(set.width()));
        const double base = set.at(cols.min_height, x, y), top = std::max(base, double(set.at(cols.max_height, x, y)));
        const Vec2d texel_size{{set.bounds().size()[0] / set.width(), set.bounds().size()[1] / set.height()}};
        const int ground = o.ground_max > 0 ? 1 + int(draw(o.seed, k, 3) * o.ground_max) : 0;
        const int n = o.intra_flashes + ground;
        for (int f = 0; f < n; ++f) {
            Flash fl;
            fl.time = start + f * o.spacing;
            if (fl.time < o.time || fl.time >= end) continue;
            fl.duration = o.duration;
            fl.sequence = k;
            fl.ground = f >= o.intra_flashes;
            const Vec2d c = set.texel_center(x, y);
            const double jx = draw(o.seed, k, 10 + 3 * uint32_t(f)) - 0.5, jy = draw(o.seed, k, 11 + 3 * uint32_t(f)) - 0.5;
            const double up = 0.3 + 0.3 * draw(o.seed, k, 12 + 3 * uint32_t(f));
            fl.position = {{c[0] + jx * texel_size[0], c[1] + jy * texel_size[1], fl.ground ? base : base + up * (top - base)}};
            // 000: the intra-cloud flashes grow in intensity before the ground discharge.
            fl.intensity = fl.ground ? o.intensity : o.intensity * 0.5 * double(f + 1) / double(o.intra_flashes);
            out.push_back(fl);
        }
    }
    std::stable_sort(out.begin(), out.end(), [](const Flash& a, const Flash& b) { return a.time < b.time; });
    return out;
}

Field2D lightning_table(const std::vector<Flash>& flashes, const Box2d& bounds) {
    const int n = std::max<int>(1, int(flashes.size()));
    Field2D t({{n, 1}}, 8, bounds, {"time", "duration", "x", "y", "z", "intensity", "ground", "sequence"});
    if (flashes.empty()) t.at(0, 0, 0) = -1;
    for (size_t i = 0; i < flashes.size(); ++i) {
        const Flash& f = flashes[i];
        int c = 0;
        for (double v : {f.time, f.duration, f.position[0], f.position[1], f.position[2], f.intensity, f.ground ? 1.0 : 0.0, double(f.sequence)})
            t.at(c++, int(i), 0) = float(v);
    }
    return t;
}

} // namespace atlas::ndf
