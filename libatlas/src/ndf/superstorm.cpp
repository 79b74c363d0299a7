// Superstorm stencil: the mesocyclone written radially into an NDF set.
#include "atlas/ndf/superstorm.h"
#include "atlas/ndf/ndf_set.h"

#include "atlas/core/error.h"
#include "atlas/noise/value_noise.h"
#include "atlas/core/parallel.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace atlas::ndf {

std::span<const NumberOption<SuperstormStencil>> superstorm_options() {
    using S = SuperstormStencil;
    static const NumberOption<S> options[] = {
        {"radius", &S::radius, 1e-6, std::numeric_limits<double>::infinity(), "m", "stencil radius (> 0)"},
        {"core", &S::core, 0, 0.999, "", "fraction of the radius at full strength"},
        {"coverage", &S::coverage, 0, 1, "", "coverage at the centre (never lowers the map's)"},
        {"blend", &S::blend, 0, 1, "", "strength of the stencil"},
        {"storm_type", &S::storm_type, 0, 1, "", "type and top type at the centre"},
        {"bottom_type", &S::bottom_type, 0, 1, "", "bottom type at the centre (1: ragged underside)"},
        {"min_height", &S::min_height, -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(), "m",
         "storm base at the centre"},
        {"max_height", &S::max_height, -std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(), "m",
         "storm top at the centre (>= min_height)"},
        {"distortion", &S::distortion, 0, 0.999, "", "radial wobble of the height gradients"},
        {"noise_scale", &S::noise_scale, 1e-6, 1e6, "", "noise cells across the radius"},
        {"anvil", &S::anvil, 0, 1, "", "anvil spread at the centre (the anvil map only)"},
        {"anvil_lift", &S::anvil_lift, 0, 20000, "m", "how far the anvil rises above max_height at bias 1 (the anvil map only)"},
        {"height_core", &S::height_core, -1, 0.999, "", "fraction of the radius where the heights are the storm's (a flat base that wide); -1 = core"},
        {"edge_noise", &S::edge_noise, 0, 0.999, "", "wobble of the footprint's edge (coverage and types); 0 = round"},
        {"stretch", &S::stretch, 1, 100, "", "downwind radius over radius: 1 a disc, > 1 a plume spreading downwind"},
        {"wind_direction", &S::wind_direction, -360, 360, "deg", "direction the plume spreads toward (0: +x, 90: +y)"},
        {"wall_noise", &S::wall_noise, 0, 0.999, "", "lumpy wall: fine wobble of the heights' radius, a fraction of the height band; 0 = smooth"},
        {"base_relief", &S::base_relief, 0, 20000, "m", "the base rises by up to this much in noise patches (underside definition); 0 = flat"},
    };
    return options;
}

void validate(const SuperstormStencil& s) {
    if (!std::isfinite(s.center[0]) || !std::isfinite(s.center[1])) throw Error("superstorm: 'center' must be finite");
    check_options(s, superstorm_options(), "superstorm");
    if (s.min_height > s.max_height) throw Error("superstorm: 'min_height' must not be above 'max_height'");
}

bool stencil_touches(const SuperstormStencil& s, const Box2d& b) {
    // The plume lies inside the disc of its downwind radius (a cheap, safe test).
    const double reach = s.radius * s.stretch;
    const double dx = std::max({b.min[0] - s.center[0], 0.0, s.center[0] - b.max[0]});
    const double dy = std::max({b.min[1] - s.center[1], 0.0, s.center[1] - b.max[1]});
    return dx * dx + dy * dy < reach * reach;
}

namespace {
// The footprint's radial distance of offset d: the plain length for a disc
// (bit-identical to before plumes), the downwind half squeezed by stretch.
double footprint_radius(const SuperstormStencil& s, Vec2d d) {
    if (s.stretch == 1) return length(d);
    const double t = s.wind_direction * (3.14159265358979323846 / 180.0);
    const double ca = std::cos(t), sa = std::sin(t);
    double a = d[0] * ca + d[1] * sa;
    const double c = -d[0] * sa + d[1] * ca;
    if (a > 0) a /= s.stretch;
    return std::sqrt(a * a + c * c);
}
} // namespace

Field2D apply_superstorm(const Field2D& set, const SuperstormStencil& s, const MemoryBudget* budget) {
    check_ndf_set(set);
    validate(s);
    (void)budget;
    Field2D out = set;
    if (s.blend == 0) return out;
    const Vec3i period{{1 << 16, 1 << 16, 1}};
    parallel_for_index(set.height(), [&](int y) {
        for (int x = 0; x < set.width(); ++x) {
            const Vec2d d = set.texel_center(x, y) - s.center;
            const double r = footprint_radius(s, d);
            if (!(r < s.radius)) continue; // beyond the radius: unchanged
            const size_t i = set.index(x, y);
            auto mix = [&](int c, double target, double weight) {
                out.channel(c)[i] = float(lerp(double(set.channel(c)[i]), target, weight));
            };
            // Distorted radius: the wobble vanishes at the centre and at the rim.
            const double k = s.noise_scale / s.radius;
            const double n = noise::value_noise(d[0] * k + 4096.0, d[1] * k + 4096.0, 0.0, period, s.seed);
            const double rd = r * (1.0 + s.distortion * (2.0 * n - 1.0) * (1.0 - r / s.radius));
            // The footprint's own wobble (edge_noise, a second octave at twice
            // the frequency): 0 keeps the round footprint, bit-identical.
            double rc = r;
            if (s.edge_noise > 0) {
                const double n2 = noise::value_noise(d[0] * 2 * k + 8192.0, d[1] * 2 * k + 8192.0, 0.0, period, s.seed + 1);
                rc = r * (1.0 + s.edge_noise * ((2.0 * n - 1.0) * 0.6 + (2.0 * n2 - 1.0) * 0.4) * (1.0 - r / s.radius));
            }
            const double g = 1.0 - smoothstep(s.core * s.radius, s.radius, rc);
            const double w = s.blend * g;
            const double hc = s.height_core >= 0 ? s.height_core : s.core;
            double rw = rd;
            if (s.wall_noise > 0) {
                // Billowed wall: finer octaves that do not vanish in the band, only in its outer quarter.
                double f = 0, amp = 0.5, amps = 0;
                for (int o = 1; o <= 3; ++o, amp *= 0.5) {
                    const double ko = k * double(1 << o);
                    f += amp * (2.0 * noise::value_noise(d[0] * ko + 1024.0 * o, d[1] * ko + 2048.0 * o, 0.0, period, s.seed + 7 + uint32_t(o)) - 1.0);
                    amps += amp;
                }
                const double band = (1.0 - hc) * s.radius;
                rw = rd + s.wall_noise * band * (f / amps) * std::min(1.0, 4.0 * (1.0 - r / s.radius));
            }
            // With its own coverage a column is the storm's only as far as the storm covers it:
            // tall columns of thin coverage render as walls a few metres thick, a shape no cloud has.
            const double take = s.own_coverage ? std::min(1.0, s.coverage * g / 0.25) : 1.0;
            const double wh = take * s.blend * (1.0 - smoothstep(hc * s.radius, s.radius, rw));
            if (s.sheet) {
                // The anvil sheet: flat top, underside rising to the ragged rim.
                if (!(wh > 0)) continue;
                out.channel(Coverage)[i] = float(s.coverage * wh);
                mix(Type, s.storm_type, wh);
                mix(TopType, s.storm_type, wh);
                mix(BottomType, std::max(double(set.channel(BottomType)[i]), s.bottom_type), wh);
                out.channel(SuperstormCoverage)[i] = float(std::max(double(set.channel(SuperstormCoverage)[i]), w));
                out.channel(MaxHeight)[i] = float(s.max_height);
                out.channel(MinHeight)[i] = float(s.max_height - (s.max_height - s.min_height) * wh);
                continue;
            }
            const double cov = set.channel(Coverage)[i];
            mix(Coverage, std::max(cov, s.coverage), w);
            if (s.own_coverage) out.channel(Coverage)[i] = float(lerp(double(out.channel(Coverage)[i]), s.coverage * g, wh));
            mix(Type, s.storm_type, w);
            mix(TopType, s.storm_type, w);
            mix(BottomType, std::max(double(set.channel(BottomType)[i]), s.bottom_type), w);
            out.channel(SuperstormCoverage)[i] = float(std::max(double(set.channel(SuperstormCoverage)[i]), w));
            double base = s.min_height;
            if (s.base_relief > 0) {
                const double n1 = noise::value_noise(d[0] * 2 * k + 512.0, d[1] * 2 * k + 512.0, 0.0, period, s.seed + 11);
                const double n2 = noise::value_noise(d[0] * 4 * k + 640.0, d[1] * 4 * k + 640.0, 0.0, period, s.seed + 12);
                base = std::min(s.max_height, base + s.base_relief * std::clamp(1.6 * (0.65 * n1 + 0.35 * n2) - 0.6, 0.0, 1.0));
            }
            mix(MinHeight, base, wh);
            mix(MaxHeight, s.max_height, wh);
        }
    });
    return out;
}

Field2D superstorm_anvil(const Field2D& set, const SuperstormStencil& s, const Field2D* previous, const MemoryBudget* budget) {
    check_ndf_set(set);
    validate(s);
    if (previous && (previous->resolution() != set.resolution() || previous->channels() < 1))
        throw Error("superstorm: the previous anvil map must have the set's resolution (" + std::to_string(set.width()) + "x" +
                    std::to_string(set.height()) + ") and one channel");
    Field2D out(set.resolution(), 2, set.bounds(), {"anvil_bias", "anvil_lift"}, budget);
    if (previous) {
        const int cb = std::max(0, previous->find_channel("anvil_bias")), cl = previous->find_channel("anvil_lift");
        std::copy(previous->channel(cb).begin(), previous->channel(cb).end(), out.channel(0).begin());
        if (cl >= 0) std::copy(previous->channel(cl).begin(), previous->channel(cl).end(), out.channel(1).begin());
    }
    if (s.blend == 0 || s.anvil == 0) return out;
    parallel_for_index(set.height(), [&](int y) {
        for (int x = 0; x < set.width(); ++x) {
            const double r = footprint_radius(s, set.texel_center(x, y) - s.center);
            if (!(r < s.radius)) continue;
            const double w = s.anvil * s.blend * (1.0 - smoothstep(s.core * s.radius, s.radius, r));
            const size_t i = set.index(x, y);
            float& v = out.channel(0)[i];
            v = float(std::max(double(v), w));
            float& l = out.channel(1)[i];
            l = float(std::max(double(l), s.anvil_lift * w));
        }
    });
    return out;
}

std::vector<VortexRing> make_vortex_rings(double radius, int count, const std::vector<double>& radii, double overlap,
                                          double inner_speed, double skew) {
    if (!(radius > 0) || !std::isfinite(radius)) throw Error("vortex rings: 'radius' must be > 0 and finite");
    if (count < 1 || count > 256) throw Error("vortex rings: 'rings' must be in [1, 256]");
    if (!(overlap >= 0 && overlap <= 1)) throw Error("vortex rings: 'overlap' must be in [0, 1]");
    if (!std::isfinite(inner_speed) || !std::isfinite(skew)) throw Error("vortex rings: 'speed' and 'skew' must be finite");
    std::vector<double> outer = radii;
    if (outer.empty())
        for (int i = 0; i < count; ++i) outer.push_back(radius * (i + 1) / count);
    if (int(outer.size()) != count)
        throw Error("vortex rings: 'ring_radii' has " + std::to_string(outer.size()) + " entries, expected " + std::to_string(count));
    for (size_t i = 0; i < outer.size(); ++i) {
        if (!(outer[i] > (i ? outer[i - 1] : 0.0)) || !std::isfinite(outer[i]))
            throw Error("vortex rings: 'ring_radii' must be > 0 and strictly increasing (entry " + std::to_string(i + 1) + ")");
        if (outer[i] > radius * (1 + 1e-12)) throw Error("vortex rings: 'ring_radii' must not exceed the stencil radius");
    }
    std::vector<VortexRing> rings;
    for (int i = 0; i < count; ++i) {
        const double in = i ? outer[size_t(i - 1)] : 0.0;
        rings.push_back({in, outer[size_t(i)], inner_speed * outer[0] / outer[size_t(i)], count > 1 ? skew * i / (count - 1) : 0.0});
    }
    return rings;
}

std::string vortex_rings_json(Vec2d center, double radius, double overlap, const std::vector<VortexRing>& rings) {
    auto num = [](double v) {
        char buf[64];
        std::snprintf(buf, sizeof buf, "%.17g", v);
        return std::string(buf);
    };
    std::string s = "{\"center\": [" + num(center[0]) + ", " + num(center[1]) + "], \"radius\": " + num(radius) + ", \"overlap\": " + num(overlap) + ", \"rings\": [";
    for (size_t i = 0; i < rings.size(); ++i) {
        const auto& r = rings[i];
        s += (i ? ", " : "") + std::string("{\"index\": ") + std::to_string(i) + ", \"inner\": " + num(r.inner) + ", \"outer\": " +
             num(r.outer) + ", \"overlap_end\": " + num(r.outer + overlap * (r.outer - r.inner)) + ", \"speed\": " + num(r.speed) + ", \"skew\": " + num(r.skew) + "}";
    }
    return s + "]}\n";
}

Field2D vortex_ring_table(Vec2d center, double radius, double overlap, const std::vector<VortexRing>& rings) {
    if (rings.empty()) throw Error("vortex rings: at least one ring");
    const Box2d box{{{center[0] - radius, center[1] - radius}}, {{center[0] + radius, center[1] + radius}}};
    if (!box.valid()) throw Error("vortex rings: 'center' and 'radius' must be finite, radius > 0");
    Field2D t({{int(rings.size()), 1}}, 5, box, {"inner", "outer", "speed", "skew", "overlap_end"});
    for (size_t i = 0; i < rings.size(); ++i) {
        const auto& r = rings[i];
        t.at(0, int(i), 0) = float(r.inner);
        t.at(1, int(i), 0) = float(r.outer);
        t.at(2, int(i), 0) = float(r.speed);
        t.at(3, int(i), 0) = float(r.skew);
        t.at(4, int(i), 0) = float(r.outer + overlap * (r.outer - r.inner));
    }
    return t;
}

Field2D vortex_ring_map(Vec2i res, Box2d bounds, Vec2d center, const std::vector<VortexRing>& rings, double overlap,
                        const MemoryBudget* budget) {
    if (rings.empty()) throw Error("vortex rings: at least one ring");
    Field2D f(res, 2, bounds, {"ring_index", "ring_blend"}, budget);
    parallel_for_index(res[1], [&](int y) {
        for (int x = 0; x < res[0]; ++x) {
            const double r = length(f.texel_center(x, y) - center);
            float idx = -1, blend = 0;
            for (size_t i = 0; i < rings.size(); ++i) {
                if (r < rings[i].outer) {
                    idx = float(i);
                    break;
                }
            }
            if (idx < 0) {
                // Past the last ring: the overlap band fades the last ring out.
                const auto& last = rings.back();
                const double band = overlap * (last.outer - last.inner);
                if (band > 0 && r < last.outer + band) {
                    idx = float(rings.size() - 1);
                    blend = float(smoothstep(last.outer, last.outer + band, r));
                }
            } else if (size_t(idx) > 0) {
                // Inside ring i: the previous ring's overlap band reaches in.
                const auto& prev = rings[size_t(idx) - 1];
                const double band = overlap * (prev.outer - prev.inner);
                if (band > 0 && r < prev.outer + band) {
                    idx -= 1;
                    blend = float(smoothstep(prev.outer, prev.outer + band, r));
                }
            }
            f.at(0, x, y) = idx;
            f.at(1, x, y) = blend;
        }
    });
    return f;
}

} // namespace atlas::ndf
