// atlas/io/animation.h - a picture sequence as one animated WebP (libwebp).
//
// Frames are display-referred colour in [0, 1] (render::tone_map's output:
// channels r, g, b), all of one size; y = 0 is the bottom row, as in
// io::write_image. Values quantise as write_image's 8-bit PNG does (clamped,
// rounded to nearest), so a lossless animation holds exactly the PNG frames'
// bytes. Frames are encoded as they are added (memory: one frame plus the
// encoder's state, not the whole sequence). Deterministic: the same frames and
// options give the same file. Not thread-safe; one writer per file.
#pragma once

#include "atlas/core/field.h"

#include <filesystem>
#include <memory>

namespace atlas::io {

struct AnimationOptions {
    double fps = 12;   // frames per second, (0, 120]
    int quality = 90;  // 0..100 lossy (WebP's quality factor); 101 = lossless
    bool loop = true;  // play forever (else once)
};

class AnimationWriter {
public:
    // width x height of every frame; throws atlas::Error on bad options.
    AnimationWriter(int width, int height, const AnimationOptions& options = {});
    ~AnimationWriter();
    AnimationWriter(const AnimationWriter&) = delete;
    AnimationWriter& operator=(const AnimationWriter&) = delete;
    // Adds the next frame (3 or more channels; the first three are r, g, b).
    // Throws atlas::Error naming the frame on a size mismatch or a NaN.
    void add(const Field2D& frame);
    int frames() const;
    // Writes the animation (path ends in .webp); at least one frame. The
    // writer is spent afterwards. Throws atlas::Error naming the file.
    void write(const std::filesystem::path& path);

private:
    struct Impl;
    std::unique_ptr<Impl> impl_;
};

} // namespace atlas::io
