// EXR reading and writing through OpenEXR (see exr.h for the layout).
#include "atlas/io/exr.h"

#include "atlas/core/error.h"
#include "io_common.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfOutputFile.h>
#include <ImfStringAttribute.h>
#include <ImfStringVectorAttribute.h>
#include <ImfVecAttribute.h>
#include <Imath/half.h>

#include <algorithm>
#include <cstring>
#include <cerrno>
#include <unistd.h>
#include <fcntl.h>
#include <cctype>
#include <cmath>
#include <fstream>
#include <functional>
#include <stdexcept>
#include <string_view>
#include <vector>

namespace atlas::io {

namespace {

constexpr int kExrLayoutVersion = 1;
// Largest finite half; beyond it a half EXR would silently store infinity.
constexpr float kHalfMax = 65504.0f;

// Planar float buffers in file row order (row 0 = top of the image).
struct Planes {
    int width = 0, height = 0;
    std::vector<std::vector<float>> data;
};

void check_channel_names(const std::vector<std::string>& names, const fs::path& path) {
    for (size_t i = 0; i < names.size(); ++i) {
        if (names[i].empty()) throw Error(path.string() + ": cannot write EXR: channel " + std::to_string(i) + " has an empty name");
        for (size_t j = i + 1; j < names.size(); ++j)
            if (names[i] == names[j]) throw Error(path.string() + ": cannot write EXR: duplicate channel name '" + names[i] + "'");
    }
}

// Half storage rounds; it must not turn finite values into infinities.
void check_half_range(const atlas::detail::FieldStorage& f, const fs::path& path) {
    for (int c = 0; c < f.channels(); ++c)
        for (size_t i = 0; i < f.voxel_count(); ++i) {
            const float v = f.channel(c)[i];
            if (std::isfinite(v) && std::fabs(v) > kHalfMax)
                throw Error(path.string() + ": cannot write EXR as half: channel '" + f.channel_name(c) + "' holds " + std::to_string(v) +
                            " (element " + std::to_string(i) + "), beyond the half range +-65504; write 32-bit float instead");
        }
}

Imf::Header base_header(int width, int height, const std::vector<std::string>& names, const std::string& meaning, bool compress) {
    Imf::Header h(width, height);
    h.compression() = compress ? Imf::ZIP_COMPRESSION : Imf::NO_COMPRESSION;
    h.insert("atlas:version", Imf::IntAttribute(kExrLayoutVersion));
    h.insert("atlas:channel_meaning", Imf::StringAttribute(meaning));
    // EXR lists channels alphabetically; this keeps the field's order.
    h.insert("atlas:channels", Imf::StringVectorAttribute(names));
    return h;
}

// Writes the image in strips of rows, each channel's strip filled by
// fill(channel, file row, destination) (file row 0 = top of the image), so
// the writer holds a few MiB besides the value instead of a whole copy of it
// (and another in half): a 512x512x64 NVDF is 256 MiB a copy.
// An OpenEXR output stream whose every write is checked. OpenEXR's own file
// stream writes the line-offset table from ~OutputFile, where a full disk is
// swallowed: a preview wrote a 0-byte EXR and exited 0. Errors are kept (a
// destructor must not throw) and raised by close().
class CheckedOStream : public Imf::OStream {
public:
    explicit CheckedOStream(const fs::path& path) : Imf::OStream(path.c_str()), path_(path) {
        fd_ = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
        if (fd_ < 0) throw Error(path.string() + ": cannot create the file: " + std::strerror(errno));
    }
    ~CheckedOStream() override {
        if (fd_ >= 0) ::close(fd_);
    }
    void write(const char c[], int n) override {
        while (n > 0 && !error_) {
            const ssize_t k = ::pwrite(fd_, c, size_t(n), off_t(pos_));
            if (k < 0 && errno == EINTR) continue;
            if (k <= 0) {
                error_ = k < 0 ? errno : ENOSPC;
                break;
            }
            c += k, n -= int(k), pos_ += uint64_t(k);
        }
        // Stop OpenEXR early while it can still take an exception, once (not
        // again from its destructor while that one unwinds).
        if (error_ && !closing_) {
            closing_ = true;
            throw std::runtime_error(std::strerror(error_));
        }
    }
    uint64_t tellp() override { return pos_; }
    void seekp(uint64_t pos) override { pos_ = pos; }
    void closing() { closing_ = true; }
    // Throws atlas::Error naming the file when any write or the close failed.
    void close() {
        const int fd = fd_;
        fd_ = -1;
        if (::close(fd) != 0 && !error_) error_ = errno;
        if (error_) throw Error(path_.string() + ": cannot write EXR: " + std::strerror(error_));
    }

private:
    fs::path path_;
    int fd_ = -1;
    uint64_t pos_ = 0;
    int error_ = 0;
    bool closing_ = false;
};

void write_rows(const fs::path& path, int width, int height, const std::vector<std::string>& names, bool half, Imf::Header header,
                const std::function<void(int, int, float*)>& fill) {
    for (const auto& n : names) header.channels().insert(n, Imf::Channel(half ? Imf::HALF : Imf::FLOAT));
    const size_t nc = names.size(), w = size_t(width);
    // A multiple of 32 rows (the most any OpenEXR compression groups), about 4 MiB of floats.
    const int strip = int(std::clamp<size_t>((size_t(4) << 20) / std::max<size_t>(1, w * nc * sizeof(float)) / 32 * 32, 32, 4096));
    std::vector<std::vector<float>> rows(nc, std::vector<float>(w * size_t(std::min(strip, height))));
    // OpenEXR converts pixel types when reading, not when writing: half
    // channels need half buffers (rounded to nearest even by Imath).
    std::vector<std::vector<::half>> halves(half ? nc : 0, std::vector<::half>(half ? rows[0].size() : 0));
    CheckedOStream stream(path);
    try {
        // One thread: OpenEXR's output is the same bytes either way, and the
        // caller decides the parallelism.
        Imf::OutputFile file(stream, header, 1);
        for (int y0 = 0; y0 < height; y0 += strip) {
            const int n = std::min(strip, height - y0);
            Imf::FrameBuffer fb;
            for (size_t c = 0; c < nc; ++c) {
                for (int r = 0; r < n; ++r) fill(int(c), y0 + r, rows[c].data() + size_t(r) * w);
                const Imath::V2i origin(0, y0);
                if (half) {
                    std::copy_n(rows[c].begin(), size_t(n) * w, halves[c].begin());
                    fb.insert(names[c], Imf::Slice::Make(Imf::HALF, halves[c].data(), origin, width, n, sizeof(::half), sizeof(::half) * w));
                } else {
                    fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, rows[c].data(), origin, width, n, sizeof(float), sizeof(float) * w));
                }
            }
            file.setFrameBuffer(fb);
            file.writePixels(n);
        }
        stream.closing(); // ~OutputFile writes the offset table: errors are kept for close()
    } catch (const std::exception& e) {
        throw Error(path.string() + ": cannot write EXR: " + e.what());
    }
    stream.close();
}

// Rank of a standard channel name within its layer (OpenEXR's conventions):
// colour R, G, B, A; vectors X, Y, Z; other names after them, alphabetically.
// A lone luminance Y comes before its alpha (Y, A).
int standard_rank(const std::string& suffix, bool luminance) {
    static const char* const kOrder[] = {"R", "G", "B", "A", "X", "Y", "Z"};
    std::string u = suffix;
    for (char& ch : u) ch = char(std::toupper(static_cast<unsigned char>(ch)));
    if (luminance && u == "Y") return -1;
    for (int i = 0; i < 7; ++i)
        if (u == kOrder[i]) return i;
    return 100;
}

// Channel order: the atlas:channels attribute when it names exactly the file's
// channels; else each layer ("diffuse.R": layer "diffuse.") in the file's
// (alphabetical) order with its channels in conventional order, so an RGB EXR
// from another tool reads as R, G, B and not as OpenEXR's alphabetical B, G, R.
// Luminance/chroma images (RY, BY) are refused: they are not RGB.
std::vector<std::string> channel_order(const Imf::Header& hd) {
    std::vector<std::string> names;
    for (auto it = hd.channels().begin(); it != hd.channels().end(); ++it) names.emplace_back(it.name());
    if (const auto* order = hd.findTypedAttribute<Imf::StringVectorAttribute>("atlas:channels")) {
        std::vector<std::string> a = order->value(), b = names;
        std::sort(a.begin(), a.end());
        std::sort(b.begin(), b.end());
        if (a == b && std::adjacent_find(a.begin(), a.end()) == a.end()) return order->value();
    }
    auto layer_of = [](const std::string& n) { const size_t dot = n.rfind('.'); return dot == std::string::npos ? std::string() : n.substr(0, dot + 1); };
    auto suffix_of = [](const std::string& n) { const size_t dot = n.rfind('.'); return dot == std::string::npos ? n : n.substr(dot + 1); };
    for (const auto& n : names)
        if (suffix_of(n) == "RY" || suffix_of(n) == "BY")
            throw Error("channel '" + n + "' is luminance/chroma (RY, BY); only RGB(A), XYZ, Y and named data channels are supported "
                        "(convert the image to RGB first)");
    // A layer is luminance when it has Y but no colour or vector partner.
    auto luminance_layer = [&](const std::string& layer) {
        bool y = false, other = false;
        for (const auto& n : names) {
            if (layer_of(n) != layer) continue;
            const int r = standard_rank(suffix_of(n), false);
            if (r == 5) y = true;
            else if (r != 3 && r != 100) other = true;
        }
        return y && !other;
    };
    std::stable_sort(names.begin(), names.end(), [&](const std::string& a, const std::string& b) {
        const std::string la = layer_of(a), lb = layer_of(b);
        if (la != lb) return la < lb;
        const bool lum = luminance_layer(la);
        const int ra = standard_rank(suffix_of(a), lum), rb = standard_rank(suffix_of(b), lum);
        if (ra != rb) return ra < rb;
        return suffix_of(a) < suffix_of(b);
    });
    return names;
}

// Reads every channel as float planes (file row order), checking the size first.
Planes read_planes(Imf::InputFile& file, const std::vector<std::string>& names, const MemoryBudget& budget) {
    const Imf::Header& hd = file.header();
    const Imath::Box2i dw = hd.dataWindow();
    const int64_t w = int64_t(dw.max.x) - dw.min.x + 1, h = int64_t(dw.max.y) - dw.min.y + 1;
    if (w <= 0 || h <= 0 || w > (1 << 30) || h > (1 << 30)) throw Error("data window is empty or absurd");
    if (names.empty()) throw Error("the image has no channels");
    if (names.size() > 64) throw Error("the image has " + std::to_string(names.size()) + " channels; at most 64 are supported");
    for (const auto& n : names) {
        const Imf::Channel* ch = hd.channels().findChannel(n);
        if (ch->xSampling != 1 || ch->ySampling != 1)
            throw Error("channel '" + n + "' is subsampled (luminance/chroma image); only full-resolution channels are supported");
    }
    // The planes plus the field built from them.
    budget.check(field_bytes(uint64_t(w) * uint64_t(h), int(names.size())) * 2,
                 "a " + std::to_string(w) + "x" + std::to_string(h) + "x" + std::to_string(names.size()) + " EXR image");
    Planes p;
    p.width = int(w);
    p.height = int(h);
    p.data.assign(names.size(), std::vector<float>(size_t(w) * size_t(h)));
    Imf::FrameBuffer fb;
    for (size_t c = 0; c < names.size(); ++c)
        fb.insert(names[c], Imf::Slice::Make(Imf::FLOAT, p.data[c].data(), dw, sizeof(float), sizeof(float) * size_t(w)));
    file.setFrameBuffer(fb);
    file.readPixels(dw.min.y, dw.max.y);
    return p;
}

template <typename Attr, typename Fn>
void if_attr(const Imf::Header& hd, const char* name, Fn&& fn) {
    if (const auto* a = hd.findTypedAttribute<Attr>(name)) fn(a->value());
}

Value make_field3d(const Imf::Header& hd, const Planes& p, const std::vector<std::string>& names, Imath::V3i r, const MemoryBudget& budget) {
    if (r.x <= 0 || r.y <= 0 || r.z <= 0 || r.x != p.width || int64_t(r.y) * r.z != p.height)
        throw Error("atlas:resolution " + std::to_string(r.x) + "x" + std::to_string(r.y) + "x" + std::to_string(r.z) +
                    " does not match the image size " + std::to_string(p.width) + "x" + std::to_string(p.height) + " (expected nx by ny*nz)");
    Box3d b{{{0, 0, 0}}, {{double(r.x), double(r.y), double(r.z)}}};
    const auto* bmin = hd.findTypedAttribute<Imf::V3dAttribute>("atlas:bounds_min");
    const auto* bmax = hd.findTypedAttribute<Imf::V3dAttribute>("atlas:bounds_max");
    if (bmin && bmax) {
        b.min = {{bmin->value().x, bmin->value().y, bmin->value().z}};
        b.max = {{bmax->value().x, bmax->value().y, bmax->value().z}};
    }
    auto f = std::make_shared<Field3D>(Vec3i{{r.x, r.y, r.z}}, int(names.size()), b, names, &budget);
    for (size_t c = 0; c < names.size(); ++c)
        for (int z = 0; z < r.z; ++z)
            for (int y = 0; y < r.y; ++y)
                std::copy_n(p.data[c].data() + (size_t(z) * size_t(r.y) + size_t(r.y - 1 - y)) * size_t(r.x), size_t(r.x),
                            f->channel(int(c)).data() + f->index(0, y, z));
    return Field3DPtr(f);
}

Value make_field2d(const Imf::Header& hd, const Planes& p, const std::vector<std::string>& names, const MemoryBudget& budget) {
    Box2d b{{{0, 0}}, {{double(p.width), double(p.height)}}};
    const auto* bmin = hd.findTypedAttribute<Imf::V2dAttribute>("atlas:bounds_min");
    const auto* bmax = hd.findTypedAttribute<Imf::V2dAttribute>("atlas:bounds_max");
    if (bmin && bmax) {
        b.min = {{bmin->value().x, bmin->value().y}};
        b.max = {{bmax->value().x, bmax->value().y}};
    }
    auto f = std::make_shared<Field2D>(Vec2i{{p.width, p.height}}, int(names.size()), b, names, &budget);
    for (size_t c = 0; c < names.size(); ++c)
        for (int y = 0; y < p.height; ++y)
            std::copy_n(p.data[c].data() + size_t(p.height - 1 - y) * size_t(p.width), size_t(p.width), f->channel(int(c)).data() + f->index(0, y));
    return Field2DPtr(f);
}

} // namespace

void write_exr(const Field2D& f, const fs::path& path, const ExrOptions& o) {
    check_channel_names(f.channel_names(), path);
    if (o.half) check_half_range(f, path);
    const int width = f.width(), height = f.height();
    Imf::Header hd = base_header(width, height, f.channel_names(), o.channel_meaning, o.compress);
    const auto& b = f.bounds();
    const Vec2d v = f.voxel_size();
    hd.insert("atlas:bounds_min", Imf::V2dAttribute(Imath::V2d(b.min[0], b.min[1])));
    hd.insert("atlas:bounds_max", Imf::V2dAttribute(Imath::V2d(b.max[0], b.max[1])));
    hd.insert("atlas:voxel_size", Imf::V2dAttribute(Imath::V2d(v[0], v[1])));
    write_rows(path, width, height, f.channel_names(), o.half, hd, [&](int c, int row, float* dst) {
        std::copy_n(f.channel(c).data() + f.index(0, height - 1 - row), size_t(width), dst);
    });
}

void write_exr(const Field3D& f, const fs::path& path, const ExrOptions& o) {
    check_channel_names(f.channel_names(), path);
    if (o.half) check_half_range(f, path);
    const int nx = f.nx(), ny = f.ny(), nz = f.nz();
    // EXR coordinates are int; the stacked image must fit.
    if (int64_t(ny) * nz > (int64_t(1) << 30))
        throw Error(path.string() + ": cannot write EXR: " + std::to_string(ny) + "x" + std::to_string(nz) + " rows are too many for one image");
    // Slices stacked top to bottom (z = 0 first), each with its rows flipped.
    Imf::Header hd = base_header(nx, ny * nz, f.channel_names(), o.channel_meaning, o.compress);
    const auto& b = f.bounds();
    const Vec3d v = f.voxel_size();
    hd.insert("atlas:bounds_min", Imf::V3dAttribute(Imath::V3d(b.min[0], b.min[1], b.min[2])));
    hd.insert("atlas:bounds_max", Imf::V3dAttribute(Imath::V3d(b.max[0], b.max[1], b.max[2])));
    hd.insert("atlas:voxel_size", Imf::V3dAttribute(Imath::V3d(v[0], v[1], v[2])));
    hd.insert("atlas:resolution", Imf::V3iAttribute(Imath::V3i(nx, ny, nz)));
    write_rows(path, nx, ny * nz, f.channel_names(), o.half, hd, [&](int c, int row, float* dst) {
        const int z = row / ny, y = ny - 1 - row % ny;
        std::copy_n(f.channel(c).data() + f.index(0, y, z), size_t(nx), dst);
    });
}

namespace {
// OpenEXR allocates what a header claims before reading pixels: an opaque
// attribute of its stated size, a line-offset table of one entry per block of
// the data window. A 274-byte file claimed about 2 GB. The header is walked
// here first, and its claims held against the file's size and the budget.
void check_exr_claims(const fs::path& path, const MemoryBudget& budget) {
    std::ifstream in(path, std::ios::binary);
    std::error_code ec;
    const uint64_t file_size = fs::file_size(path, ec);
    if (!in || ec) throw Error("cannot open the file");
    // Headers are small: read as far as the walk goes (every EXR read passes
    // here before OpenEXR reads the file again), never past 16 MiB, which is
    // far past any real header.
    const size_t cap = size_t(std::min<uint64_t>(file_size, 16u << 20));
    std::string head;
    auto more = [&] {
        if (head.size() >= cap) return false;
        const size_t old = head.size();
        head.resize(std::min(cap, std::max<size_t>(4096, 2 * old)));
        in.read(head.data() + old, std::streamsize(head.size() - old));
        head.resize(old + size_t(in.gcount()));
        return head.size() > old;
    };
    size_t pos = 0;
    auto need = [&](size_t n) {
        while (head.size() - pos < n)
            if (!more()) throw Error("the header is truncated");
    };
    auto i32 = [&] {
        need(4);
        int32_t v;
        std::memcpy(&v, head.data() + pos, 4);
        pos += 4;
        return v;
    };
    auto cstr = [&] {
        size_t end;
        while ((end = head.find('\0', pos)) == std::string::npos && head.size() - pos <= 255 && more()) {
        }
        if (end == std::string::npos || end - pos > 255) throw Error("an attribute name is not terminated");
        std::string v = head.substr(pos, end - pos);
        pos = end + 1;
        return v;
    };
    if (i32() != 20000630) throw Error("not an OpenEXR file (bad magic number)");
    const int32_t version = i32();
    const bool tiled = version & 0x200;
    int64_t x0 = 0, y0 = 0, x1 = -1, y1 = -1, channels = 0, tile_w = 0, tile_h = 0;
    int compression = 0;
    for (;;) {
        const std::string name = cstr();
        if (name.empty()) break;
        const std::string type = cstr();
        const int32_t size = i32();
        if (size < 0 || uint64_t(size) > file_size - pos)
            throw Error("attribute '" + name + "' claims " + std::to_string(size) + " bytes, more than the file holds");
        need(size_t(size));
        const char* d = head.data() + pos;
        auto at = [&](int k) {
            int32_t v;
            std::memcpy(&v, d + 4 * k, 4);
            return int64_t(v);
        };
        if (name == "dataWindow" && type == "box2i" && size == 16) x0 = at(0), y0 = at(1), x1 = at(2), y1 = at(3);
        if (name == "compression" && size == 1) compression = static_cast<unsigned char>(d[0]);
        if (name == "tiles" && type == "tiledesc" && size >= 8) tile_w = uint32_t(at(0)), tile_h = uint32_t(at(1));
        if (name == "channels" && type == "chlist")
            for (size_t q = 0; q < size_t(size) && d[q];) {
                const size_t end = std::string_view(d + q, size_t(size) - q).find('\0');
                if (end == std::string_view::npos) break;
                q += end + 1 + 16; // pixel type, pLinear, reserved, x and y sampling
                ++channels;
            }
        pos += size_t(size);
    }
    const int64_t w = x1 - x0 + 1, h = y1 - y0 + 1;
    if (w < 1 || h < 1 || w > (int64_t(1) << 30) || h > (int64_t(1) << 30))
        throw Error("the data window " + std::to_string(w) + "x" + std::to_string(h) + " is empty or absurd");
    // One offset per line block (scanlines) or per tile of the first level, 8 bytes each.
    static const int kLinesPerBlock[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};
    const int64_t lines = compression >= 0 && compression < 10 ? kLinesPerBlock[compression] : 256;
    const int64_t blocks = tiled && tile_w > 0 && tile_h > 0 ? ((w + tile_w - 1) / tile_w) * ((h + tile_h - 1) / tile_h) : (h + lines - 1) / lines;
    if (uint64_t(blocks) * 8 > file_size)
        throw Error("the header claims " + std::to_string(w) + "x" + std::to_string(h) + " pixels, whose offset table alone (" + std::to_string(blocks * 8) +
                    " bytes) is larger than the file (" + std::to_string(file_size) + " bytes)");
    budget.check(field_bytes(uint64_t(w) * uint64_t(h), int(std::max<int64_t>(channels, 1))) * 2,
                 "a " + std::to_string(w) + "x" + std::to_string(h) + "x" + std::to_string(channels) + " EXR image");
}
} // namespace

Value read_exr(const fs::path& path, const MemoryBudget* budget) {
    detail::require_regular_file(path, "EXR");
    const MemoryBudget fallback;
    const MemoryBudget& bud = detail::budget_or_default(budget, fallback);
    try {
        check_exr_claims(path, bud);
        Imf::InputFile file(path.string().c_str(), 1);
        const Imf::Header& hd = file.header();
        const std::vector<std::string> names = channel_order(hd);
        const Planes p = read_planes(file, names, bud);
        if (const auto* res = hd.findTypedAttribute<Imf::V3iAttribute>("atlas:resolution")) return make_field3d(hd, p, names, res->value(), bud);
        return make_field2d(hd, p, names, bud);
    } catch (const MemoryBudgetError& e) {
        throw MemoryBudgetError(path.string() + ": " + e.what());
    } catch (const std::exception& e) {
        throw Error(path.string() + ": cannot read EXR: " + e.what());
    }
}

} // namespace atlas::io
