// 8/16-bit images (see image.h for orientation and mapping): PNG written with
// libpng, everything else through OpenImageIO in the libatlas_oiio module,
// loaded on first use (oiio_module.h says why).
#include "atlas/io/image.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "io_common.h"
#include "oiio_module.h"

#include <dlfcn.h>
#include <png.h>

#include <cctype>
#include <cmath>
#include <csetjmp>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <vector>

namespace atlas::io {

namespace {

std::string lower_extension(const fs::path& path) {
    std::string ext = path.extension().string();
    for (auto& ch : ext) ch = char(std::tolower(static_cast<unsigned char>(ch)));
    return ext;
}

std::string texel_name(int x, int y) { return "(" + std::to_string(x) + ", " + std::to_string(y) + ")"; }


// Where the module may be: $ATLAS_OIIO_MODULE, next to (or in lib/atlas/
// beside) the binary holding this code or the running program, the install
// prefix's lib/atlas/, then the build tree's copy.
std::vector<std::string> module_candidates() {
    std::vector<std::string> c;
    if (const char* env = std::getenv("ATLAS_OIIO_MODULE"); env && *env) c.emplace_back(env);
    std::vector<fs::path> dirs;
    Dl_info info{};
    if (dladdr(reinterpret_cast<void*>(&module_candidates), &info) && info.dli_fname && *info.dli_fname)
        dirs.push_back(fs::path(info.dli_fname).parent_path());
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (!ec) dirs.push_back(exe.parent_path());
    for (size_t i = 0; i < dirs.size(); ++i) {
        if (i > 0 && dirs[i] == dirs[0]) continue; // the program holds the io code
        for (const char* rel : {"libatlas_oiio.so", "../lib/atlas/libatlas_oiio.so", "atlas/libatlas_oiio.so", "../lib/libatlas_oiio.so"})
            c.push_back((dirs[i] / rel).string());
    }
#ifdef ATLAS_OIIO_MODULE_INSTALL_PATH
    c.emplace_back(ATLAS_OIIO_MODULE_INSTALL_PATH);
#endif
#ifdef ATLAS_OIIO_MODULE_BUILD_PATH
    c.emplace_back(ATLAS_OIIO_MODULE_BUILD_PATH);
#endif
    return c;
}

const AtlasOiioApi& oiio(const std::string& where) {
    static const AtlasOiioApi* api = nullptr;
    static std::string failure;
    static std::once_flag once;
    std::call_once(once, [] {
        std::string tried;
        for (const auto& path : module_candidates()) {
            std::error_code ec;
            if (!fs::exists(path, ec)) {
                tried += "\n  " + path + ": no such file";
                continue;
            }
            void* h = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
            if (!h) {
                tried += "\n  " + path + ": " + dlerror();
                continue;
            }
            auto get = reinterpret_cast<const AtlasOiioApi* (*)()>(dlsym(h, "atlas_oiio_api"));
            const AtlasOiioApi* a = get ? get() : nullptr;
            if (a && a->abi == kAtlasOiioAbi) {
                api = a; // the module stays loaded for the life of the process
                return;
            }
            tried += "\n  " + path + ": not an Atlas OpenImageIO module of this version";
            dlclose(h);
        }
        failure = "OpenImageIO is needed for this image, but its module libatlas_oiio.so was not found or did not load (set "
                  "ATLAS_OIIO_MODULE to its path); tried:" + tried;
    });
    if (!api) throw Error(where + failure);
    return *api;
}

void collect_error(void* ctx, const char* message) { *static_cast<std::string*>(ctx) = message ? message : ""; }
void append_bytes(void* ctx, const unsigned char* bytes, size_t n) {
    auto* v = static_cast<std::vector<unsigned char>*>(ctx);
    v->insert(v->end(), bytes, bytes + n);
}

// libpng's errors return here through longjmp: only trivially destructible
// locals live in png_encode's frame.
struct PngJump {
    std::jmp_buf jump;
    char message[256];
};

void png_error_to_jump(png_structp png, png_const_charp message) {
    auto* j = static_cast<PngJump*>(png_get_error_ptr(png));
    std::snprintf(j->message, sizeof j->message, "%s", message ? message : "libpng error");
    std::longjmp(j->jump, 1);
}
void png_ignore_warning(png_structp, png_const_charp) {}
void png_append(png_structp png, png_bytep data, png_size_t n) { append_bytes(png_get_io_ptr(png), data, n); }
void png_flush_nothing(png_structp) {}

// The PNG OpenImageIO 2.4 writes (the same bytes): zlib level 6 with the
// default strategy, libpng's adaptive filters, an oFFs chunk of (0, 0).
// Returns null on success, else libpng's message (in j).
const char* png_encode(int w, int h, int nc, int bits, const unsigned char* pixels, std::vector<unsigned char>* out, PngJump* j) {
    png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, j, png_error_to_jump, png_ignore_warning);
    if (!png) return "cannot create a PNG writer";
    png_infop info = png_create_info_struct(png);
    if (!info) {
        png_destroy_write_struct(&png, nullptr);
        return "cannot create a PNG writer";
    }
    if (setjmp(j->jump)) {
        png_destroy_write_struct(&png, &info);
        return j->message;
    }
    png_set_write_fn(png, out, png_append, png_flush_nothing);
    const int type = nc == 1 ? PNG_COLOR_TYPE_GRAY : nc == 2 ? PNG_COLOR_TYPE_GRAY_ALPHA : nc == 3 ? PNG_COLOR_TYPE_RGB : PNG_COLOR_TYPE_RGB_ALPHA;
    png_set_IHDR(png, info, png_uint_32(w), png_uint_32(h), bits, type, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT, PNG_FILTER_TYPE_DEFAULT);
    png_set_compression_level(png, 6);
    png_set_compression_strategy(png, 0); // Z_DEFAULT_STRATEGY
    png_set_oFFs(png, info, 0, 0, PNG_OFFSET_PIXEL);
    png_write_info(png, info);
    if (bits == 16) png_set_swap(png); // PNG is big-endian; the rows are native uint16
    const size_t row = size_t(w) * size_t(nc) * size_t(bits / 8);
    for (int y = 0; y < h; ++y) png_write_row(png, pixels + row * size_t(y));
    png_write_end(png, nullptr);
    png_destroy_write_struct(&png, &info);
    return nullptr;
}
} // namespace

void write_image(const Field2D& f, const fs::path& path, const ImageOptions& o) {
    const std::string ext = lower_extension(path);
    const std::string where = path.string() + ": cannot write image: ";
    if (f.channels() > 4) throw Error(where + "an image holds 1 to 4 channels, the field has " + std::to_string(f.channels()));
    if (o.bits != 8 && o.bits != 16) throw Error(where + "bits must be 8 or 16, got " + std::to_string(o.bits));
    if (o.bits == 16 && ext == ".tga") throw Error(where + "TGA holds 8 bits per channel, not 16; use PNG for 16 bits");
    if (ext == ".tga" && f.channels() == 2) throw Error(where + "TGA holds 1, 3 or 4 channels, the field has 2; use PNG");
    if (!detail::valid_range(o.range_min, o.range_max))
        throw Error(where + "range must be finite with max > min, got [" + std::to_string(o.range_min) + ", " + std::to_string(o.range_max) + "]");
    const int w = f.width(), h = f.height(), nc = f.channels();
    const detail::Quantiser quantise(o.range_min, o.range_max, o.bits);
    // Interleaved, file row order: field row y is file row h-1-y.
    std::vector<uint16_t> q(size_t(w) * size_t(h) * size_t(nc));
    for (int c = 0; c < nc; ++c)
        for (int y = 0; y < h; ++y)
            for (int x = 0; x < w; ++x) {
                const float v = f.at(c, x, y);
                if (std::isnan(v)) throw Error(where + "NaN at texel " + texel_name(x, y) + " of channel '" + f.channel_name(c) + "'");
                q[(size_t(h - 1 - y) * size_t(w) + size_t(x)) * size_t(nc) + size_t(c)] = quantise(v);
            }
    // Encoded in memory, then written with every write checked (OpenImageIO's
    // PNG writer did not report a short write: a full disk gave a truncated
    // file and success).
    std::vector<unsigned char> encoded;
    std::vector<uint8_t> b;
    if (o.bits == 8) b.assign(q.begin(), q.end());
    const void* pixels = o.bits == 8 ? static_cast<const void*>(b.data()) : static_cast<const void*>(q.data());
    if (ext == ".png") {
        PngJump j{};
        if (const char* err = png_encode(w, h, nc, o.bits, static_cast<const unsigned char*>(pixels), &encoded, &j))
            throw Error(where + err);
    } else {
        const AtlasOiioApi& api = oiio(where);
        std::string err;
        const int r = api.encode(path.string().c_str(), w, h, nc, o.bits, pixels, ext == ".tga" ? 1 : 0, append_bytes, &encoded, collect_error, &err);
        if (r < 0) throw Error(where + "no image writer for the extension '" + ext + "' (" + err + ")");
        if (r == 0) throw Error(where + err);
    }
    try {
        write_file_checked(path, encoded.data(), encoded.size());
    } catch (const Error& e) {
        std::error_code ec;
        fs::remove(path, ec);
        throw Error(where + e.what());
    }
}

Field2D read_image(const fs::path& path, std::optional<Box2d> bounds, const MemoryBudget* budget) {
    detail::require_regular_file(path, "image");
    const std::string where = path.string() + ": cannot read image: ";
    if (bounds && !bounds->valid()) throw Error(where + "bounds must be finite with max > min in both axes");
    const MemoryBudget fallback;
    const MemoryBudget& bud = detail::budget_or_default(budget, fallback);
    // Keep alpha as stored: no premultiplication on read (the module asks for that).
    const AtlasOiioApi& api = oiio(where);
    std::string err;
    struct Closer {
        const AtlasOiioApi& api;
        void* image;
        ~Closer() { if (image) api.close(image); }
    } in{api, api.open(path.string().c_str(), collect_error, &err)};
    if (!in.image) throw Error(where + err);
    int64_t w = 0, h = 0, nc = 0, depth = 0;
    api.spec(in.image, &w, &h, &nc, &depth);
    if (w <= 0 || h <= 0 || nc <= 0) throw Error(where + "the image has no pixels");
    if (w > (1 << 30) || h > (1 << 30)) throw Error(where + "the image claims an absurd size " + std::to_string(w) + "x" + std::to_string(h));
    if (nc > 64) throw Error(where + "the image has " + std::to_string(nc) + " channels; at most 64 are supported");
    if (depth > 1) throw Error(where + "volume images are not supported here; use a TGA slice stack, EXR or VDB");
    try {
        bud.check(field_bytes(uint64_t(w) * uint64_t(h), int(nc)) * 2, "a " + std::to_string(w) + "x" + std::to_string(h) + "x" + std::to_string(nc) + " image");
    } catch (const MemoryBudgetError& e) {
        throw MemoryBudgetError(path.string() + ": " + e.what());
    }
    std::vector<float> px(size_t(w) * size_t(h) * size_t(nc));
    // Integer formats convert to 0..1 (value / (2^bits - 1)); float formats pass through.
    if (!api.read(in.image, int(nc), px.data(), collect_error, &err)) throw Error(where + err);
    std::vector<std::string> names;
    for (int c = 0; c < nc; ++c) {
        std::string n = api.channel_name(in.image, c);
        for (auto& ch : n) ch = char(std::tolower(static_cast<unsigned char>(ch)));
        names.push_back(n);
    }
    // Missing, empty or clashing names (rare) fall back to the defaults.
    bool usable = true;
    for (size_t i = 0; i < names.size(); ++i) {
        usable = usable && !names[i].empty();
        for (size_t j = i + 1; j < names.size(); ++j) usable = usable && names[i] != names[j];
    }
    if (!usable) names = default_channel_names(int(nc));
    const Box2d b = bounds ? *bounds : Box2d{{{0, 0}}, {{double(w), double(h)}}};
    Field2D f({{int(w), int(h)}}, int(nc), b, names, &bud);
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
            for (int c = 0; c < nc; ++c) f.at(c, x, y) = px[(size_t(h - 1 - y) * size_t(w) + size_t(x)) * size_t(nc) + size_t(c)];
    return f;
}

} // namespace atlas::io
