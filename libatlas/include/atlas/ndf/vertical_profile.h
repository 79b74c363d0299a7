// atlas/ndf/vertical_profile.h - density-height gradients by cloud type, and their LUT.
//
// Each cloud type has a rise (bottom) and a fall (top) over the height
// fraction f in [0,1] of its envelope: bottom(f) = smoothstep(b0, b1, f),
// top(f) = 1 - smoothstep(t0, t1, f). Types sit at type = 0 (stratus),
// 1/3 (stratocumulus), 2/3 (cumulus), 1 (cumulonimbus); between them the
// gradients blend linearly (HZD's weighted sum). The HFW split: profile =
// bottom(bottom_type, f) * top(top_type, f) * coverage. Pure, thread-safe.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <array>

namespace atlas::ndf {

// One type's gradient: rise from b0 to b1, fall from t0 to t1 (fractions,
// 0 <= b0 <= b1 <= t0 <= t1 <= 1 expected; b0 == b1 is a hard step).
struct TypeGradient {
    double b0, b1, t0, t1;
};

struct VerticalProfile {
    // Art-editable defaults (fractions of the envelope height), after the
    // shapes of GPU Pro 7 fig. 4.10: stratus thin and low, cumulonimbus full height.
    std::array<TypeGradient, 4> types{{
        {0.00, 0.05, 0.10, 0.25}, // stratus
        {0.00, 0.10, 0.30, 0.55}, // stratocumulus
        {0.00, 0.10, 0.55, 0.85}, // cumulus
        {0.00, 0.05, 0.80, 1.00}, // cumulonimbus
    }};

    // Throws atlas::Error naming the type when a gradient is out of order or not in [0,1].
    void validate() const;
    // Rise of the blended type at f (type and f clamped to [0,1]; NaN -> 0).
    double bottom(double type, double f) const;
    // Fall of the blended type at f.
    double top(double type, double f) const;
    // HZD: the blended full gradient sum_i w_i * bottom_i(f) * top_i(f).
    double density(double type, double f) const;
    // HFW split: bottom(bottom_type, f) * top(top_type, f).
    double split(double top_type, double bottom_type, double f) const;
};

// The LUT: a Field2D of `types` x `heights` texels over [0,1]^2 with channels
// "bottom", "top", "density". Texel (i, j) holds the analytic values at
// type = i / (types - 1), f = j / (heights - 1) (end-aligned), so a renderer
// samples it bilinearly at texel coordinates (0.5 + type * (types - 1),
// 0.5 + f * (heights - 1)). Throws when a size < 2.
Field2D build_profile_lut(const VerticalProfile& profile, int types, int heights, const MemoryBudget* budget);

// Bilinear LUT lookup with the end-aligned addressing above; channel 0..2.
double sample_profile_lut(const Field2D& lut, int channel, double type, double f);

// Max |LUT - analytic| over all channels, evaluated on a grid `oversample`
// times denser than the LUT in both axes (plus the LUT's own texels).
double profile_lut_max_error(const Field2D& lut, const VerticalProfile& profile, int oversample = 8);

} // namespace atlas::ndf
