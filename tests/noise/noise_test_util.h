// Shared helpers for the noise tests: every kernel variant as a named spec.
#pragma once

#include "atlas/noise/fill.h"
#include "atlas/noise/noise_spec.h"

#include <string>
#include <vector>

namespace atlas::noise::test {

struct NamedSpec {
    std::string name;
    NoiseSpec spec;
};

inline NoiseSpec make(Kernel k, int period = 3, uint32_t seed = 7) {
    NoiseSpec s;
    s.kernel = k;
    s.period = {{period, period + 1, period + 2}}; // unequal periods catch axis mix-ups
    s.seed = seed;
    return s;
}

// Every kernel and Worley feature/metric at one octave.
inline std::vector<NamedSpec> all_kernels() {
    std::vector<NamedSpec> r;
    r.push_back({"gradient", make(Kernel::Gradient)});
    r.push_back({"value", make(Kernel::Value)});
    const char* fnames[] = {"f1", "f2", "f2-f1", "inverted-f1"};
    const char* mnames[] = {"euclidean", "manhattan", "chebyshev"};
    for (const char* f : fnames)
        for (const char* m : mnames) {
            NoiseSpec s = make(Kernel::Worley);
            s.worley.feature = parse_worley_feature(f);
            s.worley.metric = parse_worley_metric(m);
            r.push_back({std::string("worley-") + f + "-" + m, s});
        }
    r.push_back({"perlin-worley", make(Kernel::PerlinWorley)});
    r.push_back({"alligator", make(Kernel::Alligator)});
    r.push_back({"curly-alligator", make(Kernel::CurlyAlligator)});
    r.push_back({"curl", make(Kernel::Curl)});
    return r;
}

// all_kernels() plus fractal, folded and inverted variants.
inline std::vector<NamedSpec> all_variants() {
    std::vector<NamedSpec> r = all_kernels();
    const size_t base = r.size();
    for (size_t i = 0; i < base; ++i) {
        NamedSpec fbm = r[i];
        fbm.name += "+fbm4";
        fbm.spec.fractal.octaves = 4;
        fbm.spec.fractal.lacunarity = 3;
        r.push_back(fbm);
        if (r[i].spec.kernel == Kernel::Curl) continue;
        for (Combinator c : {Combinator::Turbulence, Combinator::Billow, Combinator::Ridged}) {
            NamedSpec v = r[i];
            v.name += "+comb" + std::to_string(int(c));
            v.spec.fractal.octaves = 3;
            v.spec.fractal.combinator = c;
            r.push_back(v);
        }
        NamedSpec fold = r[i];
        fold.name += "+fold2+invert";
        fold.spec.output.fold_count = 2;
        fold.spec.output.invert = true;
        r.push_back(fold);
    }
    return r;
}

} // namespace atlas::noise::test
