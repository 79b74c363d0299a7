// Internal: the C interface of libatlas_oiio, the module that holds every
// OpenImageIO call (src/io/oiio/oiio_module.cpp). OpenImageIO drags in about
// 250 shared libraries whose symbol binding cost ~0.17 s CPU and ~100 MB of
// resident memory at every process start, for commands that read or write
// no image; io/image.cpp loads the module with dlopen on the first image it
// reads or writes in a format other than PNG (PNG is written with libpng
// directly, the same bytes). Plain C types only: the module links nothing of
// Atlas.
#pragma once

#include <cstddef>
#include <cstdint>

extern "C" {

// Receives an error message (the text after "PATH: cannot write image: ").
typedef void (*AtlasOiioError)(void* ctx, const char* message);

struct AtlasOiioApi {
    int abi; // kAtlasOiioAbi
    // Encodes w x h interleaved pixels (file row order, nc channels, uint8
    // when bits == 8, else uint16) in the format of path's extension;
    // plain_tga asks for an uncompressed TGA. On success returns 1 and hands
    // the encoded file to append(ctx, bytes, n) once; else returns 0 after
    // error(ctx, message), or -1 (no writer for the extension) after
    // error(ctx, OpenImageIO's own message).
    int (*encode)(const char* path, int w, int h, int nc, int bits, const void* pixels, int plain_tga,
                  void (*append)(void* ctx, const unsigned char* bytes, size_t n), void* ctx, AtlasOiioError error, void* ectx);
    // Opens an image for reading (alpha kept as stored); null after error().
    void* (*open)(const char* path, AtlasOiioError error, void* ectx);
    // The first subimage's size: width, height, channels, depth.
    void (*spec)(void* image, int64_t* w, int64_t* h, int64_t* nc, int64_t* depth);
    // Channel c's name as stored ("" when the file has none); valid until close.
    const char* (*channel_name)(void* image, int c);
    // All nc channels as floats (integer formats as v / (2^bits - 1)), file
    // row order; 1 on success, else 0 after error().
    int (*read)(void* image, int nc, float* pixels, AtlasOiioError error, void* ectx);
    void (*close)(void* image);
};

inline constexpr int kAtlasOiioAbi = 1;

// The module's one exported symbol.
const AtlasOiioApi* atlas_oiio_api(void);
}
