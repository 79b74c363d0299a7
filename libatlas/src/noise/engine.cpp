#include "engine.h"

#include "cellular.h"
#include "gradient.h"
#include "simd.h"
#include "value.h"

#include <algorithm>
#include <cmath>

namespace atlas::noise::detail {
namespace {

constexpr uint32_t kStreamMain = 0, kStreamCurl = 1, kStreamPwWorley = 4, kStreamCurly = 5;

// Octave 0 keeps the user's seed (so a one-octave value kernel equals
// value_noise()); later octaves get decorrelated seeds.
uint32_t octave_seed(uint32_t seed, int octave) { return octave == 0 ? seed : hash_coords(seed, octave, 0, 0, 0x6F637461u); }

template <int D>
IVec<D> scaled(const IVec<D>& p, int64_t f) {
    IVec<D> r{};
    for (int a = 0; a < D; ++a) r[a] = int(int64_t(p[a]) * f);
    return r;
}

int64_t ipow(int b, int e) {
    int64_t r = 1;
    for (int i = 0; i < e; ++i) r *= b;
    return r;
}

ValueRange native_range(Kernel k) { return k == Kernel::Gradient ? ValueRange{-1, 1} : ValueRange{0, 1}; }

template <int D>
struct Splits {
    std::array<Split, D> s;
};

template <int D>
inline Splits<D> split_all(const std::array<const double*, D>& u, size_t i, double scale, const IVec<D>& period) {
    Splits<D> r;
    for (int a = 0; a < D; ++a) r.s[a] = split(u[a][i] * scale, period[a]);
    return r;
}

template <int D, WorleyMetric M>
void worley_octave(const Lattice<D>& L, const std::array<const double*, D>& u, size_t n, double scale, float jitter,
                   WorleyFeature feature, float* out) {
    [[maybe_unused]] CellCache3 cache;
    for (size_t i = 0; i < n; ++i) {
        const auto sp = split_all<D>(u, i, scale, L.period());
        F12 f;
        if constexpr (D == 3) {
            cache.load(L, sp.s[0], sp.s[1], sp.s[2], jitter);
            f = worley3_cached<M>(cache, sp.s[0].frac, sp.s[1].frac, sp.s[2].frac);
        } else {
            f = worley2<M>(L, sp.s[0], sp.s[1], jitter);
        }
        out[i] = worley_feature(f, feature);
    }
}

uint64_t view_bits(const void* l, int x, int y, int z) { return static_cast<const Lattice<3>*>(l)->bits(x, y, z); }

void view_corners(const void* l, const int (&xs)[2], const int (&ys)[2], const int (&zs)[2], int first_i, int (&out)[8]) {
    const auto& L = *static_cast<const Lattice<3>*>(l);
    corner_bits3(L.seed(), L.stream(), xs, ys, zs, 15u, first_i, out);
}

LatticeView view_of(const Lattice<3>& L) {
    return {L.table(), L.period()[0], L.period()[1], L.period()[2], &L, &view_bits, &view_corners};
}

// The SIMD path of a 3D octave (simd.h): true when it wrote out.
bool simd_octave(Kernel k, const NoiseSpec& spec, const Lattice<3>& L, const std::array<const double*, 3>& u, size_t n, double scale,
                 float* out) {
    if (k != Kernel::Gradient && k != Kernel::Worley && k != Kernel::Alligator && k != Kernel::CurlyAlligator) return false;
    const SimdKernels* K = active_kernels();
    if (!K) return false;
    const LatticeView v = view_of(L);
    const double* up[3] = {u[0], u[1], u[2]};
    switch (k) {
    case Kernel::Gradient: K->gradient3(v, up, n, scale, out); break;
    case Kernel::Worley: K->worley3[int(spec.worley.metric)](v, up, n, scale, float(spec.worley.jitter), spec.worley.feature, out); break;
    default: K->alligator3(v, up, n, scale, float(1.0 / (spec.alligator.radius * spec.alligator.radius)), out); break;
    }
    return true;
}

// One octave of a scalar kernel in its native range.
template <int D>
void scalar_octave(Kernel k, const NoiseSpec& spec, const Lattice<D>& L, const std::array<const double*, D>& u, size_t n,
                   double scale, float* out) {
    if constexpr (D == 3)
        if (simd_octave(k, spec, L, u, n, scale, out)) return;
    switch (k) {
    case Kernel::Gradient: {
        [[maybe_unused]] GradCache3 gc;
        for (size_t i = 0; i < n; ++i) {
            const auto sp = split_all<D>(u, i, scale, L.period());
            float v;
            if constexpr (D == 3) {
                gc.load(L, sp.s[0], sp.s[1], sp.s[2]);
                v = gradient3(gc, sp.s[0].frac, sp.s[1].frac, sp.s[2].frac, nullptr);
            } else {
                v = gradient2(L, sp.s[0], sp.s[1], nullptr);
            }
            out[i] = std::clamp(v, -1.0f, 1.0f);
        }
        break;
    }
    case Kernel::Value:
        for (size_t i = 0; i < n; ++i) {
            const auto sp = split_all<D>(u, i, scale, L.period());
            if constexpr (D == 3) out[i] = value3(L, sp.s[0], sp.s[1], sp.s[2]);
            else out[i] = value2(L, sp.s[0], sp.s[1]);
        }
        break;
    case Kernel::Worley: {
        const float jitter = float(spec.worley.jitter);
        switch (spec.worley.metric) {
        case WorleyMetric::Euclidean: worley_octave<D, WorleyMetric::Euclidean>(L, u, n, scale, jitter, spec.worley.feature, out); break;
        case WorleyMetric::Manhattan: worley_octave<D, WorleyMetric::Manhattan>(L, u, n, scale, jitter, spec.worley.feature, out); break;
        case WorleyMetric::Chebyshev: worley_octave<D, WorleyMetric::Chebyshev>(L, u, n, scale, jitter, spec.worley.feature, out); break;
        }
        break;
    }
    case Kernel::Alligator:
    case Kernel::CurlyAlligator: {
        const float inv_r2 = float(1.0 / (spec.alligator.radius * spec.alligator.radius));
        [[maybe_unused]] CellCache3 cache;
        for (size_t i = 0; i < n; ++i) {
            const auto sp = split_all<D>(u, i, scale, L.period());
            if constexpr (D == 3) {
                cache.load(L, sp.s[0], sp.s[1], sp.s[2], 1.0f);
                out[i] = alligator3_cached(cache, sp.s[0].frac, sp.s[1].frac, sp.s[2].frac, inv_r2);
            } else {
                out[i] = alligator2(L, sp.s[0], sp.s[1], inv_r2);
            }
        }
        break;
    }
    default: break;
    }
}

// Curl of the potential(s) in lattice[first .. first+potentials) at u*scale,
// in units per octave cell (so the bound does not grow with the octave).
template <int D>
void curl_octave(const Lattice<D>* pots, const std::array<const double*, D>& u, size_t n, double scale, float weight,
                 float* const* out) {
    [[maybe_unused]] GradCache3 g1, g2, g3;
    for (size_t i = 0; i < n; ++i) {
        const auto sp = split_all<D>(u, i, scale, pots[0].period());
        if constexpr (D == 3) {
            float d1[3], d2[3], d3[3];
            const float fx = sp.s[0].frac, fy = sp.s[1].frac, fz = sp.s[2].frac;
            g1.load(pots[0], sp.s[0], sp.s[1], sp.s[2]);
            g2.load(pots[1], sp.s[0], sp.s[1], sp.s[2]);
            g3.load(pots[2], sp.s[0], sp.s[1], sp.s[2]);
            gradient3(g1, fx, fy, fz, d1);
            gradient3(g2, fx, fy, fz, d2);
            gradient3(g3, fx, fy, fz, d3);
            out[0][i] += weight * (d3[1] - d2[2]);
            out[1][i] += weight * (d1[2] - d3[0]);
            out[2][i] += weight * (d2[0] - d1[1]);
        } else {
            float d[2];
            gradient2(pots[0], sp.s[0], sp.s[1], d);
            out[0][i] += weight * d[1];
            out[1][i] += weight * -d[0];
        }
    }
}

struct Fractal {
    std::vector<double> scale, amp;
    double norm = 1;
};

Fractal fractal_weights(const FractalParams& f) {
    Fractal r;
    double s = 1, a = 1, norm = 0;
    for (int o = 0; o < f.octaves; ++o, s *= f.lacunarity, a *= f.gain) {
        r.scale.push_back(s);
        r.amp.push_back(a);
        norm += a;
    }
    r.norm = norm > 0 ? norm : 1;
    return r;
}

// Fractal sum of a scalar kernel into acc; returns the range of the result.
template <int D>
ValueRange scalar_fractal(Kernel k, const Plan<D>& plan, const std::array<const double*, D>& u, size_t n, Scratch& sc, float* acc) {
    const NoiseSpec& spec = plan.spec;
    const Fractal fr = fractal_weights(spec.fractal);
    const ValueRange nr = native_range(k);
    const float mid = float(nr.lo + nr.hi) * 0.5f, inv_half = float(2.0 / (nr.hi - nr.lo));
    sc.tmp.resize(n);
    float* tmp = sc.tmp.data();
    std::fill(acc, acc + n, 0.0f);
    for (size_t o = 0; o < fr.scale.size(); ++o) {
        if (fr.amp[o] == 0.0) continue;
        scalar_octave<D>(k, spec, plan.octaves[o], u, n, fr.scale[o], tmp);
        const float a = float(fr.amp[o] / fr.norm);
        switch (spec.fractal.combinator) {
        case Combinator::Fbm:
            for (size_t i = 0; i < n; ++i) acc[i] += a * tmp[i];
            break;
        case Combinator::Turbulence:
            for (size_t i = 0; i < n; ++i) acc[i] += a * std::fabs((tmp[i] - mid) * inv_half);
            break;
        case Combinator::Billow:
            for (size_t i = 0; i < n; ++i) acc[i] += a * (2.0f * std::fabs((tmp[i] - mid) * inv_half) - 1.0f);
            break;
        case Combinator::Ridged:
            for (size_t i = 0; i < n; ++i) {
                const float r = 1.0f - std::fabs((tmp[i] - mid) * inv_half);
                acc[i] += a * r * r;
            }
            break;
        }
    }
    // gain 0 leaves only octave 0 with weight 1; keep rounding inside the range.
    switch (spec.fractal.combinator) {
    case Combinator::Fbm: break;
    case Combinator::Turbulence:
    case Combinator::Ridged: return {0, 1};
    case Combinator::Billow: return {-1, 1};
    }
    return nr;
}

void clamp_span(float* v, size_t n, ValueRange r) {
    for (size_t i = 0; i < n; ++i) v[i] = std::clamp(v[i], float(r.lo), float(r.hi));
}

// invert, fold, remap (normalize is done by fill_noise).
void output_stage(const OutputParams& o, ValueRange r, float* v, size_t n) {
    if (o.invert)
        for (size_t i = 0; i < n; ++i) v[i] = float(r.lo + r.hi) - v[i];
    if (o.fold_count > 0) {
        const float lo = float(r.lo), inv = float(1.0 / (r.hi - r.lo));
        for (size_t i = 0; i < n; ++i) {
            float t = std::clamp((v[i] - lo) * inv, 0.0f, 1.0f);
            for (int f = 0; f < o.fold_count; ++f) t = std::fabs(2.0f * t - 1.0f);
            v[i] = t;
        }
    }
    if (o.remap) {
        const double s = (o.out_max - o.out_min) / (o.in_max - o.in_min);
        const float lo = float(std::min(o.out_min, o.out_max)), hi = float(std::max(o.out_min, o.out_max));
        for (size_t i = 0; i < n; ++i) {
            float m = float(o.out_min + (double(v[i]) - o.in_min) * s);
            if (o.clamp) m = std::clamp(m, lo, hi);
            v[i] = m;
        }
    }
}

} // namespace

template <int D>
Plan<D>::Plan(const NoiseSpec& s, int64_t tabulate) : spec(s) {
    for (int a = 0; a < D; ++a) period[a] = s.period[a];
    const int oct = s.fractal.octaves;
    if (s.kernel == Kernel::Curl) {
        for (int o = 0; o < oct; ++o)
            for (int c = 0; c < potentials; ++c)
                curl.emplace_back(scaled<D>(period, ipow(s.fractal.lacunarity, o)), octave_seed(s.seed, o), kStreamCurl + uint32_t(c), tabulate);
    } else {
        for (int o = 0; o < oct; ++o)
            octaves.emplace_back(scaled<D>(period, ipow(s.fractal.lacunarity, o)), octave_seed(s.seed, o), kStreamMain, tabulate);
    }
    if (s.kernel == Kernel::PerlinWorley)
        for (int o = 0; o < s.perlin_worley.worley_octaves; ++o)
            pw_worley.emplace_back(scaled<D>(period, int64_t(s.perlin_worley.worley_frequency_ratio) << o), octave_seed(s.seed, o),
                                   kStreamPwWorley, tabulate);
    if (s.kernel == Kernel::CurlyAlligator)
        for (int c = 0; c < potentials; ++c)
            curly.emplace_back(scaled<D>(period, s.curly.curl_frequency_ratio), s.seed, kStreamCurly + uint32_t(c), tabulate);
}

template <int D>
void evaluate(const Plan<D>& plan, const std::array<const double*, D>& u_in, size_t n, float* const* out, Scratch& sc) {
    const NoiseSpec& spec = plan.spec;
    std::array<const double*, D> u = u_in;

    if (spec.kernel == Kernel::Curl) {
        const Fractal fr = fractal_weights(spec.fractal);
        for (int c = 0; c < D; ++c) std::fill(out[c], out[c] + n, 0.0f);
        for (size_t o = 0; o < fr.scale.size(); ++o)
            if (fr.amp[o] != 0.0)
                curl_octave<D>(&plan.curl[o * size_t(plan.potentials)], u, n, fr.scale[o], float(fr.amp[o] / fr.norm), out);
        const ValueRange r = noise_output_range(NoiseSpec{.kernel = Kernel::Curl}, D);
        for (int c = 0; c < D; ++c) output_stage(spec.output, r, out[c], n);
        return;
    }

    if (spec.kernel == Kernel::CurlyAlligator) {
        // Displace the lookup by the curl field (periodic in the base period).
        sc.comp.assign(size_t(D) * n, 0.0f);
        float* comp[3] = {sc.comp.data(), sc.comp.data() + n, D == 3 ? sc.comp.data() + 2 * n : nullptr};
        curl_octave<D>(plan.curly.data(), u, n, double(spec.curly.curl_frequency_ratio), 1.0f, comp);
        const double k = spec.curly.curl_strength;
        for (int a = 0; a < D; ++a) {
            sc.coords[size_t(a)].resize(n);
            double* c = sc.coords[size_t(a)].data();
            for (size_t i = 0; i < n; ++i) c[i] = wrap_coord(u[a][i] + k * double(comp[a][i]), double(plan.period[a]));
            u[a] = c;
        }
    }

    float* acc = out[0];
    if (spec.kernel == Kernel::PerlinWorley) {
        ValueRange r = scalar_fractal<D>(Kernel::Gradient, plan, u, n, sc, acc);
        const float lo = float(r.lo), inv = float(1.0 / (r.hi - r.lo));
        for (size_t i = 0; i < n; ++i) acc[i] = std::clamp((acc[i] - lo) * inv, 0.0f, 1.0f);
        // Inverted-Worley FBM, lacunarity 2, gain 0.5.
        sc.acc.assign(n, 0.0f);
        sc.tmp.resize(n);
        NoiseSpec ws = spec;
        ws.worley = {};
        double a = 1, norm = 0;
        for (int o = 0; o < spec.perlin_worley.worley_octaves; ++o, a *= 0.5) norm += a;
        a = 1;
        for (int o = 0; o < spec.perlin_worley.worley_octaves; ++o, a *= 0.5) {
            scalar_octave<D>(Kernel::Worley, ws, plan.pw_worley[size_t(o)], u, n,
                             double(int64_t(spec.perlin_worley.worley_frequency_ratio) << o), sc.tmp.data());
            const float w = float(a / norm);
            for (size_t i = 0; i < n; ++i) sc.acc[i] += w * sc.tmp[i];
        }
        // remap(perlin, 0, 1, worley, 1): the Worley FBM is the new minimum.
        for (size_t i = 0; i < n; ++i) {
            const float w = std::clamp(sc.acc[i], 0.0f, 1.0f);
            acc[i] = w + acc[i] * (1.0f - w);
        }
        output_stage(spec.output, {0, 1}, acc, n);
        return;
    }

    ValueRange r = scalar_fractal<D>(spec.kernel, plan, u, n, sc, acc);
    clamp_span(acc, n, r);
    if (spec.kernel == Kernel::CurlyAlligator)
        for (size_t i = 0; i < n; ++i) acc[i] = float(r.lo + r.hi) - acc[i];
    output_stage(spec.output, r, acc, n);
}

template struct Plan<2>;
template struct Plan<3>;
template void evaluate<2>(const Plan<2>&, const std::array<const double*, 2>&, size_t, float* const*, Scratch&);
template void evaluate<3>(const Plan<3>&, const std::array<const double*, 3>&, size_t, float* const*, Scratch&);

} // namespace atlas::noise::detail
