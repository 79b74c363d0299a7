#include "atlas/noise/noise_spec.h"

#include "atlas/core/error.h"
#include "atlas/core/option_schema.h"

#include <cmath>
#include <string>

namespace atlas::noise {
namespace {


void check_range(const char* name, double v, double lo, double hi) {
    if (!(v >= lo && v <= hi))
        throw Error(std::string("noise: ") + name + " = " + detail::number_text(v) + " is out of range [" + detail::number_text(lo) + ", " + detail::number_text(hi) + "]");
}

} // namespace

void FractalParams::validate() const {
    check_range("fractal.octaves", octaves, 1, 16);
    check_range("fractal.lacunarity", lacunarity, 1, 1024);
    check_range("fractal.gain", gain, 0, 4);
}

void WorleyParams::validate() const { check_range("worley.jitter", jitter, 0, 1); }

void PerlinWorleyParams::validate() const {
    check_range("perlin_worley.worley_octaves", worley_octaves, 1, 8);
    check_range("perlin_worley.worley_frequency_ratio", worley_frequency_ratio, 1, 64);
}

void AlligatorParams::validate() const { check_range("alligator.radius", radius, 0.25, 1); }

void CurlyAlligatorParams::validate() const {
    check_range("curly.curl_strength", curl_strength, 0, 16);
    check_range("curly.curl_frequency_ratio", curl_frequency_ratio, 1, 64);
}

void OutputParams::validate() const {
    check_range("output.fold_count", fold_count, 0, 8);
    for (double v : {in_min, in_max, out_min, out_max})
        if (!std::isfinite(v)) throw Error("noise: output remap bounds must be finite");
    if (remap && !(in_max != in_min)) throw Error("noise: output.in_max must differ from output.in_min (got both " + detail::number_text(in_min) + ")");
}

void NoiseSpec::validate(int dims) const {
    if (dims != 2 && dims != 3) throw Error("noise: dims must be 2 or 3");
    constexpr double kMaxPeriod = double(1 << 30);
    const char* pnames[3] = {"period.x", "period.y", "period.z"};
    const char* onames[3] = {"offset.x", "offset.y", "offset.z"};
    for (int a = 0; a < dims; ++a) {
        check_range(pnames[a], period[a], 1, kMaxPeriod);
        if (!std::isfinite(offset[a])) throw Error(std::string("noise: ") + onames[a] + " must be finite");
    }
    check_range("frequency", frequency, 0, 1e6);
    fractal.validate();
    worley.validate();
    perlin_worley.validate();
    alligator.validate();
    curly.validate();
    output.validate();
    // Every lattice used must keep an integer period <= 2^30 cells.
    int extra = 1;
    if (kernel == Kernel::PerlinWorley) extra = perlin_worley.worley_frequency_ratio * (1 << (perlin_worley.worley_octaves - 1));
    if (kernel == Kernel::CurlyAlligator) extra = std::max(1, curly.curl_frequency_ratio);
    for (int a = 0; a < dims; ++a) {
        double p = double(period[a]) * extra;
        for (int o = 1; o < fractal.octaves; ++o) p *= fractal.lacunarity;
        if (p > kMaxPeriod)
            throw Error(std::string("noise: ") + pnames[a] + " x fractal.lacunarity^(octaves-1) = " + detail::number_text(p) +
                        " lattice cells exceeds 2^30; lower fractal.lacunarity, fractal.octaves or the period");
    }
    if (kernel == Kernel::Curl && fractal.combinator != Combinator::Fbm)
        throw Error("noise: fractal.combinator must be fbm for the curl kernel (other combinators are not divergence-free)");
    if (kernel == Kernel::Curl && output.fold_count > 0) throw Error("noise: output.fold_count must be 0 for the curl kernel");
}

int noise_components(Kernel kernel, int dims) { return kernel == Kernel::Curl ? dims : 1; }

namespace {
ValueRange kernel_range(Kernel k, int dims) {
    switch (k) {
    case Kernel::Gradient: return {-1, 1};
    case Kernel::Curl: return {-21.0 * (dims == 3 ? 1 : 0.5), 21.0 * (dims == 3 ? 1 : 0.5)};
    default: return {0, 1};
    }
}
} // namespace

ValueRange noise_output_range(const NoiseSpec& spec, int dims) {
    ValueRange r = kernel_range(spec.kernel, dims);
    if (spec.kernel != Kernel::PerlinWorley) {
        switch (spec.fractal.combinator) {
        case Combinator::Fbm: break;
        case Combinator::Turbulence: r = {0, 1}; break;
        case Combinator::Billow: r = {-1, 1}; break;
        case Combinator::Ridged: r = {0, 1}; break;
        }
    }
    if (spec.output.fold_count > 0) r = {0, 1};
    if (spec.output.remap || spec.output.normalize) {
        r = {std::min(spec.output.out_min, spec.output.out_max), std::max(spec.output.out_min, spec.output.out_max)};
        if (spec.output.remap && !spec.output.clamp && !spec.output.normalize) r = {-HUGE_VAL, HUGE_VAL};
    }
    return r;
}

std::string_view kernel_name(Kernel k) {
    switch (k) {
    case Kernel::Gradient: return "gradient";
    case Kernel::Value: return "value";
    case Kernel::Worley: return "worley";
    case Kernel::PerlinWorley: return "perlin-worley";
    case Kernel::Alligator: return "alligator";
    case Kernel::CurlyAlligator: return "curly-alligator";
    case Kernel::Curl: return "curl";
    }
    return "?";
}

Kernel parse_kernel(std::string_view n) {
    for (Kernel k : {Kernel::Gradient, Kernel::Value, Kernel::Worley, Kernel::PerlinWorley, Kernel::Alligator,
                     Kernel::CurlyAlligator, Kernel::Curl})
        if (kernel_name(k) == n) return k;
    throw Error("noise: unknown kernel '" + std::string(n) +
                "' (expected gradient, value, worley, perlin-worley, alligator, curly-alligator or curl)");
}

WorleyFeature parse_worley_feature(std::string_view n) {
    if (n == "f1") return WorleyFeature::F1;
    if (n == "f2") return WorleyFeature::F2;
    if (n == "f2-f1") return WorleyFeature::F2MinusF1;
    if (n == "inverted-f1") return WorleyFeature::InvertedF1;
    throw Error("noise: unknown worley feature '" + std::string(n) + "' (expected f1, f2, f2-f1 or inverted-f1)");
}

WorleyMetric parse_worley_metric(std::string_view n) {
    if (n == "euclidean") return WorleyMetric::Euclidean;
    if (n == "manhattan") return WorleyMetric::Manhattan;
    if (n == "chebyshev") return WorleyMetric::Chebyshev;
    throw Error("noise: unknown worley metric '" + std::string(n) + "' (expected euclidean, manhattan or chebyshev)");
}

Combinator parse_combinator(std::string_view n) {
    if (n == "fbm") return Combinator::Fbm;
    if (n == "turbulence") return Combinator::Turbulence;
    if (n == "billow") return Combinator::Billow;
    if (n == "ridged") return Combinator::Ridged;
    throw Error("noise: unknown combinator '" + std::string(n) + "' (expected fbm, turbulence, billow or ridged)");
}

} // namespace atlas::noise
