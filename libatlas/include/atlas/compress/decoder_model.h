// atlas/compress/decoder_model.h - the BC1/BC4 decoders an encoder guarantees its bounds for.
//
// The D3D specification defines BC1 and BC4 decoding with a tolerance, and real
// decoders differ in how they round the interpolated palette entries. Atlas models
// each of them exactly (see docs/compression.md for the formulas and sources):
//   Reference   exact float interpolation of the UNORM/SNORM endpoints (D3D reference)
//   Nvidia      NVIDIA's published BC1 interpolation (5-bit R/B, 8-bit G fixed point)
//   Amd         AMD's published BC1 interpolation ((43*c0 + 21*c1 + 32) / 64 on 8 bits)
//   Tool8       8-bit integer tool decoders (squish, OpenImageIO 2.4, bcdec): endpoints
//               expanded to 8 bits, interpolation truncated to 8 bits
//   Tool8Round  8-bit decoders that round the interpolation to nearest instead
//               (OpenImageIO 2.4's DDS reader, Compressonator's BC4 "+3"): BC1
//               (2a+b+1)/3, (a+b+1)/2 on expanded endpoints; BC4 (num + k/2) / k
//   Conformant  any decoder within the tolerance Atlas assumes for conforming hardware
//               (Atlas's model, not spec text): BC4 interpolants +-1/255; BC1 entries
//               +-(2/255 + 3% of the endpoints' per-channel difference). It contains
//               every other model (tested), NVIDIA's 6-bit green deviating most.
// For BC4, Nvidia and Amd interpolate with >= 16 bits and are modelled as Reference.
// A guarantee "under a DecoderSet" holds for every decoder model in the set.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace atlas::compress {

enum class Decoder : uint8_t { Reference = 0, Nvidia = 1, Amd = 2, Tool8 = 3, Conformant = 4, Tool8Round = 5 };
constexpr int kDecoderCount = 6;

// Bit set of Decoder values (bit i = Decoder i).
using DecoderSet = uint32_t;
constexpr DecoderSet decoder_bit(Decoder d) { return DecoderSet(1) << static_cast<int>(d); }
// Every modelled decoder: the strongest guarantee.
constexpr DecoderSet kAllDecoders = (DecoderSet(1) << kDecoderCount) - 1;
constexpr DecoderSet kReferenceOnly = decoder_bit(Decoder::Reference);

// The tolerance (fraction of full range) the Conformant model allows around Reference:
// BC4 interpolated entries: kConformantTolerance; BC1 palette entries:
// kBc1ConformantBase + kConformantRelative * |endpoint0 - endpoint1| per channel.
constexpr float kConformantTolerance = 1.0f / 255.0f;
constexpr float kBc1ConformantBase = 2.0f / 255.0f;
constexpr float kConformantRelative = 0.03f;

// Conformant tolerance of a BC1 palette entry in one channel, given the Reference
// values of the two endpoints in that channel.
inline float bc1_conformant_tolerance(float ref0, float ref1) {
    const float d = ref0 > ref1 ? ref0 - ref1 : ref1 - ref0;
    return kBc1ConformantBase + kConformantRelative * d;
}

// "reference", "nvidia", "amd", "tool8", "conformant", "tool8-round".
const char* decoder_name(Decoder d);
// Parses a name above; throws atlas::Error naming the accepted values.
Decoder parse_decoder(const std::string& name);
// "reference, nvidia, amd, tool8, conformant, tool8-round": every name parse_decoder takes.
std::string decoder_names();
// The decoders in a set, in enum order.
std::vector<Decoder> decoders_in(DecoderSet set);

} // namespace atlas::compress
