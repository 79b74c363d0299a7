#include "atlas/render/image_out.h"

#include "atlas/core/error.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace atlas::render {

namespace {
float srgb(float x) { return x <= 0.0031308f ? 12.92f * x : 1.055f * std::pow(x, 1.0f / 2.4f) - 0.055f; }
} // namespace

Field2D tone_map(const Field2D& linear, double exposure) {
    if (!(exposure > 0) || !std::isfinite(exposure)) throw Error("render: exposure must be finite and > 0, got " + std::to_string(exposure));
    if (linear.channels() < 3) throw Error("render: tone_map needs 3 colour channels, got " + std::to_string(linear.channels()));
    Field2D out(linear.resolution(), 3, linear.bounds(), {"r", "g", "b"});
    for (int c = 0; c < 3; ++c) {
        auto src = linear.channel(c);
        auto dst = out.channel(c);
        for (size_t i = 0; i < src.size(); ++i) {
            float x = src[i];
            x = std::isfinite(x) && x > 0 ? x * static_cast<float>(exposure) : 0.0f;
            dst[i] = srgb(x / (1.0f + x));
        }
    }
    return out;
}

// A sheet's tiles: columns, the scale factor, the tile and sheet sizes.
struct SheetLayout {
    int columns, scale, tile_w, tile_h, w, h;
};

namespace {
SheetLayout sheet_layout(int frames, int width, int height, int columns, int max_width, int gap) {
    if (frames < 1 || width < 1 || height < 1 || columns < 0 || max_width < 1 || gap < 0)
        throw Error("render: a contact sheet needs frames >= 1, a frame size >= 1, columns >= 0, max_width >= 1 and gap >= 0");
    SheetLayout l{};
    l.columns = columns > 0 ? std::min(columns, frames) : static_cast<int>(std::ceil(std::sqrt(double(frames))));
    const int rows = (frames + l.columns - 1) / l.columns;
    // The smallest factor that fits the row of tiles (and its gaps) in max_width.
    l.scale = 1;
    while ((width / l.scale) * l.columns + gap * (l.columns - 1) > max_width && width / l.scale > 1) ++l.scale;
    l.tile_w = std::max(1, width / l.scale);
    l.tile_h = std::max(1, height / l.scale);
    l.w = l.tile_w * l.columns + gap * (l.columns - 1);
    l.h = l.tile_h * rows + gap * (rows - 1);
    return l;
}
} // namespace

ContactSheet::ContactSheet(int frames, int width, int height, int columns, int max_width, int gap)
    : ContactSheet(frames, width, height, gap, sheet_layout(frames, width, height, columns, max_width, gap)) {}

ContactSheet::ContactSheet(int frames, int width, int height, int gap, const SheetLayout& l)
    : frames_(frames), width_(width), height_(height), columns_(l.columns), gap_(gap), scale_(l.scale), tile_w_(l.tile_w), tile_h_(l.tile_h),
      sheet_({{l.w, l.h}}, 3, Box2d{{{0, 0}}, {{double(l.w), double(l.h)}}}, {"r", "g", "b"}) {}

void ContactSheet::add(int index, const Field2D& frame) {
    if (index < 0 || index >= frames_) throw Error("render: contact sheet frame " + std::to_string(index) + " is outside 0.." + std::to_string(frames_ - 1));
    if (frame.width() != width_ || frame.height() != height_ || frame.channels() < 3)
        throw Error("render: contact sheet frame " + std::to_string(index) + " is " + std::to_string(frame.width()) + "x" +
                    std::to_string(frame.height()) + " with " + std::to_string(frame.channels()) + " channels; expected " + std::to_string(width_) +
                    "x" + std::to_string(height_) + " with at least 3");
    const int col = index % columns_, row = index / columns_;
    const int x0 = col * (tile_w_ + gap_);
    // Row 0 is the top; the field's y = 0 is the bottom row.
    const int y0 = sheet_.height() - (row + 1) * tile_h_ - row * gap_;
    // Tiles keep the frame's top rows: a frame whose height the factor does not
    // divide drops its bottom rows (as its right columns).
    const int oy = height_ - tile_h_ * scale_;
    const float inv = 1.0f / float(scale_ * scale_);
    for (int c = 0; c < 3; ++c)
        for (int ty = 0; ty < tile_h_; ++ty)
            for (int tx = 0; tx < tile_w_; ++tx) {
                float acc = 0;
                for (int j = 0; j < scale_; ++j)
                    for (int i = 0; i < scale_; ++i) acc += frame.at(c, tx * scale_ + i, oy + ty * scale_ + j);
                sheet_.at(c, x0 + tx, y0 + ty) = acc * inv;
            }
}

} // namespace atlas::render
