#include "atlas/io/animation.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "io_common.h"

#include <webp/encode.h>
#include <webp/mux.h>

#include <cmath>
#include <string>
#include <vector>

namespace atlas::io {

struct AnimationWriter::Impl {
    int w = 0, h = 0, n = 0;
    AnimationOptions o;
    WebPAnimEncoder* enc = nullptr;
    WebPConfig config;
    ~Impl() {
        if (enc) WebPAnimEncoderDelete(enc);
    }
    // Frame i's start time in milliseconds (rounded, so the sequence keeps its pace).
    int timestamp(int i) const { return static_cast<int>(std::lround(1000.0 * i / o.fps)); }
};

AnimationWriter::AnimationWriter(int width, int height, const AnimationOptions& options) : impl_(std::make_unique<Impl>()) {
    const std::string where = "animation: ";
    if (width < 1 || height < 1 || width > 16383 || height > 16383)
        throw Error(where + "frames must be 1..16383 pixels on a side (WebP's limit), got " + std::to_string(width) + "x" + std::to_string(height));
    if (!(options.fps > 0 && options.fps <= 120)) throw Error(where + "fps must be in (0, 120], got " + std::to_string(options.fps));
    if (options.quality < 0 || options.quality > 101)
        throw Error(where + "quality must be 0..100 (lossy) or 101 (lossless), got " + std::to_string(options.quality));
    Impl& m = *impl_;
    m.w = width;
    m.h = height;
    m.o = options;
    WebPAnimEncoderOptions eo;
    if (!WebPAnimEncoderOptionsInit(&eo)) throw Error(where + "libwebp's version does not match its headers");
    eo.anim_params.loop_count = options.loop ? 0 : 1;
    eo.allow_mixed = 0;
    eo.minimize_size = 0; // deterministic and fast: each frame as given
    m.enc = WebPAnimEncoderNew(width, height, &eo);
    if (!m.enc) throw Error(where + "libwebp could not start an animation of " + std::to_string(width) + "x" + std::to_string(height));
    if (!WebPConfigInit(&m.config)) throw Error(where + "libwebp's version does not match its headers");
    m.config.lossless = options.quality > 100 ? 1 : 0;
    m.config.quality = options.quality > 100 ? 75.0f : float(options.quality); // lossless: effort
    m.config.method = 4;
    m.config.thread_level = 0;
    m.config.exact = 1;
}

AnimationWriter::~AnimationWriter() = default;

int AnimationWriter::frames() const { return impl_->n; }

void AnimationWriter::add(const Field2D& f) {
    Impl& m = *impl_;
    const std::string where = "animation frame " + std::to_string(m.n) + ": ";
    if (!m.enc) throw Error(where + "the animation was already written");
    if (f.width() != m.w || f.height() != m.h)
        throw Error(where + "is " + std::to_string(f.width()) + "x" + std::to_string(f.height()) + ", the animation's frames are " +
                    std::to_string(m.w) + "x" + std::to_string(m.h));
    if (f.channels() < 3) throw Error(where + "needs r, g, b channels, it has " + std::to_string(f.channels()));
    const detail::Quantiser q(0.0f, 1.0f, 8);
    std::vector<uint8_t> rgb(size_t(m.w) * size_t(m.h) * 3);
    for (int y = 0; y < m.h; ++y)
        for (int x = 0; x < m.w; ++x)
            for (int c = 0; c < 3; ++c) {
                const float v = f.at(c, x, y);
                if (std::isnan(v)) throw Error(where + "NaN at pixel (" + std::to_string(x) + ", " + std::to_string(y) + ")");
                rgb[(size_t(m.h - 1 - y) * size_t(m.w) + size_t(x)) * 3 + size_t(c)] = static_cast<uint8_t>(q(v));
            }
    WebPPicture pic;
    if (!WebPPictureInit(&pic)) throw Error(where + "libwebp's version does not match its headers");
    pic.use_argb = 1;
    pic.width = m.w;
    pic.height = m.h;
    struct Free {
        WebPPicture* p;
        ~Free() { WebPPictureFree(p); }
    } free_pic{&pic};
    if (!WebPPictureImportRGB(&pic, rgb.data(), m.w * 3)) throw Error(where + "libwebp ran out of memory");
    if (!WebPAnimEncoderAdd(m.enc, &pic, m.timestamp(m.n), &m.config))
        throw Error(where + "libwebp could not encode it: " + WebPAnimEncoderGetError(m.enc));
    ++m.n;
}

void AnimationWriter::write(const std::filesystem::path& path) {
    Impl& m = *impl_;
    const std::string where = path.string() + ": cannot write animation: ";
    if (!m.enc) throw Error(where + "the animation was already written");
    if (m.n == 0) throw Error(where + "it has no frames");
    if (path.extension() != ".webp") throw Error(where + "the animation is written as WebP; name it .webp");
    // The last frame lasts one frame time too.
    if (!WebPAnimEncoderAdd(m.enc, nullptr, m.timestamp(m.n), nullptr)) throw Error(where + WebPAnimEncoderGetError(m.enc));
    WebPData data;
    WebPDataInit(&data);
    if (!WebPAnimEncoderAssemble(m.enc, &data)) throw Error(where + WebPAnimEncoderGetError(m.enc));
    WebPAnimEncoderDelete(m.enc);
    m.enc = nullptr;
    try {
        write_file_checked(path, data.bytes, data.size);
    } catch (const Error& e) {
        WebPDataClear(&data);
        std::error_code ec;
        std::filesystem::remove(path, ec);
        throw Error(where + e.what());
    }
    WebPDataClear(&data);
}

} // namespace atlas::io
