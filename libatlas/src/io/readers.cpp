#include "atlas/io/readers.h"

#include "atlas/core/error.h"
#include "atlas/io/exr.h"
#include "atlas/io/image.h"
#include "atlas/io/tga_slices.h"
#include "atlas/io/vdb.h"

#include <algorithm>

namespace atlas::io {

Value read_field_file(const std::filesystem::path& path, const MemoryBudget* budget) {
    std::string ext = path.extension().string();
    std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
    const std::string name = path.filename().string();
    if (ext == ".exr") return read_exr(path, budget);
    if (ext == ".vdb") return Field3DPtr(std::make_shared<Field3D>(read_vdb(path, {}, budget)));
    auto ends_with = [&](const std::string& tail) { return name.size() > tail.size() && name.compare(name.size() - tail.size(), tail.size(), tail) == 0; };
    // The first slice of a stack in either naming: Atlas's STEM.001.tga or the pack's STEM(0).tga.
    if (ext == ".tga" && (ends_with(".001.tga") || ends_with("(0).tga"))) {
        const auto slices = find_tga_slices(path);
        Field2D first = read_image(slices[0]);
        Box3d b{{{0, 0, 0}}, {{double(first.width()), double(first.height()), double(slices.size())}}};
        return Field3DPtr(std::make_shared<Field3D>(read_tga_slices(path, b, 4, budget)));
    }
    if (ext == ".png" || ext == ".tga" || ext == ".tif" || ext == ".tiff" || ext == ".jpg" || ext == ".jpeg")
        return Field2DPtr(std::make_shared<Field2D>(read_image(path, {}, budget)));
    throw Error(path.string() + ": unknown file type '" + ext + "' (expected .exr, .vdb, .png, .tga, .tif, .jpg, or the first slice of a stack: STEM.001.tga or STEM(0).tga)");
}

Field3DPtr as_field3d(const Value& v) {
    if (auto f3 = std::get_if<Field3DPtr>(&v)) return *f3;
    const Field2D& f = *std::get<Field2DPtr>(v);
    auto out = std::make_shared<Field3D>(Vec3i{{f.width(), f.height(), 1}}, f.channels(),
                                         Box3d{{{f.bounds().min[0], f.bounds().min[1], 0}}, {{f.bounds().max[0], f.bounds().max[1], 1}}},
                                         f.channel_names());
    for (int c = 0; c < f.channels(); ++c) std::copy(f.channel(c).begin(), f.channel(c).end(), out->channel(c).begin());
    return out;
}

} // namespace atlas::io
