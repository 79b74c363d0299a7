// Cone-step maps: brute force reference and max-mip branch-and-bound.
#include "atlas/ndf/cone_map.h"

#include "atlas/core/error.h"

#include "atlas/core/parallel.h"

#include <cmath>

namespace atlas::ndf {

namespace {
struct Rect {
    double x0, y0, x1, y1;
};

// Euclidean distance between two axis-aligned rectangles (0 when they touch).
// Gaps are differences of small integers / half-integers: exact, so the
// pyramid's bounds never exceed a leaf's value (monotone rounding).
double rect_distance(const Rect& a, const Rect& b) {
    const double gx = std::max({0.0, b.x0 - a.x1, a.x0 - b.x1});
    const double gy = std::max({0.0, b.y0 - a.y1, a.y0 - b.y1});
    return std::sqrt(gx * gx + gy * gy);
}

struct Prepared {
    int w = 0, h = 0;
    std::vector<double> height; // heights in texel units (metres / texel_size)
    std::vector<double> apex;   // apex per texel, texel units
    std::vector<Rect> region;   // apex region per texel
    double at(int x, int y) const { return height[size_t(y) * size_t(w) + size_t(x)]; }
};

double neighbourhood_max(const Field2D& f, int c, int x, int y, int r) {
    double m = -INFINITY;
    for (int j = std::max(0, y - r); j <= std::min(f.height() - 1, y + r); ++j)
        for (int i = std::max(0, x - r); i <= std::min(f.width() - 1, x + r); ++i) m = std::max(m, double(f.at(c, i, j)));
    return m;
}

Prepared prepare(const Field2D& heights, int channel, const ConeMapOptions& opt) {
    if (channel < 0 || channel >= heights.channels()) throw Error("cone map: 'channel' out of range for the height input");
    if (!(opt.texel_size > 0) || !std::isfinite(opt.texel_size)) throw Error("cone map: 'texel_size' must be > 0 and finite");
    if (!(opt.max_ratio > 0) || !std::isfinite(opt.max_ratio)) throw Error("cone map: 'max_ratio' must be > 0 and finite");
    Prepared p;
    p.w = heights.width();
    p.h = heights.height();
    const size_t n = size_t(p.w) * size_t(p.h);
    p.height.resize(n);
    p.apex.resize(n);
    p.region.resize(n);
    for (int y = 0; y < p.h; ++y)
        for (int x = 0; x < p.w; ++x) {
            const size_t i = size_t(y) * size_t(p.w) + size_t(x);
            const double v = heights.at(channel, x, y);
            if (!std::isfinite(v)) throw Error("cone map: heights must be finite (texel " + std::to_string(x) + ", " + std::to_string(y) + ")");
            p.height[i] = v / opt.texel_size;
            if (opt.robust) {
                p.apex[i] = neighbourhood_max(heights, channel, x, y, 1) / opt.texel_size;
                p.region[i] = {x - 0.5, y - 0.5, x + 1.5, y + 1.5};
            } else {
                p.apex[i] = p.height[i];
                p.region[i] = {double(x), double(y), x + 1.0, y + 1.0};
            }
        }
    return p;
}

Field2D make_output(const Field2D& heights, int channel, const ConeMapOptions& opt, const MemoryBudget* budget) {
    if (!opt.robust) return Field2D(heights.resolution(), 1, heights.bounds(), {"cone_ratio"}, budget);
    Field2D out(heights.resolution(), 2, heights.bounds(), {"apex_height", "cone_ratio"}, budget);
    for (int y = 0; y < heights.height(); ++y)
        for (int x = 0; x < heights.width(); ++x) out.at(0, x, y) = float(neighbourhood_max(heights, channel, x, y, 2));
    return out;
}

// Storing as float rounds; round toward zero so the stored cone never widens.
float conservative_float(double r) {
    float f = float(r);
    if (double(f) > r) f = std::nextafter(f, 0.0f);
    return f;
}
} // namespace

double cone_step_length(double ratio, double z, double apex, double dz) {
    if (!(z > apex) || !(ratio > 0)) return 0.0;
    return ratio * (z - apex) / (1.0 - ratio * std::min(dz, 0.0));
}

Field2D cone_map_brute_force(const Field2D& heights, int channel, const ConeMapOptions& opt, const MemoryBudget* budget) {
    const Prepared p = prepare(heights, channel, opt);
    Field2D out = make_output(heights, channel, opt, budget);
    const int rc = out.channels() - 1;
    for (int y = 0; y < p.h; ++y)
        for (int x = 0; x < p.w; ++x) {
            const size_t t = size_t(y) * size_t(p.w) + size_t(x);
            double best = opt.max_ratio;
            for (int sy = 0; sy < p.h; ++sy)
                for (int sx = 0; sx < p.w; ++sx) {
                    const double hs = p.at(sx, sy);
                    if (!(hs > p.apex[t])) continue;
                    const Rect box{double(sx), double(sy), sx + 1.0, sy + 1.0};
                    best = std::min(best, rect_distance(p.region[t], box) / (hs - p.apex[t]));
                }
            out.at(rc, x, y) = conservative_float(best);
        }
    return out;
}

Field2D cone_map(const Field2D& heights, int channel, const ConeMapOptions& opt, const MemoryBudget* budget, const ProgressSink* progress) {
    const Prepared p = prepare(heights, channel, opt);
    Field2D out = make_output(heights, channel, opt, budget);
    const int rc = out.channels() - 1;

    // Max-mip pyramid: level k texel (i, j) = max over its 2^k x 2^k block.
    struct Level {
        int w, h;
        std::vector<double> m;
    };
    std::vector<Level> levels{{p.w, p.h, p.height}};
    while (levels.back().w > 1 || levels.back().h > 1) {
        const Level& a = levels.back();
        Level b{(a.w + 1) / 2, (a.h + 1) / 2, {}};
        b.m.assign(size_t(b.w) * size_t(b.h), -INFINITY);
        for (int y = 0; y < a.h; ++y)
            for (int x = 0; x < a.w; ++x) {
                double& d = b.m[size_t(y / 2) * size_t(b.w) + size_t(x / 2)];
                d = std::max(d, a.m[size_t(y) * size_t(a.w) + size_t(x)]);
            }
        levels.push_back(std::move(b));
    }
    const int top = int(levels.size()) - 1;

    parallel_for_index(p.h, [&](int y) {
        if (progress) progress->poll();
        struct Node {
            int k, i, j;
        };
        std::vector<Node> stack;
        for (int x = 0; x < p.w; ++x) {
            const size_t t = size_t(y) * size_t(p.w) + size_t(x);
            const double a = p.apex[t];
            const Rect& reg = p.region[t];
            double best = opt.max_ratio;
            stack.assign(1, {top, 0, 0});
            while (!stack.empty()) {
                const Node n = stack.back();
                stack.pop_back();
                const Level& L = levels[size_t(n.k)];
                const double m = L.m[size_t(n.j) * size_t(L.w) + size_t(n.i)];
                if (!(m > a)) continue;
                const double s = double(1 << n.k);
                const Rect box{n.i * s, n.j * s, std::min((n.i + 1) * s, double(p.w)), std::min((n.j + 1) * s, double(p.h))};
                const double bound = rect_distance(reg, box) / (m - a);
                if (!(bound < best)) continue;
                if (n.k == 0) {
                    best = bound;
                    continue;
                }
                // Children, farthest pushed first so the nearest is searched first.
                const Level& C = levels[size_t(n.k - 1)];
                Node ch[4];
                double dist[4];
                int cnt = 0;
                for (int dj = 0; dj < 2; ++dj)
                    for (int di = 0; di < 2; ++di) {
                        const int ci = 2 * n.i + di, cj = 2 * n.j + dj;
                        if (ci >= C.w || cj >= C.h) continue;
                        const double cs = s / 2;
                        ch[cnt] = {n.k - 1, ci, cj};
                        dist[cnt] = rect_distance(reg, {ci * cs, cj * cs, (ci + 1) * cs, (cj + 1) * cs});
                        ++cnt;
                    }
                for (int i = 1; i < cnt; ++i)
                    for (int j = i; j > 0 && dist[j] > dist[j - 1]; --j) {
                        std::swap(dist[j], dist[j - 1]);
                        std::swap(ch[j], ch[j - 1]);
                    }
                for (int i = 0; i < cnt; ++i) stack.push_back(ch[i]);
            }
            out.at(rc, x, y) = conservative_float(best);
        }
    });
    return out;
}

} // namespace atlas::ndf
