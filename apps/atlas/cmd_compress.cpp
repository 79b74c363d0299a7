// atlas compress / atlas decompress: fields to BC / uncompressed DDS textures and back.
#include "cli.h"
#include "progress_bar.h"

#include "atlas/compress/compress_options.h"
#include "atlas/compress/texture.h"
#include "atlas/core/files.h"
#include "atlas/io/dds_file.h"
#include "atlas/io/readers.h"
#include "atlas/io/writers.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <iostream>

namespace atlas::cli {

namespace {

// Every option through the compress schema (atlas/compress/compress_options.h), the
// one a graph's dds output parses its options with.
// Channel names are resolved once the input is read (resolve_channels).
compress::CompressOptions parse_compress_options(const Args& a) {
    compress::CompressOptions o;
    if (!a.has("--format")) throw UsageError{"--format is required (" + compress::format_names() + ")", "compress"};
    read_schema_flags(a, compress::compress_options(), o, "compress");
    return o;
}

void resolve_channels(compress::CompressOptions& o, const Field3D& field) {
    try {
        compress::resolve_channel_names(o, field);
    } catch (const Error& e) {
        throw Error(std::string("--channels: ") + e.what());
    }
}

void print_report(const compress::CompressReport& r) {
    std::printf("%s: %s %dx%dx%d%s, %d mip level(s), value range [%g, %g]\n", r.file.c_str(), r.format.c_str(), r.width, r.height, r.depth,
                r.array_size > 1 ? (" x" + std::to_string(r.array_size)).c_str() : "", r.mip_levels, r.value_range.first, r.value_range.second);
    for (size_t c = 0; c < r.max_error.size(); ++c)
        std::printf("  channel %zu: max error %.6g  RMSE %.6g  PSNR %.2f dB\n", c, r.max_error[c], r.rmse[c], r.psnr[c]);
    std::printf("  guaranteed max error over all decoders: %.6g%s\n", r.bound_max_error,
                r.requested_max_error ? (" (requested " + std::to_string(*r.requested_max_error) + ")").c_str() : "");
    std::printf("  blocks over the bound: %zu%s\n", r.blocks_over_bound.size(),
                r.blocks_over_bound.empty() ? "" : " (DDS texel of the block's corner: x column, y row from the top, z slice)");
    for (size_t i = 0; i < r.blocks_over_bound.size() && i < 20; ++i) {
        const auto& b = r.blocks_over_bound[i];
        std::printf("    block at (%d, %d, %d) mip %d: best error %.6g%s\n", b.x, b.y, b.z, b.mip, b.best_error,
                    b.one_sided_failed ? " (one-sided not met)" : "");
    }
    std::printf("  encode %.3f s, %.3g texels/s, %llu bytes\n", r.encode_seconds, r.texels_per_second, (unsigned long long)r.bytes);
}

void print_verify(const compress::CompressReport& v) {
    std::printf("  verify (decoded file against the source):\n");
    for (const auto& d : v.per_decoder) {
        double worst = 0;
        for (double e : d.max_error) worst = std::max(worst, e);
        std::printf("    %-11s max error %.6g  max over source %.6g  one-sided violations %llu  mean under %.6g\n",
                    compress::decoder_name(d.decoder), worst, d.max_over, (unsigned long long)d.one_sided_violations, d.mean_under);
    }
}

} // namespace

int run_compress(const Args& a) {
    if (a.positional.size() != 1) throw UsageError{"expected one input file", "compress"};
    const std::string in = a.positional[0];
    // Usage errors before the (possibly long) read of the input.
    if (!a.has("--sweep") && !a.has("--out")) throw UsageError{"-o OUT.dds is required", "compress"};
    compress::CompressOptions o = parse_compress_options(a);
    // No written file may replace the input (or be a link or a device), checked before the read.
    const std::vector<ProtectedFile> input = {{in, "the input file"}};
    for (const char* flag : {"--out", "--report", "--csv"})
        if (a.has(flag)) check_destination(a.get(flag), input, std::string(flag + 2) + " file");
    const MemoryBudget budget(a.has("--memory-budget") ? parse_byte_size(a.get("--memory-budget")) : MemoryBudget::kDefaultLimit);
    Field3DPtr field = io::as_field3d(io::read_field_file(in, &budget));
    resolve_channels(o, *field);

    if (a.has("--sweep")) {
        auto rows = compress::sweep(*field, o);
        std::printf("quality,max_error,rmse,seconds\n");
        for (const auto& r : rows) std::printf("%s,%.8g,%.8g,%.6f\n", compress::quality_name(r.quality), r.max_error, r.rmse, r.seconds);
        if (a.has("--csv")) {
            std::ostringstream csv;
            csv << "quality,max_error,rmse,seconds\n";
            for (const auto& r : rows) csv << compress::quality_name(r.quality) << "," << r.max_error << "," << r.rmse << "," << r.seconds << "\n";
            const std::string text = csv.str();
            // write_file_checked: a full disk says why, where an ofstream said nothing.
            write_file_atomic(a.get("--csv"), [&](const fs::path& tmp) { write_file_checked(tmp, text.data(), text.size()); }, input);
        }
        return 0;
    }
    if (!a.has("--out")) throw UsageError{"-o OUT.dds is required", "compress"};
    const std::string out = a.get("--out");
    ProgressBar bar(!a.has("--quiet"));
    ProgressSink sink = bar.sink();
    compress::CompressReport r;
    try {
        r = io::compress_to_dds(*field, out, o, &sink);
    } catch (const compress::BoundError& e) {
        bar.finish();
        print_report(e.report());
        throw;
    }
    bar.finish();
    print_report(r);
    const bool bounded = o.max_error || o.one_sided_below;
    if ((bounded && !a.has("--no-verify")) || a.has("--verify")) print_verify(io::verify_dds(out, *field, o.decoders, o.channels));
    if (a.has("--report")) {
        std::string json = r.to_json();
        write_file_atomic(a.get("--report"), [&](const fs::path& tmp) { write_file_checked(tmp, json.data(), json.size()); },
                          {{in, "the input file"}, {out, "the compressed texture"}});
    }
    return 0;
}

int run_decompress(const Args& a) {
    if (a.positional.size() != 1) throw UsageError{"expected one input .dds file", "decompress"};
    if (!a.has("--out")) throw UsageError{"-o OUT.exr is required", "decompress"};
    const compress::Decoder decoder = a.has("--decoder") ? compress::parse_decoder(a.get("--decoder")) : compress::Decoder::Reference;
    const std::vector<ProtectedFile> input = {{a.positional[0], "the input file"}};
    check_destination(a.get("--out"), input, "output");
    auto field = std::make_shared<Field3D>(io::read_dds(a.positional[0], decoder));
    const fs::path out = a.get("--out");
    Value v = Field3DPtr(field);
    if (field->nz() == 1) {
        auto f2 = std::make_shared<Field2D>(Vec2i{{field->nx(), field->ny()}}, field->channels(),
                                            Box2d{{{field->bounds().min[0], field->bounds().min[1]}}, {{field->bounds().max[0], field->bounds().max[1]}}},
                                            field->channel_names());
        for (int c = 0; c < field->channels(); ++c) std::copy(field->channel(c).begin(), field->channel(c).end(), f2->channel(c).begin());
        v = Field2DPtr(f2);
    }
    const std::string format = io::output_format_for_path(out);
    write_file_atomic(out, [&](const fs::path& tmp) { io::write_value(v, tmp, format, {}); }, input);
    std::printf("%s\n", out.string().c_str());
    return 0;
}

} // namespace atlas::cli
