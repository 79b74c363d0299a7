#include "atlas/io/exr.h"

#include "atlas/core/error.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStandardAttributes.h>
#include <ImfStringAttribute.h>
#include <ImfVecAttribute.h>

#include <vector>

namespace atlas::io {

namespace {

constexpr int kExrLayoutVersion = 1;

// Writes `channels` planar buffers (each width*height, file row order) to an EXR.
void write_planes(const fs::path& path, int width, int height, const std::vector<std::string>& names,
                  const std::vector<std::vector<float>>& planes, bool half, Imf::Header header) {
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const auto& n : names) header.channels().insert(n, Imf::Channel(half ? Imf::HALF : Imf::FLOAT));
    Imf::FrameBuffer fb;
    for (size_t c = 0; c < names.size(); ++c)
        fb.insert(names[c], Imf::Slice(Imf::FLOAT, (char*)planes[c].data(), sizeof(float), sizeof(float) * size_t(width)));
    try {
        Imf::OutputFile file(path.string().c_str(), header, 1);
        file.setFrameBuffer(fb);
        file.writePixels(height);
    } catch (const std::exception& e) {
        throw Error(path.string() + ": cannot write EXR: " + e.what());
    }
}

Imf::Header base_header(int width, int height, const std::string& meaning) {
    Imf::Header h(width, height);
    h.insert("atlas:version", Imf::IntAttribute(kExrLayoutVersion));
    if (!meaning.empty()) h.insert("atlas:channel_meaning", Imf::StringAttribute(meaning));
    return h;
}

void check_channel_names(const std::vector<std::string>& names, const fs::path& path) {
    for (size_t i = 0; i < names.size(); ++i)
        for (size_t j = i + 1; j < names.size(); ++j)
            if (names[i] == names[j]) throw Error(path.string() + ": cannot write EXR: duplicate channel name '" + names[i] + "'");
}

} // namespace

void write_exr(const Field2D& f, const fs::path& path, const ExrOptions& o) {
    check_channel_names(f.channel_names(), path);
    const int w = f.width(), h = f.height();
    std::vector<std::vector<float>> planes(size_t(f.channels()), std::vector<float>(f.voxel_count()));
    for (int c = 0; c < f.channels(); ++c)
        for (int y = 0; y < h; ++y)
            std::copy_n(f.channel(c).data() + f.index(0, y), w, planes[size_t(c)].data() + size_t(h - 1 - y) * size_t(w));
    Imf::Header hd = base_header(w, h, o.channel_meaning);
    hd.insert("atlas:bounds_min", Imf::V2dAttribute(Imath::V2d(f.bounds().min[0], f.bounds().min[1])));
    hd.insert("atlas:bounds_max", Imf::V2dAttribute(Imath::V2d(f.bounds().max[0], f.bounds().max[1])));
    hd.insert("atlas:voxel_size", Imf::V2dAttribute(Imath::V2d(f.voxel_size()[0], f.voxel_size()[1])));
    write_planes(path, w, h, f.channel_names(), planes, o.half, hd);
}

void write_exr(const Field3D& f, const fs::path& path, const ExrOptions& o) {
    check_channel_names(f.channel_names(), path);
    const int nx = f.nx(), ny = f.ny(), nz = f.nz();
    if (int64_t(ny) * nz > (1 << 30)) throw Error(path.string() + ": field too tall for the EXR slice layout");
    std::vector<std::vector<float>> planes(size_t(f.channels()), std::vector<float>(f.voxel_count()));
    for (int c = 0; c < f.channels(); ++c)
        for (int z = 0; z < nz; ++z)
            for (int y = 0; y < ny; ++y)
                std::copy_n(f.channel(c).data() + f.index(0, y, z), nx,
                            planes[size_t(c)].data() + (size_t(z) * size_t(ny) + size_t(ny - 1 - y)) * size_t(nx));
    Imf::Header hd = base_header(nx, ny * nz, o.channel_meaning);
    const auto& b = f.bounds();
    hd.insert("atlas:bounds_min", Imf::V3dAttribute(Imath::V3d(b.min[0], b.min[1], b.min[2])));
    hd.insert("atlas:bounds_max", Imf::V3dAttribute(Imath::V3d(b.max[0], b.max[1], b.max[2])));
    hd.insert("atlas:voxel_size", Imf::V3dAttribute(Imath::V3d(f.voxel_size()[0], f.voxel_size()[1], f.voxel_size()[2])));
    hd.insert("atlas:resolution", Imf::V3iAttribute(Imath::V3i(nx, ny, nz)));
    write_planes(path, nx, ny * nz, f.channel_names(), planes, o.half, hd);
}

Value read_exr(const fs::path& path, const MemoryBudget* budget) {
    if (!fs::exists(path)) throw Error(path.string() + ": cannot open EXR file (no such file)");
    try {
        Imf::InputFile file(path.string().c_str(), 1);
        const Imf::Header& hd = file.header();
        const Imath::Box2i dw = hd.dataWindow();
        const int w = dw.max.x - dw.min.x + 1, h = dw.max.y - dw.min.y + 1;
        std::vector<std::string> names;
        for (auto it = hd.channels().begin(); it != hd.channels().end(); ++it) names.emplace_back(it.name());
        if (names.empty()) throw Error("no channels");
        if (names.size() > 64) throw Error("more than 64 channels");
        if (budget) budget->check(uint64_t(w) * uint64_t(h) * names.size() * 4 * 2, path.string() + ": reading the EXR");
        std::vector<std::vector<float>> planes(names.size(), std::vector<float>(size_t(w) * size_t(h)));
        Imf::FrameBuffer fb;
        for (size_t c = 0; c < names.size(); ++c) {
            // Base pointer shifted so that data-window origin maps to element 0.
            char* base = (char*)(planes[c].data() - int64_t(dw.min.x) - int64_t(dw.min.y) * w);
            fb.insert(names[c], Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * size_t(w), 1, 1, 0.0));
        }
        file.setFrameBuffer(fb);
        file.readPixels(dw.min.y, dw.max.y);

        if (const auto* res = hd.findTypedAttribute<Imf::V3iAttribute>("atlas:resolution")) {
            const Imath::V3i r = res->value();
            if (r.x != w || int64_t(r.y) * r.z != h || r.x <= 0 || r.y <= 0 || r.z <= 0)
                throw Error("atlas:resolution " + std::to_string(r.x) + "x" + std::to_string(r.y) + "x" + std::to_string(r.z) +
                            " does not match the image size " + std::to_string(w) + "x" + std::to_string(h));
            Box3d b{{{0, 0, 0}}, {{double(r.x), double(r.y), double(r.z)}}};
            const auto* bmin = hd.findTypedAttribute<Imf::V3dAttribute>("atlas:bounds_min");
            const auto* bmax = hd.findTypedAttribute<Imf::V3dAttribute>("atlas:bounds_max");
            if (bmin && bmax) {
                b.min = {{bmin->value().x, bmin->value().y, bmin->value().z}};
                b.max = {{bmax->value().x, bmax->value().y, bmax->value().z}};
            }
            auto f = std::make_shared<Field3D>(Vec3i{{r.x, r.y, r.z}}, int(names.size()), b, names, budget);
            for (size_t c = 0; c < names.size(); ++c)
                for (int z = 0; z < r.z; ++z)
                    for (int y = 0; y < r.y; ++y)
                        std::copy_n(planes[c].data() + (size_t(z) * size_t(r.y) + size_t(r.y - 1 - y)) * size_t(w), w,
                                    f->channel(int(c)).data() + f->index(0, y, z));
            return Field3DPtr(f);
        }
        Box2d b{{{0, 0}}, {{double(w), double(h)}}};
        const auto* bmin = hd.findTypedAttribute<Imf::V2dAttribute>("atlas:bounds_min");
        const auto* bmax = hd.findTypedAttribute<Imf::V2dAttribute>("atlas:bounds_max");
        if (bmin && bmax) {
            b.min = {{bmin->value().x, bmin->value().y}};
            b.max = {{bmax->value().x, bmax->value().y}};
        }
        auto f = std::make_shared<Field2D>(Vec2i{{w, h}}, int(names.size()), b, names, budget);
        for (size_t c = 0; c < names.size(); ++c)
            for (int y = 0; y < h; ++y)
                std::copy_n(planes[c].data() + size_t(h - 1 - y) * size_t(w), w, f->channel(int(c)).data() + f->index(0, y));
        return Field2DPtr(f);
    } catch (const MemoryBudgetError&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path.string() + ": cannot read EXR: " + e.what());
    }
}

} // namespace atlas::io
