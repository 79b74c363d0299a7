// libatlas_oiio: every OpenImageIO call of Atlas, behind a C interface
// (../oiio_module.h), loaded on demand by io/image.cpp.
#include "../oiio_module.h"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>

#include <memory>
#include <string>
#include <vector>

namespace {

int do_encode(const char* path, int w, int h, int nc, int bits, const void* pixels, int plain_tga,
           void (*append)(void*, const unsigned char*, size_t), void* ctx, AtlasOiioError error, void* ectx) {
    try {
        const std::string p = path;
        // Encoded in memory, then written by the caller with every write
        // checked: OpenImageIO's writers do not all report a short write.
        std::vector<unsigned char> encoded;
        OIIO::Filesystem::IOVecOutput proxy(encoded);
        auto out = OIIO::ImageOutput::create(p);
        if (!out) {
            error(ectx, OIIO::geterror().c_str());
            return -1;
        }
        if (!out->supports("ioproxy") || !out->set_ioproxy(&proxy)) {
            error(ectx, "the image writer cannot encode in memory");
            return 0;
        }
        const OIIO::TypeDesc type = bits == 8 ? OIIO::TypeDesc::UINT8 : OIIO::TypeDesc::UINT16;
        OIIO::ImageSpec spec(w, h, nc, type);
        if (plain_tga) spec.attribute("compression", "none"); // plain 8-bit TGA, as game pipelines expect
        // Channels are independent data, never colour premultiplied by alpha.
        spec.attribute("oiio:UnassociatedAlpha", 1);
        if (!out->open(p, spec)) {
            error(ectx, out->geterror().c_str());
            return 0;
        }
        bool ok = out->write_image(type, pixels);
        ok = out->close() && ok;
        if (!ok) {
            error(ectx, out->geterror().c_str());
            return 0;
        }
        append(ctx, encoded.data(), encoded.size());
        return 1;
    } catch (const std::exception& e) {
        error(ectx, e.what());
        return 0;
    }
}

struct Image {
    std::unique_ptr<OIIO::ImageInput> in;
    OIIO::ImageSpec spec;
};

void* do_open(const char* path, AtlasOiioError error, void* ectx) {
    try {
        OIIO::ImageSpec config;
        config.attribute("oiio:UnassociatedAlpha", 1); // keep alpha as stored: no premultiplication on read
        // Only the reader the extension names: ImageInput::open falls back to
        // every other format when it fails, and a large junk '.png' was read
        // whole by the DICOM reader (410 s for 1 GiB).
        auto in = OIIO::ImageInput::create(path);
        if (!in) {
            error(ectx, OIIO::geterror().c_str());
            return nullptr;
        }
        OIIO::ImageSpec spec;
        if (!in->valid_file(path) || !in->open(path, spec, config)) {
            const std::string why = in->geterror();
            error(ectx, (why.empty() ? std::string("not a valid ") + in->format_name() + " file" : why).c_str());
            return nullptr;
        }
        auto* im = new Image;
        im->spec = in->spec();
        im->in = std::move(in);
        return im;
    } catch (const std::exception& e) {
        error(ectx, e.what());
        return nullptr;
    }
}

void do_spec(void* image, int64_t* w, int64_t* h, int64_t* nc, int64_t* depth) {
    const auto& s = static_cast<Image*>(image)->spec;
    *w = s.width;
    *h = s.height;
    *nc = s.nchannels;
    *depth = s.depth;
}

const char* do_channel_name(void* image, int c) {
    const auto& s = static_cast<Image*>(image)->spec;
    return c >= 0 && c < int(s.channelnames.size()) ? s.channelnames[size_t(c)].c_str() : "";
}

int do_read(void* image, int nc, float* pixels, AtlasOiioError error, void* ectx) {
    auto* im = static_cast<Image*>(image);
    try {
        if (!im->in->read_image(0, 0, 0, nc, OIIO::TypeDesc::FLOAT, pixels)) {
            error(ectx, im->in->geterror().c_str());
            return 0;
        }
        im->in->close();
        return 1;
    } catch (const std::exception& e) {
        error(ectx, e.what());
        return 0;
    }
}

void do_close(void* image) { delete static_cast<Image*>(image); }

const AtlasOiioApi kApi{kAtlasOiioAbi, do_encode, do_open, do_spec, do_channel_name, do_read, do_close};

} // namespace

extern "C" __attribute__((visibility("default"))) const AtlasOiioApi* atlas_oiio_api(void) { return &kApi; }
