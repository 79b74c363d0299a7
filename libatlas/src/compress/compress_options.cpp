// The compress options' one schema (compress_options.h): `atlas compress` flags and
// the DDS output options are both read through it.
#include "atlas/compress/compress_options.h"

#include "atlas/core/error.h"

#include <algorithm>

namespace atlas::compress {

namespace {
// Every name parse_format takes, in its order.
std::vector<std::string> format_words() {
    std::vector<std::string> v;
    const std::string list = format_names();
    for (size_t a = 0; a < list.size();) {
        const size_t b = std::min(list.find(", ", a), list.size());
        v.push_back(list.substr(a, b - a));
        a = b + 2;
    }
    return v;
}
std::vector<std::string> decoder_words() {
    std::vector<std::string> v;
    for (int i = 0; i < kDecoderCount; ++i) v.emplace_back(decoder_name(Decoder(i)));
    return v;
}
std::vector<TextOption<CompressOptions>> make_compress_options() {
    using K = OptionKind;
    using C = CompressOptions;
    using V = OptionValue;
    const std::string mips_max = std::to_string(kMaxMipLevels);
    auto opt = [](TextOptionSpec spec, void (*apply)(C&, const V&)) {
        TextOption<C> o{std::move(spec)};
        o.apply = apply;
        return o;
    };
    return {
        opt({"encoding", "--format", "FORMAT", K::Choice,
             std::string("texture format (a dds output's default: ") + format_name(kDdsOutputDefaultFormat) + "; atlas compress requires --format)",
             -INFINITY, INFINITY, format_words()},
            [](C& c, const V& v) { c.format = parse_format(v.word); }),
        opt({"type_encoding", "--type-encoding", "NAME", K::Choice,
             "cloud type convention of channels named type, top_type, bottom_type: atlas (0 stratus, 1/3 stratocumulus, 2/3 cumulus, "
             "1 cumulonimbus; default) or gpu_pro_7 (HZD's 0, 0.5, 1 for stratus, stratocumulus, cumulus; cumulonimbus stored as "
             "cumulus); recorded in the manifest",
             -INFINITY, INFINITY, {type_encoding_name(TypeEncoding::Atlas), type_encoding_name(TypeEncoding::GpuPro7)}},
            [](C& c, const V& v) { c.type_encoding = parse_type_encoding(v.word); }),
        opt({"quality", "--quality", "LEVEL", K::Choice, "encoder effort (default normal; bc4 best: exhaustive, provably optimal)", -INFINITY,
             INFINITY, {quality_name(Quality::Fast), quality_name(Quality::Normal), quality_name(Quality::Best)}},
            [](C& c, const V& v) { c.quality = parse_quality(v.word.c_str()); }),
        opt({"max_error", "--max-error", "E", K::Number,
             "guarantee |decoded - source| <= E (source units) for every texel, or fail listing the blocks; BC1 spends the room under E on the mean error (default: no bound)", 0.0,
             double(std::numeric_limits<float>::max())},
            [](C& c, const V& v) { c.max_error = float(v.number); }),
        opt({"one_sided", "--one-sided", "below", K::Choice, "'below': guarantee decoded <= source (SDFs for sphere tracing); mips are min-reduced",
             -INFINITY, INFINITY, {"below"}},
            [](C& c, const V&) { c.one_sided_below = true; }),
        opt({"allow_over_bound", "--allow-over-bound", "", K::Flag, "write the texture even when some blocks miss max_error (they are listed)"},
            [](C& c, const V& v) { c.allow_over_bound = v.flag; }),
        opt({"decoders", "--decoders", "LIST", K::List, "decoder models the bounds hold for (default all)", -INFINITY, INFINITY, decoder_words()},
            [](C& c, const V& v) {
                c.decoders = 0;
                for (const std::string& d : v.items) c.decoders |= decoder_bit(parse_decoder(d));
            }),
        opt({"mips", "--mips", "N|full", K::Integer, "mip levels: 1.." + mips_max + " or full, the whole chain (default 1: none)", 1.0,
             double(kMaxMipLevels), {"full"}},
            [](C& c, const V& v) { c.mip_levels = v.word == "full" ? 0 : int(v.number); }),
        opt({"range", "--range", "LO,HI", K::Range, "source values mapped to the format's 0..1 (default: the data's min and max)",
             -double(std::numeric_limits<float>::max()), double(std::numeric_limits<float>::max())},
            [](C& c, const V& v) { c.value_range = std::make_pair(float(v.lo), float(v.hi)); }),
        opt({"channels", "--channels", "NAMES", K::List, "input channels to store, by name (default: the first ones the format needs)"},
            [](C& c, const V& v) { c.channel_names = v.items; }),
        opt({"array", "--array", "", K::Flag, "store a 3D input as a 2D texture array instead of a volume"},
            [](C& c, const V& v) { c.as_array = v.flag; }),
    };
}
} // namespace

std::span<const TextOption<CompressOptions>> compress_options() {
    static const std::vector<TextOption<CompressOptions>> options = make_compress_options();
    return options;
}

void resolve_channel_names(CompressOptions& options, const Field3D& field) {
    if (options.channel_names.empty()) return;
    options.channels.clear();
    for (const std::string& name : options.channel_names) {
        const int c = field.find_channel(name);
        if (c < 0) {
            std::string have;
            for (const std::string& n : field.channel_names()) have += (have.empty() ? "" : ", ") + n;
            throw Error("'channels': the field has no channel '" + name + "' (it has: " + have + ")");
        }
        options.channels.push_back(c);
    }
}

} // namespace atlas::compress
