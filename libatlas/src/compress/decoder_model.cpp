#include "atlas/compress/decoder_model.h"

#include "atlas/core/error.h"

namespace atlas::compress {

const char* decoder_name(Decoder d) {
    switch (d) {
    case Decoder::Reference: return "reference";
    case Decoder::Nvidia: return "nvidia";
    case Decoder::Amd: return "amd";
    case Decoder::Tool8: return "tool8";
    case Decoder::Conformant: return "conformant";
    case Decoder::Tool8Round: return "tool8-round";
    }
    return "?";
}

std::string decoder_names() {
    std::string s;
    for (int i = 0; i < kDecoderCount; ++i) s += (i ? ", " : "") + std::string(decoder_name(static_cast<Decoder>(i)));
    return s;
}

Decoder parse_decoder(const std::string& name) {
    for (int i = 0; i < kDecoderCount; ++i)
        if (name == decoder_name(static_cast<Decoder>(i))) return static_cast<Decoder>(i);
    throw Error("unknown decoder model '" + name + "' (expected one of: " + decoder_names() + ")");
}

std::vector<Decoder> decoders_in(DecoderSet set) {
    std::vector<Decoder> out;
    for (int i = 0; i < kDecoderCount; ++i)
        if (set & (DecoderSet(1) << i)) out.push_back(static_cast<Decoder>(i));
    return out;
}

} // namespace atlas::compress
