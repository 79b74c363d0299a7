// Fast generalized winding numbers and the union's surface of overlapping parts.
#include "mesh_line_hits.h"

#include "atlas/core/error.h"
#include "atlas/core/parallel.h"
#include "atlas/volume/mesh_repair.h"
#include "atlas/volume/mesh_voxelize.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/intersections.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>

namespace atlas::volume::detail {
namespace {

Vec3d to_d(const Vec3f& v) { return {{v[0], v[1], v[2]}}; }

// Signed solid angle of triangle abc seen from the origin (Van Oosterom & Strackee).
double solid_angle(const Vec3d& a, const Vec3d& b, const Vec3d& c) {
    const double la = length(a), lb = length(b), lc = length(c);
    const double det = dot(a, cross(b, c));
    const double den = la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb;
    return 2 * std::atan2(det, den);
}

constexpr uint32_t kLeafSize = 8;

} // namespace

FastWindingNumber::FastWindingNumber(const Mesh& m, double beta) : beta_(beta) {
    const uint32_t n = uint32_t(m.triangles.size());
    std::vector<uint32_t> order(n);
    std::iota(order.begin(), order.end(), 0u);
    std::vector<Vec3d> centroid(n);
    for (uint32_t t = 0; t < n; ++t) {
        const auto& tri = m.triangles[t];
        centroid[t] = (to_d(m.vertices[tri[0]]) + to_d(m.vertices[tri[1]]) + to_d(m.vertices[tri[2]])) / 3.0;
    }
    // Iterative build: median split along the widest axis of the centroids
    // (ties by triangle index, so the tree is deterministic).
    struct Task {
        uint32_t node, begin, end;
    };
    nodes_.push_back({});
    std::vector<Task> stack{{0, 0, n}};
    while (!stack.empty()) {
        const Task tk = stack.back();
        stack.pop_back();
        if (tk.end - tk.begin <= kLeafSize) {
            nodes_[tk.node].begin = tk.begin, nodes_[tk.node].end = tk.end, nodes_[tk.node].left = 0;
            continue;
        }
        Vec3d lo = centroid[order[tk.begin]], hi = lo;
        for (uint32_t i = tk.begin; i < tk.end; ++i)
            for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], centroid[order[i]][a]), hi[a] = std::max(hi[a], centroid[order[i]][a]);
        int axis = 0;
        for (int a = 1; a < 3; ++a)
            if (hi[a] - lo[a] > hi[axis] - lo[axis]) axis = a;
        const uint32_t mid = tk.begin + (tk.end - tk.begin) / 2;
        std::nth_element(order.begin() + tk.begin, order.begin() + mid, order.begin() + tk.end, [&](uint32_t x, uint32_t y) {
            return centroid[x][axis] != centroid[y][axis] ? centroid[x][axis] < centroid[y][axis] : x < y;
        });
        const uint32_t left = uint32_t(nodes_.size());
        nodes_.push_back({});
        nodes_.push_back({});
        nodes_[tk.node].begin = tk.begin, nodes_[tk.node].end = tk.end, nodes_[tk.node].left = left;
        stack.push_back({left, tk.begin, mid});
        stack.push_back({left + 1, mid, tk.end});
    }
    corners_.resize(n);
    for (uint32_t i = 0; i < n; ++i) {
        const auto& tri = m.triangles[order[i]];
        corners_[i] = {to_d(m.vertices[tri[0]]), to_d(m.vertices[tri[1]]), to_d(m.vertices[tri[2]])};
    }
    // Node moments from the triangles in their range (ranges nest, so this is
    // O(n log n) overall).
    parallel_for_each(nodes_.size(), 1, [&](size_t k) {
        Node& nd = nodes_[k];
        Vec3d an{}, c{}, mean{};
        double area = 0;
        for (uint32_t i = nd.begin; i < nd.end; ++i) {
            const auto& p = corners_[i];
            const Vec3d w = cross(p[1] - p[0], p[2] - p[0]) * 0.5;
            const double a = length(w);
            an = an + w;
            area += a;
            const Vec3d ct = (p[0] + p[1] + p[2]) / 3.0;
            c = c + ct * a;
            mean = mean + ct;
        }
        nd.centre = area > 0 ? c / area : mean / double(std::max(1u, nd.end - nd.begin));
        nd.area_normal = an;
        double r = 0;
        for (uint32_t i = nd.begin; i < nd.end; ++i)
            for (const Vec3d& p : corners_[i]) r = std::max(r, length(p - nd.centre));
        nd.radius = r;
    });
}

double FastWindingNumber::operator()(const Vec3d& q) const {
    double sum = 0;
    uint32_t stack[128];
    int top = 0;
    stack[top++] = 0;
    while (top > 0) {
        const Node& nd = nodes_[stack[--top]];
        const Vec3d d = nd.centre - q;
        const double dist = length(d);
        if (dist > beta_ * nd.radius) {
            // Dipole term: area-weighted normal . (p - q) / |p - q|^3.
            sum += dot(nd.area_normal, d) / (dist * dist * dist);
        } else if (nd.left == 0) {
            for (uint32_t i = nd.begin; i < nd.end; ++i) {
                const auto& p = corners_[i];
                sum += solid_angle(p[0] - q, p[1] - q, p[2] - q);
            }
        } else {
            stack[top++] = nd.left + 1;
            stack[top++] = nd.left;
        }
    }
    return sum / (4 * std::numbers::pi);
}

bool UnionSurface::point_buried(const Mesh& m, uint32_t t, const Vec3d& q) const {
    if (state.empty() || state[t] == kSurface) return false;
    if (state[t] == kBuried) return true;
    // Just beyond q: along the normal and a little into the triangle, so a
    // point on an edge or corner does not land on a neighbour's plane.
    const auto& tri = m.triangles[t];
    const Vec3d a = to_d(m.vertices[tri[0]]), b = to_d(m.vertices[tri[1]]), c = to_d(m.vertices[tri[2]]);
    const Vec3d n = cross(b - a, c - a);
    const double ln = length(n);
    if (!(ln > 0)) return false;
    Vec3d in = (a + b + c) / 3.0 - q;
    const double li = length(in);
    in = li > 0 ? in / li : Vec3d{};
    return (*winding)(q + (n / ln + in) * eps) > 0.5;
}

UnionSurface union_surface(const Mesh& m) {
    using K = CGAL::Exact_predicates_inexact_constructions_kernel;
    using Box = CGAL::Box_intersection_d::Box_with_info_d<double, 3, uint32_t>;
    UnionSurface us;
    const uint32_t n = uint32_t(m.triangles.size());
    std::vector<std::pair<uint64_t, uint32_t>> edges; // (sorted vertex pair, triangle), sorted
    edges.reserve(size_t(n) * 3);
    for (uint32_t t = 0; t < n; ++t)
        for (int e = 0; e < 3; ++e) {
            const uint64_t a = m.triangles[t][size_t(e)], b = m.triangles[t][size_t((e + 1) % 3)];
            edges.push_back({std::min(a, b) << 32 | std::max(a, b), t});
        }
    std::sort(edges.begin(), edges.end());
    // Edge-connected regions (union-find), optionally not joining through `cut` triangles.
    auto regions = [&](const std::vector<uint8_t>* cut) {
        std::vector<uint32_t> parent(n);
        std::iota(parent.begin(), parent.end(), 0u);
        auto root = [&](uint32_t i) {
            while (parent[i] != i) i = parent[i] = parent[parent[i]];
            return i;
        };
        for (size_t i = 1; i < edges.size(); ++i) {
            const uint32_t s0 = edges[i - 1].second, s1 = edges[i].second;
            if (edges[i].first != edges[i - 1].first || (cut && ((*cut)[s0] || (*cut)[s1]))) continue;
            parent[root(s1)] = root(s0);
        }
        for (uint32_t t = 0; t < n; ++t) parent[t] = root(t);
        return parent;
    };
    {
        const std::vector<uint32_t> comp = regions(nullptr);
        for (uint32_t t = 0; t < n; ++t) us.components += comp[t] == t;
    }

    // Crossing pairs of triangles that share no vertex.
    std::vector<K::Triangle_3> tri(n);
    std::vector<Box> boxes;
    boxes.reserve(n);
    for (uint32_t t = 0; t < n; ++t) {
        const auto& v = m.triangles[t];
        auto P = [&](int k) { const Vec3f& p = m.vertices[v[size_t(k)]]; return K::Point_3(p[0], p[1], p[2]); };
        tri[t] = K::Triangle_3(P(0), P(1), P(2));
        boxes.emplace_back(tri[t].bbox(), t);
    }
    std::vector<std::pair<uint32_t, uint32_t>> pairs;
    CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const Box& x, const Box& y) {
        const uint32_t s = x.info(), t = y.info();
        for (uint32_t a : m.triangles[s])
            for (uint32_t b : m.triangles[t])
                if (a == b) return;
        pairs.push_back({std::min(s, t), std::max(s, t)});
    });
    std::sort(pairs.begin(), pairs.end());
    // The exact tests in parallel (one flag per pair), the crossings then in pair order.
    std::vector<uint8_t> crosses(pairs.size(), 0);
    parallel_blocks(pairs.size(), 1024, [&](size_t i0, size_t i1) {
        for (size_t i = i0; i < i1; ++i) {
            const auto [s, t] = pairs[i];
            crosses[i] = !tri[s].is_degenerate() && !tri[t].is_degenerate() && CGAL::do_intersect(tri[s], tri[t]);
        }
    });
    std::vector<std::vector<std::array<Vec3d, 2>>> segs;
    std::vector<uint8_t> hit(n, 0);
    for (size_t pi = 0; pi < pairs.size(); ++pi) {
        if (!crosses[pi]) continue;
        const auto [s, t] = pairs[pi];
        if (segs.empty()) segs.resize(n);
        hit[s] = hit[t] = 1;
        const auto r = CGAL::intersection(tri[s], tri[t]);
        if (!r) continue;
        auto pd = [](const K::Point_3& p) { return Vec3d{{p.x(), p.y(), p.z()}}; };
        std::vector<Vec3d> loop; // boundary of the intersection (segment, or a coplanar overlap polygon)
        if (const auto* sg = boost::get<K::Segment_3>(&*r)) loop = {pd(sg->source()), pd(sg->target())};
        else if (const auto* tr = boost::get<K::Triangle_3>(&*r)) loop = {pd(tr->vertex(0)), pd(tr->vertex(1)), pd(tr->vertex(2))};
        else if (const auto* poly = boost::get<std::vector<K::Point_3>>(&*r))
            for (const auto& p : *poly) loop.push_back(pd(p));
        const size_t k = loop.size();
        for (size_t i = 0; k >= 2 && i < (k == 2 ? 1 : k); ++i) {
            const std::array<Vec3d, 2> e{loop[i], loop[(i + 1) % k]};
            segs[s].push_back(e);
            segs[t].push_back(e);
        }
    }
    const bool any_cross = !segs.empty();
    if (!any_cross && us.components <= 1) return us; // one part, no self-crossing: all surface

    // The offset for "just beyond" tests: far above float rounding of the
    // coordinates, far below any voxel.
    Vec3d lo = to_d(m.vertices[m.triangles[0][0]]), hi = lo;
    for (const auto& t : m.triangles)
        for (uint32_t v : t)
            for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], double(m.vertices[v][a])), hi[a] = std::max(hi[a], double(m.vertices[v][a]));
    us.eps = 1e-5 * length(hi - lo);
    us.winding = std::make_unique<FastWindingNumber>(m);
    us.state.assign(n, UnionSurface::kSurface);
    for (uint32_t t = 0; t < n; ++t)
        if (hit[t]) us.state[t] = UnionSurface::kStraddling;
    // A connected region of triangles that cross nothing lies wholly on one
    // side of every other part: one test per region (at its largest triangle).
    const std::vector<uint32_t> region = regions(&hit);
    auto centre_buried = [&](uint32_t t) {
        const auto& v = m.triangles[t];
        const Vec3d a = to_d(m.vertices[v[0]]), b = to_d(m.vertices[v[1]]), c = to_d(m.vertices[v[2]]);
        const Vec3d nn = cross(b - a, c - a);
        const double l = length(nn);
        if (!(l > 0)) return false;
        return (*us.winding)((a + b + c) / 3.0 + nn * (us.eps / l)) > 0.5;
    };
    std::vector<uint32_t> rep(n, UINT32_MAX);
    std::vector<double> rep_area(n, -1);
    for (uint32_t t = 0; t < n; ++t) {
        if (hit[t]) continue;
        const double a = tri[t].squared_area();
        if (a > rep_area[region[t]]) rep_area[region[t]] = a, rep[region[t]] = t;
    }
    std::vector<uint32_t> reps;
    for (uint32_t r = 0; r < n; ++r)
        if (rep[r] != UINT32_MAX) reps.push_back(r);
    std::vector<uint8_t> region_buried(n, 0);
    parallel_for_each(reps.size(), 1, [&](size_t i) { region_buried[reps[i]] = centre_buried(rep[reps[i]]); });
    std::vector<uint8_t> own(n, 0);
    for (uint32_t t = 0; t < n; ++t)
        if (!hit[t]) own[t] = region_buried[region[t]];
    for (uint32_t t = 0; t < n; ++t) {
        if (own[t]) us.state[t] = UnionSurface::kBuried, ++us.buried;
        if (us.state[t] == UnionSurface::kStraddling) ++us.straddling;
    }
    us.segments = std::move(segs);
    us.corner_buried.assign(n, {0, 0, 0});
    parallel_for_each(n, 1, [&](size_t t) {
        if (us.state[t] != UnionSurface::kStraddling) return;
        for (int k = 0; k < 3; ++k) us.corner_buried[t][size_t(k)] = us.point_buried(m, uint32_t(t), to_d(m.vertices[m.triangles[t][size_t(k)]]));
    });
    return us;
}

void union_boundary_hits(const AxisHits& ah, uint32_t l, std::vector<double>& out) {
    const uint32_t k0 = ah.offsets[l], k1 = ah.offsets[l + 1];
    int total = 0;
    for (uint32_t k = k0; k < k1; ++k) total += ah.sign[k];
    int below = 0;
    // Hits at the same t form one crossing (touching faces cancel).
    for (uint32_t k = k0; k < k1;) {
        uint32_t e = k;
        int step = 0;
        while (e < k1 && ah.t[e] == ah.t[k]) step += ah.sign[e++];
        const int lb = below, la = below + step;     // count from -inf, before / after
        const int rb = lb - total, ra = la - total;  // count from +inf
        const bool interior = lb >= 1 && la >= 1 && rb >= 1 && ra >= 1;
        if (!interior)
            for (uint32_t i = k; i < e; ++i) out.push_back(ah.t[i]);
        below = la;
        k = e;
    }
}

} // namespace atlas::volume::detail

namespace atlas::volume {

std::vector<double> fast_winding_numbers(const Mesh& m, const std::vector<Vec3d>& points) {
    validate_mesh(m, "fast_winding_numbers");
    const detail::FastWindingNumber wn(m);
    std::vector<double> out(points.size());
    parallel_for_each(points.size(), 1, [&](size_t i) { out[i] = wn(points[i]); });
    return out;
}

} // namespace atlas::volume
