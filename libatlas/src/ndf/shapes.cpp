// Shapes painted from a list: ellipses, polygons, strokes with falloff.
#include "atlas/ndf/generators.h"
#include "atlas/ndf/ndf_set.h"

#include "atlas/core/error.h"

#include "atlas/core/parallel.h"

#include <cmath>
#include <sstream>

namespace atlas::ndf {

namespace {
double segment_distance(Vec2d p, Vec2d a, Vec2d b) {
    const Vec2d ab = b - a;
    const double l2 = dot(ab, ab);
    const double t = l2 > 0 ? std::clamp(dot(p - a, ab) / l2, 0.0, 1.0) : 0.0;
    return length(p - (a + ab * t));
}

// Distance outside the shape in metres (<= 0 inside).
double outside_distance(const Shape& s, Vec2d p) {
    switch (s.kind) {
    case Shape::Kind::Ellipse: {
        // Scaled radial distance: exact for circles, a smooth approximation
        // for ellipses (distance along the ray from the centre).
        const Vec2d q{{(p[0] - s.points[0][0]) / s.radii[0], (p[1] - s.points[0][1]) / s.radii[1]}};
        const double k = length(q);
        if (k <= 1) return 0;
        const Vec2d edge{{q[0] / k * s.radii[0], q[1] / k * s.radii[1]}};
        return length(p - s.points[0]) - length(edge);
    }
    case Shape::Kind::Polygon: {
        double d = INFINITY;
        bool inside = false;
        const size_t n = s.points.size();
        for (size_t i = 0, j = n - 1; i < n; j = i++) {
            const Vec2d a = s.points[j], b = s.points[i];
            d = std::min(d, segment_distance(p, a, b));
            if ((b[1] > p[1]) != (a[1] > p[1]) && p[0] < (a[0] - b[0]) * (p[1] - b[1]) / (a[1] - b[1]) + b[0]) inside = !inside;
        }
        return inside ? 0 : d;
    }
    case Shape::Kind::Stroke: {
        double d = INFINITY;
        for (size_t i = 1; i < s.points.size(); ++i) d = std::min(d, segment_distance(p, s.points[i - 1], s.points[i]));
        return std::max(0.0, d - 0.5 * s.width);
    }
    }
    return INFINITY;
}

void check_shape(const Shape& s, size_t i) {
    const std::string where = "shapes: entry " + std::to_string(i + 1) + ": ";
    for (const auto& p : s.points)
        if (!std::isfinite(p[0]) || !std::isfinite(p[1])) throw Error(where + "coordinates must be finite");
    if (!std::isfinite(s.value)) throw Error(where + "value must be finite");
    if (!(s.falloff >= 0) || !std::isfinite(s.falloff)) throw Error(where + "falloff must be >= 0 and finite");
    switch (s.kind) {
    case Shape::Kind::Ellipse:
        if (s.points.size() != 1) throw Error(where + "an ellipse has one centre");
        if (!(s.radii[0] > 0 && s.radii[1] > 0) || !std::isfinite(s.radii[0]) || !std::isfinite(s.radii[1]))
            throw Error(where + "ellipse radii must be > 0 and finite");
        break;
    case Shape::Kind::Polygon:
        if (s.points.size() < 3) throw Error(where + "a polygon needs at least 3 vertices");
        break;
    case Shape::Kind::Stroke:
        if (s.points.size() < 2) throw Error(where + "a stroke needs at least 2 points");
        if (!(s.width > 0) || !std::isfinite(s.width)) throw Error(where + "stroke width must be > 0");
        break;
    }
}
} // namespace

std::vector<Shape> parse_shapes(const std::string& text) {
    std::vector<Shape> out;
    std::stringstream all(text);
    std::string entry;
    while (std::getline(all, entry, ';')) {
        std::istringstream in(entry);
        std::string kind;
        if (!(in >> kind)) continue;
        const std::string where = "shapes: entry " + std::to_string(out.size() + 1) + " ('" + kind + "'): ";
        std::vector<double> v;
        std::string tok;
        while (in >> tok) {
            try {
                size_t used = 0;
                v.push_back(std::stod(tok, &used));
                if (used != tok.size()) throw std::invalid_argument(tok);
            } catch (const std::exception&) {
                throw Error(where + "'" + tok + "' is not a number");
            }
        }
        Shape s;
        auto pts = [&](size_t from) {
            if ((v.size() - from) % 2 != 0) throw Error(where + "coordinates come in x y pairs");
            for (size_t i = from; i + 1 < v.size(); i += 2) s.points.push_back({{v[i], v[i + 1]}});
        };
        if (kind == "ellipse") {
            if (v.size() != 6) throw Error(where + "expected 'ellipse CX CY RX RY VALUE FALLOFF'");
            s.kind = Shape::Kind::Ellipse;
            s.points = {{{v[0], v[1]}}};
            s.radii = {{v[2], v[3]}};
            s.value = v[4];
            s.falloff = v[5];
        } else if (kind == "polygon") {
            if (v.size() < 8) throw Error(where + "expected 'polygon VALUE FALLOFF X Y X Y X Y ...' (3+ vertices)");
            s.kind = Shape::Kind::Polygon;
            s.value = v[0];
            s.falloff = v[1];
            pts(2);
        } else if (kind == "stroke") {
            if (v.size() < 7) throw Error(where + "expected 'stroke WIDTH VALUE FALLOFF X Y X Y ...' (2+ points)");
            s.kind = Shape::Kind::Stroke;
            s.width = v[0];
            s.value = v[1];
            s.falloff = v[2];
            pts(3);
        } else {
            throw Error(where + "unknown shape (expected ellipse, polygon or stroke)");
        }
        check_shape(s, out.size());
        out.push_back(std::move(s));
    }
    return out;
}

Field2D paint_shapes(Vec2i res, Box2d bounds, const std::vector<Shape>& shapes, const MemoryBudget* budget) {
    if (!bounds.valid()) throw Error("shapes: bounds must be finite with max > min");
    for (size_t i = 0; i < shapes.size(); ++i) check_shape(shapes[i], i);
    Field2D f(res, 1, bounds, {"value"}, budget);
    auto out = f.channel(0);
    // Conservative bounding boxes: a texel outside one is beyond the shape's
    // falloff (weight exactly 0), so skipping it changes no value.
    std::vector<Box2d> boxes;
    for (const Shape& s : shapes) {
        Box2d b{s.points[0], s.points[0]};
        for (const Vec2d& q : s.points)
            for (int a = 0; a < 2; ++a) b.min[a] = std::min(b.min[a], q[a]), b.max[a] = std::max(b.max[a], q[a]);
        double grow = s.falloff;
        if (s.kind == Shape::Kind::Ellipse) grow += std::max(s.radii[0], s.radii[1]);
        if (s.kind == Shape::Kind::Stroke) grow += 0.5 * s.width;
        for (int a = 0; a < 2; ++a) {
            const double margin = 1e-6 * (std::abs(b.min[a]) + std::abs(b.max[a]) + grow) + 1e-12;
            b.min[a] -= grow + margin;
            b.max[a] += grow + margin;
        }
        boxes.push_back(b);
    }
    parallel_for_index(res[1], [&](int y) {
        for (int x = 0; x < res[0]; ++x) {
            const Vec2d p = f.texel_center(x, y);
            double v = 0;
            bool any = false;
            for (size_t k = 0; k < shapes.size(); ++k) {
                const Shape& s = shapes[k];
                const Box2d& bb = boxes[k];
                if (p[0] < bb.min[0] || p[0] > bb.max[0] || p[1] < bb.min[1] || p[1] > bb.max[1]) continue;
                const double d = outside_distance(s, p);
                double w;
                if (d <= 0) w = 1;
                else if (s.falloff > 0) w = 1.0 - smoothstep(0.0, s.falloff, d);
                else w = 0;
                if (w <= 0) continue;
                v = any ? std::max(v, s.value * w) : s.value * w;
                any = true;
            }
            out[f.index(x, y)] = float(v);
        }
    });
    return f;
}

} // namespace atlas::ndf
