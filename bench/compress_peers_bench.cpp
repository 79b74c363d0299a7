// Atlas's BC1 / BC4 encoders side by side with libsquish (and rgbcx from bc7enc_rdo when
// -DATLAS_PEERS_DIR holds rgbcx.h and a librgbcx.a built from it) on the same inputs, in one run:
// single-thread CPU time per image and the error of the decoded result (Reference decoder,
// in 8-bit steps). Built only when libsquish is found (Debian libsquish-dev).
//
// Inputs: a smooth field (gradient + value noise, 512x512) and natural images (PNG
// renders the project generates, docs/images/, or files named by ATLAS_PEER_IMAGES,
// ':'-separated). Every encoder gets the same 8-bit source (squish needs 8-bit);
// BC4 inputs are the images' luminance.
//
// Extra modes used by bench/compare_nvcompress.sh:
//   compress_peers_bench --write-inputs DIR   writes the inputs as PNG (RGB and grey)
//   compress_peers_bench --rmse FILE.dds SOURCE.png   RMSE / max error of a DDS (our decoder)
#include "sdf_volume.h"
#include "atlas/compress/bc1.h"
#include "atlas/compress/bc4.h"
#include "atlas/compress/texture.h"
#include "atlas/io/dds_file.h"

#include <OpenImageIO/imageio.h>
#include <benchmark/benchmark.h>
#include <squish.h>
#if defined(ATLAS_BENCH_RGBCX)
#include <rgbcx.h>
#endif
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <memory>
#include <utility>
#include <string>
#include <vector>

namespace {

using namespace atlas::compress;
using atlas::io::read_dds;

// 8-bit RGB image, width and height multiples of 4.
struct Image {
    std::string name;
    int w = 0, h = 0;
    std::vector<uint8_t> rgb; // 3 per texel
    uint8_t grey(size_t i) const { // Rec. 709 luminance, rounded
        return uint8_t(std::lround(0.2126 * rgb[3 * i] + 0.7152 * rgb[3 * i + 1] + 0.0722 * rgb[3 * i + 2]));
    }
};

double hash01(int x, int y, int s) {
    uint32_t h = uint32_t(x) * 0x8da6b343u ^ uint32_t(y) * 0xd8163841u ^ uint32_t(s) * 0xcb1ab31fu;
    h ^= h >> 13; h *= 0x5bd1e995u; h ^= h >> 15;
    return double(h) / 4294967296.0;
}

// Value noise, bilinear between lattice points `cell` texels apart.
double value_noise(double x, double y, int cell, int seed) {
    const int ix = int(std::floor(x / cell)), iy = int(std::floor(y / cell));
    const double fx = x / cell - ix, fy = y / cell - iy;
    const double sx = fx * fx * (3 - 2 * fx), sy = fy * fy * (3 - 2 * fy);
    const double a = hash01(ix, iy, seed), b = hash01(ix + 1, iy, seed), c = hash01(ix, iy + 1, seed), d = hash01(ix + 1, iy + 1, seed);
    return (a * (1 - sx) + b * sx) * (1 - sy) + (c * (1 - sx) + d * sx) * sy;
}

// n x n; the 64x64 one is a small texture (a tile, a small DDS output), where an encoder's
// per-texture set-up weighs most.
Image smooth_image(int n) {
    Image im;
    im.name = "smooth " + std::to_string(n) + "x" + std::to_string(n) + " (gradient + noise)";
    im.w = im.h = n;
    im.rgb.resize(size_t(im.w) * size_t(im.h) * 3);
    for (int y = 0; y < im.h; ++y)
        for (int x = 0; x < im.w; ++x)
            for (int c = 0; c < 3; ++c) {
                const double g = (x + (c + 1) * 0.5 * y) / (im.w * (1 + 0.5 * (c + 1)));
                const double v = 0.7 * g + 0.2 * value_noise(x, y, 32, c) + 0.1 * value_noise(x, y, 8, c + 7);
                im.rgb[(size_t(y) * size_t(im.w) + size_t(x)) * 3 + size_t(c)] = uint8_t(std::lround(std::clamp(v, 0.0, 1.0) * 255));
            }
    return im;
}

bool load_png(const std::string& path, Image& im) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) return false;
    const OIIO::ImageSpec& spec = in->spec();
    std::vector<uint8_t> px(size_t(spec.width) * size_t(spec.height) * size_t(spec.nchannels));
    if (!in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, px.data())) return false;
    im.w = spec.width / 4 * 4;
    im.h = spec.height / 4 * 4;
    if (im.w == 0 || im.h == 0) return false;
    im.rgb.resize(size_t(im.w) * size_t(im.h) * 3);
    for (int y = 0; y < im.h; ++y)
        for (int x = 0; x < im.w; ++x)
            for (int c = 0; c < 3; ++c)
                im.rgb[(size_t(y) * size_t(im.w) + size_t(x)) * 3 + size_t(c)] =
                    px[(size_t(y) * size_t(spec.width) + size_t(x)) * size_t(spec.nchannels) + size_t(std::min(c, spec.nchannels - 1))];
    const size_t slash = path.find_last_of('/');
    im.name = path.substr(slash == std::string::npos ? 0 : slash + 1) + " " + std::to_string(im.w) + "x" + std::to_string(im.h);
    return true;
}

std::vector<Image> inputs() {
    std::vector<Image> out{smooth_image(512), smooth_image(64)};
    std::string list;
    if (const char* env = std::getenv("ATLAS_PEER_IMAGES")) list = env;
    else
        list = std::string(ATLAS_SOURCE_DIR) + "/docs/images/render_cloudscape_inside.png:" + ATLAS_SOURCE_DIR +
               "/docs/images/ndf_hzd_weather.png";
    size_t start = 0;
    while (start <= list.size()) {
        const size_t end = std::min(list.find(':', start), list.size());
        Image im;
        if (end > start && load_png(list.substr(start, end - start), im)) out.push_back(std::move(im));
        start = end + 1;
    }
    return out;
}

// Errors of decoded values against the 8-bit source, in 8-bit steps.
struct Errors {
    double sq = 0, max = 0;
    size_t n = 0;
    void add(double decoded01, uint8_t src) {
        const double d = (decoded01 - src / 255.0) * 255.0;
        sq += d * d;
        max = std::max(max, std::fabs(d));
        ++n;
    }
    double rmse() const { return n ? std::sqrt(sq / double(n)) : 0; }
};

// AtlasNormalWithinItsMax: `normal` given a bound equal to the largest block error of an
// unbounded `normal` encode of the same image (found before the clock starts): the max error
// is no worse than the unbounded encode's, and the encoder spends the room on squared error.
enum class Codec { AtlasFast, AtlasNormal, AtlasBest, AtlasNormalAll, AtlasNormalWithinItsMax, SquishRange, SquishCluster, SquishIterative, RgbcxDefault, RgbcxHq };

// Thread CPU seconds: the machine is shared, so wall time overstates every encoder's cost.
double cpu_now() {
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return double(ts.tv_sec) + 1e-9 * double(ts.tv_nsec);
}

const char* codec_name(Codec c) {
    switch (c) {
    case Codec::AtlasFast: return "atlas_fast";
    case Codec::AtlasNormal: return "atlas_normal";
    case Codec::AtlasBest: return "atlas_best";
    case Codec::AtlasNormalAll: return "atlas_normal_all6decoders";
    case Codec::AtlasNormalWithinItsMax: return "atlas_normal_within_its_max";
    case Codec::SquishRange: return "squish_fast_rangefit";
    case Codec::SquishCluster: return "squish_normal_clusterfit";
    case Codec::SquishIterative: return "squish_best_iterativeclusterfit";
    case Codec::RgbcxDefault: return "rgbcx_default";
    case Codec::RgbcxHq: return "rgbcx_best";
    }
    return "?";
}

bool is_atlas(Codec c) {
    return c == Codec::AtlasFast || c == Codec::AtlasNormal || c == Codec::AtlasBest || c == Codec::AtlasNormalAll || c == Codec::AtlasNormalWithinItsMax;
}

BlockOptions atlas_options(Codec c) {
    BlockOptions o;
    o.quality = c == Codec::AtlasFast ? Quality::Fast : c == Codec::AtlasBest ? Quality::Best : Quality::Normal;
    o.decoders = c == Codec::AtlasNormalAll ? kAllDecoders : kReferenceOnly; // squish targets one decoder too
    return o;
}

// Encodes the whole image single-threaded; returns seconds, fills the errors. As for BC4,
// the blocks' texels are gathered before the clock starts, in each encoder's input type
// (8-bit RGBA for the peers, float RGB for Atlas), so only the encoders are timed.
// bound >= 0 (normalized units): Atlas's max_error (the BC1 bound sweep).
double run_bc1(const Image& im, Codec codec, Errors& err, float bound = -1.0f) {
    const int bw = im.w / 4, bh = im.h / 4;
    const size_t nblocks = size_t(bw) * size_t(bh);
    std::vector<uint8_t> blocks(nblocks * 8);
    BlockOptions o = atlas_options(codec);
    if (bound >= 0) o.max_error = bound;
    const int flags = squish::kDxt1 | (codec == Codec::SquishRange ? squish::kColourRangeFit
                                       : codec == Codec::SquishIterative ? squish::kColourIterativeClusterFit
                                                                         : squish::kColourClusterFit);
    std::vector<uint8_t> rgba(nblocks * 64);
    std::vector<float> rgbf(nblocks * 48);
    for (int by = 0; by < bh; ++by)
        for (int bx = 0; bx < bw; ++bx) {
            const size_t b = size_t(by) * size_t(bw) + size_t(bx);
            for (int t = 0; t < 16; ++t) {
                for (int c = 0; c < 3; ++c) {
                    const uint8_t v = im.rgb[((size_t(by) * 4 + size_t(t / 4)) * size_t(im.w) + size_t(bx) * 4 + size_t(t % 4)) * 3 + size_t(c)];
                    rgba[b * 64 + 4 * size_t(t) + size_t(c)] = v;
                    rgbf[b * 48 + 3 * size_t(t) + size_t(c)] = v / 255.0f;
                }
                rgba[b * 64 + 4 * size_t(t) + 3] = 255;
            }
        }
    if (codec == Codec::AtlasNormalWithinItsMax) { // the bound: the unbounded encode's largest block error
        float largest = 0;
        for (size_t b = 0; b < nblocks; ++b) largest = std::max(largest, encode_bc1_block(&rgbf[b * 48], atlas_options(Codec::AtlasNormal), &blocks[b * 8]).max_error);
        o.max_error = largest;
    }
    const double t0 = cpu_now();
    for (size_t b = 0; b < nblocks; ++b) {
        uint8_t* out = &blocks[b * 8];
#if defined(ATLAS_BENCH_RGBCX)
        if (codec == Codec::RgbcxDefault || codec == Codec::RgbcxHq) {
            // Levels as bc7enc's command line: default 10, best rgbcx::MAX_LEVEL (18); 3-colour blocks allowed.
            rgbcx::encode_bc1(codec == Codec::RgbcxHq ? rgbcx::MAX_LEVEL : 10, out, &rgba[b * 64], true, false);
            continue;
        }
#endif
        if (is_atlas(codec)) encode_bc1_block(&rgbf[b * 48], o, out);
        else squish::Compress(&rgba[b * 64], out, flags);
    }
    const double s = cpu_now() - t0;
    for (int by = 0; by < bh; ++by)
        for (int bx = 0; bx < bw; ++bx) {
            float rgb[48];
            decode_bc1_block(&blocks[(size_t(by) * size_t(bw) + size_t(bx)) * 8], Decoder::Reference, rgb);
            for (int t = 0; t < 16; ++t)
                for (int c = 0; c < 3; ++c)
                    err.add(rgb[3 * t + c], im.rgb[((size_t(by) * 4 + size_t(t / 4)) * size_t(im.w) + size_t(bx) * 4 + size_t(t % 4)) * 3 + size_t(c)]);
        }
    return s;
}

double run_bc4(const Image& im, Codec codec, Errors& err) {
    const int bw = im.w / 4, bh = im.h / 4;
    std::vector<uint8_t> blocks(size_t(bw) * size_t(bh) * 8);
    // The encoder is built inside the timed region: a texture pays its own set-up. Its
    // tables are shared per kind of encoder within the process, so one encoder built
    // before the clock starts pays their one-time build, as rgbcx::init() does in main().
    std::unique_ptr<Bc4Encoder> enc;
    if (is_atlas(codec)) Bc4Encoder warm(false, atlas_options(codec));
    auto grey = [&](int bx, int by, int t) { return im.grey((size_t(by) * 4 + size_t(t / 4)) * size_t(im.w) + size_t(bx) * 4 + size_t(t % 4)); };
    // The blocks' texels, gathered before the clock starts (every encoder gets its own
    // input type ready: 8-bit for the peers, float for Atlas).
    std::vector<uint8_t> texels(size_t(bw) * size_t(bh) * 16);
    for (int by = 0; by < bh; ++by)
        for (int bx = 0; bx < bw; ++bx)
            for (int t = 0; t < 16; ++t) texels[(size_t(by) * size_t(bw) + size_t(bx)) * 16 + size_t(t)] = grey(bx, by, t);
    std::vector<float> texels_f(texels.size());
    for (size_t i = 0; i < texels.size(); ++i) texels_f[i] = texels[i] / 255.0f;
    std::vector<BlockResult> results(is_atlas(codec) ? size_t(bw) * size_t(bh) : 0);
    const double t0 = cpu_now();
    if (is_atlas(codec)) enc = std::make_unique<Bc4Encoder>(false, atlas_options(codec));
    // Atlas: the run API the texture encoder uses (encode() per block gives the same bytes).
    if (enc) enc->encode_blocks(texels_f.data(), results.size(), blocks.data(), results.data());
    for (int by = 0; by < bh && !enc; ++by)
        for (int bx = 0; bx < bw; ++bx) {
            uint8_t* out = &blocks[(size_t(by) * size_t(bw) + size_t(bx)) * 8];
            const uint8_t* g8 = &texels[(size_t(by) * size_t(bw) + size_t(bx)) * 16];
#if defined(ATLAS_BENCH_RGBCX)
            if (codec == Codec::RgbcxDefault || codec == Codec::RgbcxHq) {
                if (codec == Codec::RgbcxDefault) rgbcx::encode_bc4(out, g8, 1);
                else rgbcx::encode_bc4_hq(out, g8, 1);
                continue;
            }
#endif
            uint8_t rgba[64] = {};
            for (int t = 0; t < 16; ++t) rgba[4 * t] = g8[t]; // squish's BC4 reads red
            squish::Compress(rgba, out, squish::kBc4);
        }
    const double s = cpu_now() - t0;
    for (int by = 0; by < bh; ++by)
        for (int bx = 0; bx < bw; ++bx) {
            float v[16];
            decode_bc4_block(&blocks[(size_t(by) * size_t(bw) + size_t(bx)) * 8], false, Decoder::Reference, v);
            for (int t = 0; t < 16; ++t) err.add(v[t], grey(bx, by, t));
        }
    return s;
}

const std::vector<Image>& images() {
    static const std::vector<Image> im = inputs();
    return im;
}

void peer(benchmark::State& state, int image, bool bc4, Codec codec) {
    const Image& im = images()[size_t(image)];
    Errors err;
    for (auto _ : state) {
        err = Errors{};
        const double s = bc4 ? run_bc4(im, codec, err) : run_bc1(im, codec, err);
        state.SetIterationTime(s);
        state.counters["Mtexels_per_s"] = double(im.w) * im.h / s / 1e6;
    }
    state.counters["rmse_8bit"] = err.rmse();
    state.counters["max_err_8bit"] = err.max;
}

// BC1 `normal` given --max-error as `steps` 8-bit steps: the squared error the bound buys,
// and what it costs (docs/PERFORMANCE.md, the bound sweep).
void bc1_bound_sweep(benchmark::State& state, int image, int steps) {
    const Image& im = images()[size_t(image)];
    Errors err;
    for (auto _ : state) {
        err = Errors{};
        const double s = run_bc1(im, Codec::AtlasNormal, err, float(steps) / 255.0f);
        state.SetIterationTime(s);
        state.counters["Mtexels_per_s"] = double(im.w) * im.h / s / 1e6;
    }
    state.counters["rmse_8bit"] = err.rmse();
    state.counters["max_err_8bit"] = err.max;
}

int write_inputs(const std::string& dir) {
    int k = 0;
    for (const Image& im : images()) {
        const std::string base = dir + "/input" + std::to_string(k++);
        // Grey images carry the value in alpha too: nvcompress 2.0's -bc4 encodes alpha.
        std::vector<uint8_t> grey(size_t(im.w) * size_t(im.h) * 4);
        for (size_t i = 0; i < size_t(im.w) * size_t(im.h); ++i) grey[4 * i] = grey[4 * i + 1] = grey[4 * i + 2] = grey[4 * i + 3] = im.grey(i);
        for (int g = 0; g < 2; ++g) {
            const std::string path = base + (g ? "_grey.png" : "_rgb.png");
            auto out = OIIO::ImageOutput::create(path);
            OIIO::ImageSpec spec(im.w, im.h, g ? 4 : 3, OIIO::TypeDesc::UINT8);
            if (!out || !out->open(path, spec) || !out->write_image(OIIO::TypeDesc::UINT8, g ? grey.data() : im.rgb.data())) {
                std::fprintf(stderr, "cannot write %s\n", path.c_str());
                return 1;
            }
            out->close();
            std::printf("%s\t%s\n", path.c_str(), im.name.c_str());
        }
    }
    return 0;
}

// RMSE and max error (8-bit steps, channels R,G,B or R only for BC4) of a DDS
// decoded by Atlas's Reference decoder against an 8-bit PNG. Both files store rows top
// down; a decoded field's y runs up (row 0 of the DDS is the field's top row, y = ny - 1),
// so PNG row y is field row ny - 1 - y (compared as is, every image was upside down:
// nvcompress's BC4 read as RMSE 49.9; test peers_rmse_orientation).
int rmse_of(const std::string& dds, const std::string& png) {
    Image src;
    if (!load_png(png, src)) { std::fprintf(stderr, "cannot read %s\n", png.c_str()); return 1; }
    const atlas::Field3D f = read_dds(dds, Decoder::Reference);
    if (f.nx() < src.w || f.ny() < src.h) {
        std::fprintf(stderr, "%s is %dx%d, smaller than %s's %dx%d\n", dds.c_str(), f.nx(), f.ny(), png.c_str(), src.w, src.h);
        return 1;
    }
    auto decoded = [&](int c, int x, int png_row) { return f.at(c, x, f.ny() - 1 - png_row, 0); };
    Errors err;
    const int ch = std::min(3, f.channels());
    int wx = 0, wy = 0, wc = 0;
    for (int y = 0; y < src.h; ++y)
        for (int x = 0; x < src.w; ++x)
            for (int c = 0; c < ch; ++c) {
                const double before = err.max;
                err.add(decoded(c, x, y), src.rgb[(size_t(y) * size_t(src.w) + size_t(x)) * 3 + size_t(c)]);
                if (err.max > before) { wx = x; wy = y; wc = c; }
            }
    std::printf("rmse_8bit %.4f max_err_8bit %.3f channels %d worst (%d, %d) ch %d: decoded %.1f source %d\n", err.rmse(), err.max, ch,
                wx, wy, wc, decoded(wc, wx, wy) * 255.0, int(src.rgb[(size_t(wy) * size_t(src.w) + size_t(wx)) * 3 + size_t(wc)]));
    return 0;
}

// BC4 `best` (the exhaustive search) on the SDF volume of compress_bench (distance to 4
// spheres, -256..4096 m, all 6 decoder models) at three sizes: encode_texture on all
// threads; reports its encode time (wall) and the process CPU time of the call.
using atlas::bench::sdf_volume;

void bc4_best_volume(benchmark::State& state) {
    const int nx = int(state.range(0)), nz = int(state.range(1));
    const atlas::Field3D f = sdf_volume(nx, nx, nz);
    CompressOptions o;
    o.format = Format::Bc4;
    o.quality = Quality::Best;
    o.decoders = kAllDecoders;
    CompressReport last;
    double cpu = 0;
    for (auto _ : state) {
        const std::clock_t c0 = std::clock();
        EncodedTexture e = encode_texture(f, o);
        cpu = double(std::clock() - c0) / CLOCKS_PER_SEC;
        benchmark::DoNotOptimize(e.dds.data.data());
        last = e.report;
        state.SetIterationTime(e.report.encode_seconds);
    }
    state.counters["process_cpu_s_incl_verify"] = cpu;
    state.counters["max_err_m"] = last.bound_max_error;
    state.counters["rmse_m"] = last.rmse.empty() ? 0 : last.rmse[0];
}

} // namespace

int main(int argc, char** argv) {
    if (argc == 3 && std::strcmp(argv[1], "--write-inputs") == 0) return write_inputs(argv[2]);
    if (argc == 4 && std::strcmp(argv[1], "--rmse") == 0) {
        try { return rmse_of(argv[2], argv[3]); } catch (const std::exception& e) { std::fprintf(stderr, "%s\n", e.what()); return 1; }
    }
#if defined(ATLAS_BENCH_RGBCX)
    rgbcx::init();
#endif
    std::vector<Codec> bc1 = {Codec::AtlasFast, Codec::AtlasNormal, Codec::AtlasBest, Codec::AtlasNormalAll, Codec::AtlasNormalWithinItsMax,
                              Codec::SquishRange, Codec::SquishCluster, Codec::SquishIterative};
    std::vector<Codec> bc4 = {Codec::AtlasFast, Codec::AtlasNormal, Codec::AtlasBest, Codec::AtlasNormalAll, Codec::SquishCluster};
#if defined(ATLAS_BENCH_RGBCX)
    for (auto* v : {&bc1, &bc4}) { v->push_back(Codec::RgbcxDefault); v->push_back(Codec::RgbcxHq); }
#endif
    for (int i = 0; i < int(images().size()); ++i) {
        const std::string tag = "[" + images()[size_t(i)].name + "]";
        for (Codec c : bc1)
            benchmark::RegisterBenchmark(("BC1/" + std::string(codec_name(c)) + tag).c_str(), peer, i, false, c)
                ->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
        for (Codec c : bc4)
            benchmark::RegisterBenchmark(("BC4/" + std::string(c == Codec::SquishCluster ? "squish" : codec_name(c)) + tag).c_str(),
                                         peer, i, true, c)
                ->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
        for (int steps : {4, 8, 16, 32, 64})
            benchmark::RegisterBenchmark(("BC1Bound/atlas_normal_max" + std::to_string(steps) + tag).c_str(), bc1_bound_sweep, i, steps)
                ->UseManualTime()->Iterations(1)->Unit(benchmark::kMillisecond);
    }
    for (auto [nx, nz] : {std::pair{128, 16}, std::pair{256, 32}, std::pair{512, 64}})
        benchmark::RegisterBenchmark(("BC4Volume/atlas_best_sdf_" + std::to_string(nx) + "x" + std::to_string(nx) + "x" + std::to_string(nz)).c_str(),
                                     bc4_best_volume)
            ->Args({nx, nz})->UseManualTime()->Iterations(1)->Unit(benchmark::kSecond);
    // A tiny case for the ctest smoke run (the filter "Smoke").
    benchmark::RegisterBenchmark("Smoke_PeersBc4Squish", [](benchmark::State& s) {
        uint8_t rgba[64] = {}, out[8];
        for (auto _ : s) { squish::Compress(rgba, out, squish::kBc4); benchmark::DoNotOptimize(out); }
    });
    benchmark::Initialize(&argc, argv);
    benchmark::RunSpecifiedBenchmarks();
    benchmark::Shutdown();
    return 0;
}
