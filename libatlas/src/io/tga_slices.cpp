// TGA slice stacks (the Nubis voxel cloud pack layout; see tga_slices.h) and
// the TGA codec they use (uncompressed and RLE, types 2, 3, 10, 11).
#include "atlas/io/tga_slices.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"
#include "io_common.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>

namespace atlas::io {

namespace {

// ---------------------------------------------------------------- codec

// The pixel bytes of a TGA of `bytes_pp` bytes per pixel, RLE or raw, into
// `dst` (npix * bytes_pp bytes, file order). Packets may span rows.
void decode_pixels(const std::vector<uint8_t>& b, size_t pos, bool rle, size_t npix, int bytes_pp, std::vector<uint8_t>& dst,
                   const fs::path& p) {
    const size_t bpp = size_t(bytes_pp);
    if (!rle) {
        if (b.size() < pos || b.size() - pos < npix * bpp)
            throw Error(p.string() + ": TGA pixel data is truncated (expected " + std::to_string(npix * bpp) + " bytes from offset " +
                        std::to_string(pos) + ", the file has " + std::to_string(b.size() > pos ? b.size() - pos : 0) + ")");
        std::memcpy(dst.data(), b.data() + pos, npix * bpp);
        return;
    }
    size_t i = 0;
    while (i < npix) {
        if (pos >= b.size())
            throw Error(p.string() + ": TGA RLE data is truncated at byte " + std::to_string(pos) + " (decoded " + std::to_string(i) + " of " +
                        std::to_string(npix) + " pixels)");
        const size_t at = pos;
        const uint8_t head = b[pos++];
        const size_t count = size_t(head & 0x7f) + 1;
        if (i + count > npix)
            throw Error(p.string() + ": TGA RLE packet at byte " + std::to_string(at) + " (" + std::to_string(count) + " pixels from pixel " +
                        std::to_string(i) + ") runs past the end of the image (" + std::to_string(npix) + " pixels)");
        const size_t need = (head & 0x80) ? bpp : bpp * count;
        if (b.size() - pos < need)
            throw Error(p.string() + ": TGA RLE packet at byte " + std::to_string(at) + " is truncated (needs " + std::to_string(need) +
                        " bytes, the file has " + std::to_string(b.size() - pos) + ")");
        if (head & 0x80) {
            for (size_t k = 0; k < count; ++k) std::memcpy(dst.data() + (i + k) * bpp, b.data() + pos, bpp);
        } else {
            std::memcpy(dst.data() + i * bpp, b.data() + pos, need);
        }
        pos += need;
        i += count;
    }
}

// One row (or any pixel sequence) RLE-encoded and appended to `out`.
void encode_rle_row(const uint8_t* px, size_t n, size_t bpp, std::vector<uint8_t>& out) {
    const size_t min_run = bpp == 1 ? 3 : 2; // a run of 2 grey bytes costs the same as raw
    auto same = [&](size_t a, size_t c) { return std::memcmp(px + a * bpp, px + c * bpp, bpp) == 0; };
    auto run_at = [&](size_t i) {
        size_t r = 1;
        while (i + r < n && r < 128 && same(i, i + r)) ++r;
        return r;
    };
    size_t i = 0;
    while (i < n) {
        const size_t r = run_at(i);
        if (r >= min_run) {
            out.push_back(uint8_t(0x80 | (r - 1)));
            out.insert(out.end(), px + i * bpp, px + (i + 1) * bpp);
            i += r;
            continue;
        }
        // Raw packet: until a run worth encoding starts, or 128 pixels.
        size_t j = i + 1;
        while (j < n && j - i < 128 && run_at(j) < min_run) ++j;
        out.push_back(uint8_t(j - i - 1));
        out.insert(out.end(), px + i * bpp, px + j * bpp);
        i = j;
    }
}

// ---------------------------------------------------------------- names

bool iequals(const std::string& a, const std::string& b) {
    return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
               return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
           });
}

bool all_digits(const std::string& s) {
    return !s.empty() && std::all_of(s.begin(), s.end(), [](char ch) { return ch >= '0' && ch <= '9'; });
}

bool ends_with_tga(const std::string& name) { return name.size() >= 4 && iequals(name.substr(name.size() - 4), ".tga"); }

// A slice file name split into {stem, index part}; empty stem when the name
// has neither shape. atlas: "STEM.<index>.tga"; nubis: "STEM(<index>).tga".
std::pair<std::string, std::string> split_slice_name(const std::string& name, SliceNaming naming) {
    if (!ends_with_tga(name)) return {};
    const std::string base = name.substr(0, name.size() - 4);
    if (naming == SliceNaming::atlas) {
        const size_t dot = base.rfind('.');
        if (dot == std::string::npos || dot == 0) return {};
        return {base.substr(0, dot), base.substr(dot + 1)};
    }
    if (base.empty() || base.back() != ')') return {};
    const size_t open = base.rfind('(');
    if (open == std::string::npos || open == 0) return {};
    return {base.substr(0, open), base.substr(open + 1, base.size() - open - 2)};
}

// What a name given for the stack means: the stem, the naming (or both
// namings for a bare DIR/STEM), whether it names the first slice.
struct StackName {
    std::string stem;
    bool ok = false;
    bool atlas = false, nubis = false; // namings it may refer to
};

bool is_pattern(const std::string& index) {
    const bool hashes = !index.empty() && std::all_of(index.begin(), index.end(), [](char ch) { return ch == '#'; });
    const bool printf_style = index.size() >= 2 && index.front() == '%' && index.back() == 'd' &&
                              (index.size() == 2 || all_digits(index.substr(1, index.size() - 2)));
    return hashes || printf_style || index == "*";
}

long long index_value(const std::string& digits) {
    const size_t nz = digits.find_first_not_of('0');
    return nz == std::string::npos ? 0 : std::stoll(digits.substr(nz));
}

StackName parse_stack_name(const std::string& name) {
    // STEM(<n>).tga first: "a.b(0).tga" is nubis, while the atlas split would see index "b(0)".
    for (SliceNaming naming : {SliceNaming::nubis, SliceNaming::atlas}) {
        auto [stem, index] = split_slice_name(name, naming);
        if (stem.empty()) continue;
        const bool nubis = naming == SliceNaming::nubis;
        if (is_pattern(index)) return {stem, true, !nubis, nubis};
        if (all_digits(index) && index.size() <= 9) {
            if (index_value(index) == (nubis ? 0 : 1)) return {stem, true, !nubis, nubis};
            return {stem, false, !nubis, nubis};
        }
    }
    // A bare stem (DIR/STEM, as write_value takes it; it may contain dots).
    if (!name.empty() && !ends_with_tga(name)) return {name, true, true, true};
    return {};
}

// Every STEM.<digits>.tga (or STEM(<digits>).tga) in `dir`, by index.
std::map<long long, fs::path> list_slices(const fs::path& parent, const std::string& want_stem, SliceNaming naming) {
    const fs::path dir = parent.empty() ? fs::path(".") : parent;
    std::map<long long, fs::path> found;
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string n = it->path().filename().string();
        auto [stem, index] = split_slice_name(n, naming);
        if (stem != want_stem || !all_digits(index) || index.size() > 9) continue;
        const long long i = index_value(index);
        if (naming == SliceNaming::atlas && i < 1) continue;
        auto [pos, fresh] = found.emplace(i, parent / n);
        if (!fresh)
            throw Error((parent / n).string() + ": slice " + std::to_string(i) + " exists twice (also " + pos->second.filename().string() + ")");
    }
    if (ec) throw Error(dir.string() + ": cannot list the directory of the TGA stack: " + ec.message());
    return found;
}

} // namespace

// ---------------------------------------------------------------- public codec

TgaImage read_tga(const fs::path& p, const MemoryBudget* budget) {
    const MemoryBudget fallback;
    const MemoryBudget& bud = detail::budget_or_default(budget, fallback);
    detail::require_regular_file(p, "TGA");
    std::error_code ec;
    const auto file_size = fs::file_size(p, ec);
    if (ec) throw Error(p.string() + ": cannot open TGA file: " + ec.message());
    bud.check(uint64_t(file_size), p.string() + ": TGA file");
    std::ifstream in(p, std::ios::binary);
    if (!in) throw Error(p.string() + ": cannot open TGA file");
    std::vector<uint8_t> b((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    if (b.size() < 18) throw Error(p.string() + ": not a TGA file (" + std::to_string(b.size()) + " bytes, shorter than the 18-byte header)");
    const int id_len = b[0], cmap_type = b[1], type = b[2];
    const int cmap_len = b[5] | (b[6] << 8), cmap_bits = b[7];
    const int w = b[12] | (b[13] << 8), h = b[14] | (b[15] << 8);
    const int bits = b[16], desc = b[17];
    if (type == 1 || type == 9)
        throw Error(p.string() + ": colour-mapped TGA (image type " + std::to_string(type) +
                    ") is not supported; expected true-colour or grey (types 2, 3, 10, 11)");
    if ((type != 2 && type != 3 && type != 10 && type != 11) || cmap_type > 1)
        throw Error(p.string() + ": not a TGA file Atlas reads (image type " + std::to_string(type) + ", colour map type " + std::to_string(cmap_type) +
                    "; expected true-colour or grey, types 2, 3, 10 or 11)");
    const bool grey = type == 3 || type == 11;
    if (grey ? bits != 8 : (bits != 15 && bits != 16 && bits != 24 && bits != 32))
        throw Error(p.string() + ": TGA with " + std::to_string(bits) + " bits per pixel (expected " +
                    (grey ? std::string("8 for grey") : std::string("15, 16, 24 or 32 for true-colour")) + ")");
    if (w == 0 || h == 0) throw Error(p.string() + ": TGA image is " + std::to_string(w) + "x" + std::to_string(h) + " (expected at least 1x1)");
    const int bytes_pp = (bits + 7) / 8;
    const int channels = grey ? 1 : (bits == 32 || (bits == 16 && (desc & 15) >= 1) ? 4 : 3);
    const size_t npix = size_t(w) * size_t(h);
    bud.check(uint64_t(npix) * uint64_t(bytes_pp + channels), p.string() + ": TGA image " + std::to_string(w) + "x" + std::to_string(h));
    const size_t pos = 18 + size_t(id_len) + (cmap_type == 1 ? size_t(cmap_len) * size_t((cmap_bits + 7) / 8) : 0);
    std::vector<uint8_t> raw(npix * size_t(bytes_pp));
    decode_pixels(b, pos, type >= 9, npix, bytes_pp, raw, p);
    b.clear();
    b.shrink_to_fit();

    TgaImage img;
    img.width = w;
    img.height = h;
    img.channels = channels;
    img.pixels.resize(npix * size_t(channels));
    const bool top = (desc & 0x20) != 0, right_to_left = (desc & 0x10) != 0;
    for (int row = 0; row < h; ++row) {
        const int y = top ? h - 1 - row : row;
        for (int col = 0; col < w; ++col) {
            const int x = right_to_left ? w - 1 - col : col;
            const uint8_t* s = raw.data() + (size_t(row) * size_t(w) + size_t(col)) * size_t(bytes_pp);
            uint8_t* d = img.pixels.data() + (size_t(y) * size_t(w) + size_t(x)) * size_t(channels);
            if (grey) {
                d[0] = s[0];
            } else if (bytes_pp == 2) {
                const int v = s[0] | (s[1] << 8);
                auto five = [](int c) { return uint8_t((c << 3) | (c >> 2)); };
                d[0] = five((v >> 10) & 31), d[1] = five((v >> 5) & 31), d[2] = five(v & 31);
                if (channels == 4) d[3] = (v & 0x8000) ? 255 : 0;
            } else {
                d[0] = s[2], d[1] = s[1], d[2] = s[0];
                if (channels == 4) d[3] = s[3];
            }
        }
    }
    return img;
}

void write_tga(const fs::path& p, const TgaImage& img, bool rle) {
    if (img.channels != 1 && img.channels != 3 && img.channels != 4)
        throw Error(p.string() + ": cannot write TGA: " + std::to_string(img.channels) + " channels (expected 1, 3 or 4)");
    if (img.width < 1 || img.height < 1 || img.width > 65535 || img.height > 65535)
        throw Error(p.string() + ": cannot write TGA: " + std::to_string(img.width) + "x" + std::to_string(img.height) +
                    " pixels (a TGA holds 1..65535 in each direction)");
    const size_t w = size_t(img.width), h = size_t(img.height), bpp = size_t(img.channels);
    if (img.pixels.size() != w * h * bpp)
        throw Error(p.string() + ": cannot write TGA: " + std::to_string(img.pixels.size()) + " bytes of pixels for " + std::to_string(w) + "x" +
                    std::to_string(h) + "x" + std::to_string(bpp));
    std::vector<uint8_t> out(18, 0);
    out[2] = uint8_t(img.channels == 1 ? (rle ? 11 : 3) : (rle ? 10 : 2));
    out[12] = uint8_t(w & 255), out[13] = uint8_t(w >> 8);
    out[14] = uint8_t(h & 255), out[15] = uint8_t(h >> 8);
    out[16] = uint8_t(8 * bpp);
    out[17] = uint8_t(img.channels == 4 ? 8 : 0); // alpha bits; origin bottom-left
    // File byte order: B G R A; rows bottom-up (img row 0 is the bottom).
    std::vector<uint8_t> row(w * bpp);
    out.reserve(18 + (rle ? w * h * bpp / 4 : w * h * bpp) + 26);
    for (size_t y = 0; y < h; ++y) {
        const uint8_t* s = img.pixels.data() + y * w * bpp;
        for (size_t x = 0; x < w; ++x) {
            uint8_t* d = row.data() + x * bpp;
            const uint8_t* q = s + x * bpp;
            if (bpp == 1) {
                d[0] = q[0];
            } else {
                d[0] = q[2], d[1] = q[1], d[2] = q[0];
                if (bpp == 4) d[3] = q[3];
            }
        }
        if (rle) encode_rle_row(row.data(), w, bpp, out);
        else out.insert(out.end(), row.begin(), row.end());
    }
    // TGA 2.0 footer (no extension or developer area).
    static const char kFooter[] = "TRUEVISION-XFILE.";
    out.insert(out.end(), 8, 0);
    out.insert(out.end(), kFooter, kFooter + sizeof kFooter); // with its NUL
    std::ofstream f(p, std::ios::binary | std::ios::trunc);
    if (!f) throw Error(p.string() + ": cannot write TGA (cannot create the file)");
    f.write(reinterpret_cast<const char*>(out.data()), std::streamsize(out.size()));
    if (!f.flush()) throw Error(p.string() + ": cannot write TGA (write failed; disk full?)");
}

std::string tga_slice_name(const std::string& stem, int z, int nz, SliceNaming naming) {
    if (naming == SliceNaming::nubis) return stem + "(" + std::to_string(z) + ").tga";
    const int digits = std::max(3, int(std::to_string(nz).size()));
    std::string n = std::to_string(z + 1);
    if (int(n.size()) < digits) n = std::string(size_t(digits - int(n.size())), '0') + n;
    return stem + "." + n + ".tga";
}

// ---------------------------------------------------------------- stacks

std::vector<fs::path> write_tga_slices(const Field3D& f, const fs::path& dir, const std::string& stem, const SliceOptions& o) {
    if (stem.empty()) throw Error("tga-slices: the file stem is empty (expected DIR/STEM, giving STEM.001.tga ... or STEM(0).tga ...)");
    const std::string where = "tga-slices '" + (dir / stem).string() + "': ";
    if (!detail::valid_range(o.range_min, o.range_max))
        throw Error(where + "range must be finite with max > min, got [" + std::to_string(o.range_min) + ", " + std::to_string(o.range_max) + "]");
    std::vector<int> map = o.channel_map;
    if (map.empty())
        for (int c = 0; c < 4; ++c) map.push_back(c < f.channels() ? c : -1);
    if (map.size() != 4) throw Error(where + "the channel map needs 4 entries (R, G, B, A), got " + std::to_string(map.size()));
    for (int m : map)
        if (m < -1 || m >= f.channels())
            throw Error(where + "the channel map refers to channel " + std::to_string(m) + " of a " + std::to_string(f.channels()) +
                        "-channel field (expected -1 or 0.." + std::to_string(f.channels() - 1) + ")");
    if (f.nx() > 65535 || f.ny() > 65535)
        throw Error(where + "slices are " + std::to_string(f.nx()) + "x" + std::to_string(f.ny()) + " (a TGA holds at most 65535x65535)");
    const int w = f.nx(), h = f.ny();
    const int out_ch = o.pixels == SlicePixels::rgba ? 4 : (o.pixels == SlicePixels::rgb ? 3 : 1);
    const detail::Quantiser quantise(o.range_min, o.range_max, 8);
    StagedOutputs staged(dir);
    std::vector<fs::path> written;
    TgaImage img;
    img.width = w;
    img.height = h;
    img.channels = out_ch;
    img.pixels.resize(size_t(w) * size_t(h) * size_t(out_ch));
    for (int z = 0; z < f.nz(); ++z) {
        const std::string name = tga_slice_name(stem, z, f.nz(), o.naming);
        const fs::path p = dir / name;
        for (int k = 0; k < out_ch; ++k) {
            const int c = map[size_t(k)];
            for (int y = 0; y < h; ++y)
                for (int x = 0; x < w; ++x) {
                    uint8_t v = k == 3 ? o.default_alpha : 0;
                    if (c >= 0) {
                        const float s = f.at(c, x, y, z);
                        if (std::isnan(s))
                            throw Error(p.string() + ": cannot write TGA slice: NaN at voxel (" + std::to_string(x) + ", " + std::to_string(y) +
                                        ", " + std::to_string(z) + ") of channel '" + f.channel_name(c) + "'");
                        v = uint8_t(quantise(s));
                    }
                    img.pixels[(size_t(y) * size_t(w) + size_t(x)) * size_t(out_ch) + size_t(k)] = v;
                }
        }
        try {
            write_tga(staged.stage(name), img, o.rle);
        } catch (const Error& e) {
            throw Error(p.string() + ": cannot write TGA slice (" + e.what() + ")");
        }
        written.push_back(p);
    }
    staged.commit();
    return written;
}

std::vector<fs::path> find_tga_slices(const fs::path& first) {
    const std::string name = first.filename().string();
    const StackName sn = parse_stack_name(name);
    if (!sn.ok) {
        if (!sn.stem.empty())
            throw Error(first.string() + ": expected the first slice of the TGA stack (" +
                        tga_slice_name(sn.stem, 0, 1, sn.nubis ? SliceNaming::nubis : SliceNaming::atlas) + ")");
        throw Error(first.string() + ": expected the first slice of a TGA stack (STEM.001.tga or STEM(0).tga) or a pattern (STEM.###.tga, "
                                     "STEM.%03d.tga, STEM.*.tga, STEM(*).tga, or DIR/STEM)");
    }
    const fs::path parent = first.parent_path();
    std::map<long long, fs::path> atlas_found, nubis_found;
    if (sn.atlas) atlas_found = list_slices(parent, sn.stem, SliceNaming::atlas);
    if (sn.nubis) nubis_found = list_slices(parent, sn.stem, SliceNaming::nubis);
    if (!atlas_found.empty() && !nubis_found.empty())
        throw Error(first.string() + ": two TGA stacks match, " + atlas_found.begin()->second.filename().string() + " ... and " +
                    nubis_found.begin()->second.filename().string() + " ...; name the first slice of the one to read");
    const bool nubis = !nubis_found.empty() || !sn.atlas;
    const SliceNaming naming = nubis ? SliceNaming::nubis : SliceNaming::atlas;
    const auto& found = nubis ? nubis_found : atlas_found;
    const long long base = nubis ? 0 : 1;
    if (found.empty() || found.begin()->first != base)
        throw Error((parent / tga_slice_name(sn.stem, 0, 1, naming)).string() + ": cannot open TGA slice (no such file)");
    std::vector<fs::path> files;
    long long expect = base;
    for (const auto& [i, p] : found) {
        if (i != expect) {
            const int nz = int(std::min<long long>(found.rbegin()->first, 1000000000));
            throw Error((parent / tga_slice_name(sn.stem, int(expect - base), nz, naming)).string() + ": missing slice in the TGA stack (" +
                        p.filename().string() + " exists after it)");
        }
        files.push_back(p);
        ++expect;
    }
    return files;
}

Field3D read_tga_slices(const fs::path& first, Box3d bounds, int channels, const MemoryBudget* budget) {
    if (channels < 1 || channels > 4) throw Error(first.string() + ": tga-slices channels must be 1..4, got " + std::to_string(channels));
    if (!bounds.valid()) throw Error(first.string() + ": tga-slices bounds must be finite with max > min in every axis");
    const MemoryBudget fallback;
    const MemoryBudget& bud = detail::budget_or_default(budget, fallback);
    const auto files = find_tga_slices(first);
    TgaImage s = read_tga(files[0], &bud);
    const int w = s.width, h = s.height;
    Field3D f({{w, h, int(files.size())}}, channels, bounds, {}, &bud);
    for (size_t z = 0; z < files.size(); ++z) {
        if (z > 0) s = read_tga(files[z], &bud);
        if (s.width != w || s.height != h)
            throw Error(files[z].string() + ": slice is " + std::to_string(s.width) + "x" + std::to_string(s.height) + ", expected " +
                        std::to_string(w) + "x" + std::to_string(h) + " like " + files[0].filename().string());
        // Channels the file lacks: colour 0, alpha 1 (opaque).
        const size_t sc = size_t(s.channels);
        for (int c = 0; c < channels; ++c) {
            float* dst = f.channel(c).data() + f.index(0, 0, int(z));
            if (c >= s.channels) {
                std::fill_n(dst, size_t(w) * size_t(h), c == 3 ? 1.0f : 0.0f);
                continue;
            }
            for (size_t i = 0; i < size_t(w) * size_t(h); ++i) dst[i] = float(s.pixels[i * sc + size_t(c)]) / 255.0f;
        }
    }
    return f;
}

} // namespace atlas::io
