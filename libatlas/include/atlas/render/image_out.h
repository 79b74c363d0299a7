// atlas/render/image_out.h - turning a rendered image into pictures.
//
// The renderer's image (renderer.h) is linear radiance plus transmittance.
// PNG previews are tone-mapped: x * exposure, then Reinhard x / (1 + x)
// per channel, then the sRGB transfer curve; EXR keeps linear floats. The
// files are written by io (io::write_image for the tone-mapped picture,
// io::write_exr with kLinearImageMeaning for the linear one): render works on
// memory. Pure functions; thread-safe.
#pragma once

#include "atlas/core/field.h"

namespace atlas::render {

// Three channels "r", "g", "b" in [0, 1] (display-referred sRGB), same size
// and bounds. exposure > 0 and finite, else atlas::Error.
Field2D tone_map(const Field2D& linear, double exposure = 1.5);

// A contact sheet of a picture sequence: frames left to right, then top to
// bottom (frame 0 top left), `columns` per row (0: ceil(sqrt(frames))), each
// scaled down by one integer factor (a box filter) so that the sheet is at
// most `max_width` pixels wide, `gap` pixels of black between tiles. Frames are
// added one at a time (memory: the sheet). Channels: the frames' first three.
struct SheetLayout;
class ContactSheet {
public:
    // Throws atlas::Error on frames < 1, a size < 1, columns < 0, max_width < 1 or gap < 0.
    ContactSheet(int frames, int width, int height, int columns = 0, int max_width = 1920, int gap = 4);
    // Frame `index` (0 .. frames - 1), width x height with at least 3 channels.
    void add(int index, const Field2D& frame);
    const Field2D& sheet() const { return sheet_; }
    int scale() const { return scale_; }
    int columns() const { return columns_; }

private:
    ContactSheet(int frames, int width, int height, int gap, const SheetLayout& layout);
    int frames_, width_, height_, columns_, gap_, scale_, tile_w_, tile_h_;
    Field2D sheet_;
};

// What the channels of a linear preview EXR hold (its channel_meaning attribute).
inline constexpr const char* kLinearImageMeaning = "linear radiance r, g, b and view transmittance (atlas render)";

} // namespace atlas::render
