// OpenVDB files: dense Field3D <-> sparse float / vec3s grids (see vdb.h).
#include "atlas/io/vdb.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "io_common.h"
#include "vdb_internal.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <array>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <mutex>
#include <set>

namespace atlas::io {

namespace detail {

void init_openvdb() {
    // openvdb::initialize() is idempotent and thread-safe; call_once only
    // spares its internal lock on every read and write.
    static std::once_flag once;
    std::call_once(once, [] { openvdb::initialize(); });
}

// Index (i,j,k) -> world min + (i + 0.5) * voxel: the field's voxel centres.
openvdb::math::Transform::Ptr field_transform(const Field3D& f) {
    const Vec3d v = f.voxel_size();
    openvdb::math::Mat4d m = openvdb::math::Mat4d::identity();
    m.setToScale(openvdb::Vec3d(v[0], v[1], v[2]));
    m.setTranslation(openvdb::Vec3d(f.bounds().min[0] + 0.5 * v[0], f.bounds().min[1] + 0.5 * v[1], f.bounds().min[2] + 0.5 * v[2]));
    return openvdb::math::Transform::createLinearTransform(m);
}

void add_atlas_meta(openvdb::GridBase& g, const Field3D& f) {
    const auto& b = f.bounds();
    g.insertMeta("atlas_bounds_min", openvdb::Vec3DMetadata(openvdb::Vec3d(b.min[0], b.min[1], b.min[2])));
    g.insertMeta("atlas_bounds_max", openvdb::Vec3DMetadata(openvdb::Vec3d(b.max[0], b.max[1], b.max[2])));
    g.insertMeta("atlas_resolution", openvdb::Vec3IMetadata(openvdb::Vec3i(f.nx(), f.ny(), f.nz())));
}

// OpenVDB writes a random UUID into every archive header. Replace it with one
// derived from what was written, so the same field gives the same bytes.
void write_vdb_grids(const fs::path& path, const openvdb::GridPtrVec& grids) {
    // Same bytes as openvdb::io::File::write, through a stream whose state is checked.
    struct CheckedArchive : openvdb::io::Archive {
        void write_to(std::ostream& os, const openvdb::GridPtrVec& g) const { Archive::write(os, g, /*seekable=*/true); }
    };
    try {
        std::ofstream file(path, std::ios::out | std::ios::binary | std::ios::trunc);
        if (!file) throw Error("cannot create the file");
        CheckedArchive().write_to(file, grids);
        file.close();
        if (!file) throw Error(std::string("write failed (") + std::strerror(errno) + "; disk full?)");
    } catch (...) {
        std::error_code ec;
        fs::remove(path, ec);
        throw;
    }
}

void make_uuid_deterministic(const fs::path& path, const Hash128& content) {
    // Header: magic (8), file version (4), library version (4 + 4), grid offsets flag (1), UUID text (36).
    constexpr size_t at = 21, len = 36;
    std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
    std::string head(at + len, '\0');
    file.read(head.data(), std::streamsize(head.size()));
    if (!file) throw Error(path.string() + ": cannot finish the VDB header (file too short)");
    const std::string uuid = head.substr(at, len);
    // An unknown header layout is left alone rather than damaged.
    if (uuid[8] != '-' || uuid[13] != '-' || uuid[18] != '-' || uuid[23] != '-') return;
    const std::string hex = content.hex();
    const std::string det = hex.substr(0, 8) + "-" + hex.substr(8, 4) + "-" + hex.substr(12, 4) + "-" + hex.substr(16, 4) + "-" + hex.substr(20, 12);
    file.seekp(std::streamoff(at));
    file.write(det.data(), std::streamsize(len));
    file.flush();
    if (!file) throw Error(path.string() + ": cannot finish the VDB header");
}

} // namespace detail

namespace {
using detail::add_atlas_meta;
using detail::field_transform;
using detail::init_openvdb;
using detail::make_uuid_deterministic;
using detail::write_vdb_grids;


// The name of a vector grid: the channels' shared "NAME." prefix (vel.x,
// vel.y, vel.z -> vel), else "vector".
std::string vector_grid_name(const Field3D& f) {
    const std::string& a = f.channel_name(0);
    const size_t dot = a.rfind('.');
    if (dot != std::string::npos && dot > 0) {
        const std::string prefix = a.substr(0, dot + 1);
        if (f.channel_name(1).rfind(prefix, 0) == 0 && f.channel_name(2).rfind(prefix, 0) == 0) return a.substr(0, dot);
    }
    return "vector";
}

std::string list_names(const std::vector<std::string>& names) {
    std::string s;
    for (const auto& n : names) s += (s.empty() ? "" : ", ") + n;
    return s;
}

// Axis-aligned with positive scale: scale + translation only.
bool axis_aligned(const openvdb::math::Transform& xf) {
    if (!xf.isLinear()) return false;
    const openvdb::Mat4d m = xf.baseMap()->getAffineMap()->getMat4();
    for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) {
            const double v = m(i, j);
            if (i == j ? !(v > 0) : std::fabs(v) > 1e-12 * std::fabs(m(i, i)) + 0.0) return false;
        }
    return true;
}

// The atlas metadata describes exactly this transform (not one edited since).
bool meta_matches(const openvdb::math::Transform& xf, const Box3d& b, const openvdb::Vec3i& r) {
    for (int k = 0; k < 3; ++k)
        if (r[k] <= 0) return false;
    if (!b.valid()) return false;
    const openvdb::Vec3d o = xf.indexToWorld(openvdb::Vec3d(0, 0, 0));
    const openvdb::Vec3d e = xf.indexToWorld(openvdb::Vec3d(r.x(), r.y(), r.z()));
    for (int k = 0; k < 3; ++k) {
        const double v = (b.max[k] - b.min[k]) / r[k];
        const double tol = 1e-6 * v;
        if (std::fabs(o[k] - (b.min[k] + 0.5 * v)) > tol || std::fabs(e[k] - (b.max[k] + 0.5 * v)) > tol) return false;
    }
    return true;
}

} // namespace

void write_vdb(const Field3D& f, const fs::path& path, const VdbOptions& o) {
    init_openvdb();
    const std::string where = path.string() + ": cannot write VDB: ";
    if (!(o.tolerance >= 0) || !std::isfinite(o.tolerance)) throw Error(where + "tolerance must be a finite number >= 0, got " + std::to_string(o.tolerance));
    const size_t grid_count = o.vector3 ? 1 : size_t(f.channels());
    if (o.vector3 && f.channels() != 3) throw Error(where + "vector3 needs a 3-channel field, the field has " + std::to_string(f.channels()));
    std::vector<std::string> names = o.grid_names;
    if (names.empty()) names = o.vector3 ? std::vector<std::string>{vector_grid_name(f)} : f.channel_names();
    if (names.size() != grid_count)
        throw Error(where + std::to_string(names.size()) + " grid names given for " + std::to_string(grid_count) + " grid(s)");
    for (size_t i = 0; i < names.size(); ++i) {
        if (names[i].empty()) throw Error(where + "grid name " + std::to_string(i) + " is empty");
        for (size_t j = i + 1; j < names.size(); ++j)
            if (names[i] == names[j]) throw Error(where + "grid name '" + names[i] + "' is used twice");
    }

    openvdb::GridPtrVec grids;
    const openvdb::CoordBBox bbox(openvdb::Coord(0, 0, 0), openvdb::Coord(f.nx() - 1, f.ny() - 1, f.nz() - 1));
    openvdb::math::Transform::Ptr xf;
    try {
        xf = field_transform(f);
    } catch (const std::exception& e) {
        const Vec3d v = f.voxel_size();
        throw Error(where + "OpenVDB cannot represent voxel size " + std::to_string(v[0]) + " x " + std::to_string(v[1]) + " x " +
                    std::to_string(v[2]) + " (" + e.what() + "); scale the bounds to larger units");
    }
    if (o.vector3) {
        auto g = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        auto acc = g->getAccessor();
        for (int z = 0; z < f.nz(); ++z)
            for (int y = 0; y < f.ny(); ++y)
                for (int x = 0; x < f.nx(); ++x) {
                    const openvdb::Vec3s v(f.at(0, x, y, z), f.at(1, x, y, z), f.at(2, x, y, z));
                    // Inactive only when every component is within tolerance of 0 (NaN stays active).
                    if (!(std::fabs(v[0]) <= o.tolerance && std::fabs(v[1]) <= o.tolerance && std::fabs(v[2]) <= o.tolerance))
                        acc.setValue(openvdb::Coord(x, y, z), v);
                }
        g->setName(names[0]);
        g->setTransform(xf);
        g->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
        g->setGridClass(openvdb::GRID_FOG_VOLUME);
        add_atlas_meta(*g, f);
        grids.push_back(g);
    } else {
        for (int c = 0; c < f.channels(); ++c) {
            auto g = openvdb::FloatGrid::create(0.0f);
            // |v - 0| <= tolerance stays inactive. copyFromDense is parallel, but
            // the tree it builds depends only on the values.
            openvdb::tools::Dense<const float, openvdb::tools::LayoutXYZ> dense(bbox, f.channel(c).data());
            openvdb::tools::copyFromDense(dense, *g, o.tolerance);
            g->setName(names[size_t(c)]);
            g->setTransform(xf->copy());
            g->setGridClass(openvdb::GRID_FOG_VOLUME);
            add_atlas_meta(*g, f);
            grids.push_back(g);
        }
    }
    try {
        write_vdb_grids(path, grids);
    } catch (const std::exception& e) {
        throw Error(where + e.what());
    }
    Hasher h;
    f.hash_into(h);
    h.add(o.tolerance).add(o.vector3);
    for (const auto& n : names) h.add(n);
    make_uuid_deterministic(path, h.finish());
}

namespace {
// OpenVDB trusts the lengths, counts and offsets in a file: one truncated to
// 173 bytes took 43 s and 5 GB to fail, and fuzzed tree data crashed inside
// Grid::readTopology (tests/fuzz/known-crashes). So everything OpenVDB will
// parse is walked here first, in the order OpenVDB reads it (OpenVDB 10,
// file format 222..224; see Archive::readGrid, RootNode/InternalNode/LeafNode
// readTopology/readBuffers, io::readCompressedValues): the header, file
// metadata and grid descriptors always; for a grid that is read, its
// metadata, transform, topology and every leaf buffer. Every length is checked
// against what is left of the file, every count against the bytes it needs,
// metadata of a known type must have that type's size (OpenVDB reads the
// type's size whatever the length says), node masks must not overlap, child
// origins must be aligned and unique, and compressed blocks must say the size
// OpenVDB expects. Only what passes is handed to OpenVDB.
struct VdbGridEntry {
    std::string name, type, parent; // unique name (as stored), type without "_HalfFloat", instance parent
    bool half = false;              // saved as half floats
    int64_t grid_pos = 0, block_pos = 0, end_pos = 0;
};
struct VdbLayout {
    uint32_t version = 0;
    std::vector<VdbGridEntry> grids;
};

class VdbScanner {
public:
    explicit VdbScanner(const fs::path& path) : where_(path.string() + ": not a readable VDB file: "), in_(path, std::ios::binary) {
        std::error_code ec;
        size_ = fs::file_size(path, ec);
        if (ec) throw Error(where_ + ec.message());
        if (!in_) throw Error(where_ + "cannot open it");
    }
    uint64_t size() const { return size_; }
    uint64_t pos() const { return pos_; }
    [[noreturn]] void fail(const std::string& what) const { throw Error(where_ + what); }
    void need(uint64_t n, const char* what) const {
        if (n > size_ - std::min(pos_, size_))
            fail(std::string(what) + " at byte " + std::to_string(pos_) + " runs past the end of the file (" + std::to_string(size_) + " bytes)");
    }
    void read(void* dst, uint64_t n, const char* what) {
        need(n, what);
        in_.read(static_cast<char*>(dst), std::streamsize(n));
        if (!in_) fail("read error at byte " + std::to_string(pos_));
        pos_ += n;
    }
    void skip(uint64_t n, const char* what) {
        need(n, what);
        in_.seekg(std::streamoff(n), std::ios::cur);
        pos_ += n;
    }
    void seek(uint64_t at) {
        if (at > size_) fail("offset " + std::to_string(at) + " is past the end of the file");
        in_.clear();
        in_.seekg(std::streamoff(at));
        pos_ = at;
    }
    template <class T> T get(const char* what) {
        T v{};
        read(&v, sizeof v, what);
        return v;
    }
    std::string str(const char* what, uint32_t max_len = 1u << 16) {
        const uint32_t n = get<uint32_t>(what);
        if (n > max_len) fail(std::string(what) + " at byte " + std::to_string(pos_ - 4) + " is " + std::to_string(n) + " bytes long (at most " + std::to_string(max_len) + " expected)");
        std::string s(n, '\0');
        read(s.data(), n, what);
        return s;
    }
    // A bit mask of `words` 64-bit words.
    std::vector<uint64_t> mask(size_t words, const char* what) {
        std::vector<uint64_t> m(words);
        read(m.data(), words * 8, what);
        return m;
    }

private:
    std::string where_;
    std::ifstream in_;
    uint64_t size_ = 0, pos_ = 0;
};

size_t count_on(const std::vector<uint64_t>& m) {
    size_t n = 0;
    for (uint64_t w : m) n += size_t(__builtin_popcountll(w));
    return n;
}

// The size OpenVDB's TypedMetadata<T> reads for a registered type name; 0 for
// strings and unknown types (read as their length says), -1 for __delayedload.
int metadata_size(const std::string& type) {
    static const std::pair<const char*, int> sizes[] = {
        {"bool", 1},    {"double", 8},   {"float", 4},    {"int32", 4},    {"int64", 8},    {"vec2i", 8},     {"vec2s", 8},
        {"vec2d", 16},  {"vec3i", 12},   {"vec3s", 12},   {"vec3d", 24},   {"vec4i", 16},   {"vec4s", 16},    {"vec4d", 32},
        {"mat4s", 64},  {"mat4d", 128},  {"ptidx32", 4},  {"ptidx64", 8},  {"__delayedload", -1}};
    for (const auto& [name, n] : sizes)
        if (type == name) return n;
    return 0;
}

// io::DelayedLoadMetadata::readValue allocates and blosc-decompresses what
// its counts say; its value must be exactly what the writer produces.
void check_delayed_load(VdbScanner& s, uint32_t bytes) {
    if (bytes == 0) return;
    const uint64_t end = s.pos() + bytes;
    s.need(bytes, "a delayed-load metadata value");
    auto block = [&](uint32_t count, uint64_t item, const char* what) {
        const uint32_t n = s.get<uint32_t>(what);
        if (n == 0) {
            s.skip(uint64_t(count) * item, what);
        } else {
            if (n < 16) s.fail(std::string(what) + ": a compressed block of " + std::to_string(n) + " bytes is shorter than its header");
            uint8_t head[16];
            s.read(head, 16, what);
            uint32_t nbytes = 0, cbytes = 0;
            std::memcpy(&nbytes, head + 4, 4);
            std::memcpy(&cbytes, head + 12, 4);
            // The writer pads what is shorter than 128 bytes to 128 (points/StreamCompression.cc);
            // the reader decompresses into room for the padded size.
            const uint64_t want = uint64_t(count) * item;
            if ((nbytes != want && !(want < 128 && nbytes == 128)) || cbytes != n)
                s.fail(std::string(what) + ": the compressed block's sizes do not match its " + std::to_string(count) + " entries");
            s.skip(n - 16, what);
        }
    };
    if (bytes < 12) s.fail("a delayed-load metadata value of " + std::to_string(bytes) + " bytes is too short");
    const uint32_t count = s.get<uint32_t>("a delayed-load metadata value");
    // One entry per leaf: a leaf takes more than 64 bytes of the file.
    if (uint64_t(count) * 64 > s.size()) s.fail("delayed-load metadata claims " + std::to_string(count) + " leaves, more than the file can hold");
    block(count, 1, "delayed-load masks");
    const uint32_t sizes = s.get<uint32_t>("delayed-load metadata");
    if (sizes != 0xffffffffu) {
        // The same block layout, read back through the count already taken.
        s.seek(s.pos() - 4);
        block(count, 8, "delayed-load compressed sizes");
    }
    if (s.pos() > end) s.fail("a delayed-load metadata value runs past its own length");
    s.seek(end);
}

void check_metadata(VdbScanner& s, const char* what) {
    const uint32_t n = s.get<uint32_t>(what);
    s.need(uint64_t(n) * 12, what);
    for (uint32_t i = 0; i < n; ++i) {
        s.str("a metadata name");
        const std::string type = s.str("a metadata type");
        const uint32_t bytes = s.get<uint32_t>("a metadata value");
        const int expect = metadata_size(type);
        if (expect < 0) {
            check_delayed_load(s, bytes);
        } else if (expect > 0) {
            if (bytes != uint32_t(expect))
                s.fail("metadata of type " + type + " at byte " + std::to_string(s.pos()) + " is " + std::to_string(bytes) + " bytes long, expected " + std::to_string(expect));
            if (type == "bool") {
                if (s.get<uint8_t>("a bool metadata value") > 1) s.fail("a bool metadata value is neither 0 nor 1");
            } else {
                s.skip(bytes, "a metadata value");
            }
        } else {
            s.skip(bytes, "a metadata value");
        }
    }
}

// Transform::read: a registered map type name, then that map's fixed-size data.
void check_transform(VdbScanner& s) {
    const std::string type = s.str("a grid transform", 256);
    static const std::pair<const char*, int> maps[] = {{"AffineMap", 128}, {"UnitaryMap", 128}, {"ScaleMap", 120}, {"UniformScaleMap", 120},
                                                       {"TranslationMap", 24}, {"ScaleTranslateMap", 144}, {"UniformScaleTranslateMap", 144}};
    for (const auto& [name, n] : maps)
        if (type == name) {
            s.skip(uint64_t(n), "a grid transform");
            return;
        }
    if (type == "NonlinearFrustumMap") s.fail("a frustum transform (only linear, axis-aligned grids can become a field)");
    s.fail("unknown transform type '" + type.substr(0, 64) + "'");
}

// io::readCompressedValues of `count` values (value_size bytes each, half
// floats when `half`) under `value_mask`.
void check_values(VdbScanner& s, uint32_t compression, size_t count, const std::vector<uint64_t>& value_mask, size_t value_size, bool half,
                  const char* what) {
    const bool mask_compressed = compression & 0x2;
    const int8_t meta = s.get<int8_t>(what);
    if (meta < 0 || meta > 6) s.fail(std::string(what) + ": unknown value compression " + std::to_string(int(meta)) + " at byte " + std::to_string(s.pos() - 1));
    if (meta == 2 || meta == 4 || meta == 5) s.skip(value_size, what);
    if (meta == 5) s.skip(value_size, what);
    if (meta == 3 || meta == 4 || meta == 5) s.skip(value_mask.size() * 8, what);
    const size_t n = mask_compressed && meta != 6 ? count_on(value_mask) : count;
    if (half && n == 0) return; // HalfReader reads nothing for no values
    const uint64_t bytes = uint64_t(n) * (half ? value_size / 2 : value_size);
    if (compression & (0x4 | 0x1)) {
        const int64_t stored = s.get<int64_t>(what);
        if (stored <= 0) {
            if (uint64_t(-stored) != bytes)
                s.fail(std::string(what) + " at byte " + std::to_string(s.pos() - 8) + ": a block of " + std::to_string(-stored) + " bytes where " + std::to_string(bytes) + " are expected");
            s.skip(bytes, what);
        } else if (compression & 0x4) {
            if (stored < 16) s.fail(std::string(what) + ": a compressed block of " + std::to_string(stored) + " bytes is shorter than its header");
            uint8_t head[16];
            s.read(head, 16, what);
            uint32_t nbytes = 0, cbytes = 0;
            std::memcpy(&nbytes, head + 4, 4);
            std::memcpy(&cbytes, head + 12, 4);
            if (nbytes != bytes || cbytes != uint64_t(stored))
                s.fail(std::string(what) + " at byte " + std::to_string(s.pos() - 16) + ": the compressed block's header does not match its size");
            s.skip(uint64_t(stored) - 16, what);
        } else {
            // zlib's uncompress is bounded by the expected size.
            s.skip(uint64_t(stored), what);
        }
    } else {
        s.skip(bytes, what);
    }
}

constexpr int kMaxCoord = 1 << 29; // keeps every node's bounding box inside int32

// The topology and buffers of a Tree_<float|vec3s>_5_4_3 grid.
void check_tree(VdbScanner& s, const VdbGridEntry& g, uint32_t compression, size_t value_size) {
    // Written as 1 since OpenVDB 3; OpenVDB logs a warning for anything else.
    if (s.get<int32_t>("a tree's buffer count") != 1) s.fail("grid '" + g.name + "' has a multi-buffer tree (not supported)");
    s.skip(value_size, "a tree's background value");
    const uint32_t tiles = s.get<uint32_t>("a root tile count");
    const uint32_t children = s.get<uint32_t>("a root child count");
    if (tiles == 0 && children == 0) return;
    s.need(uint64_t(tiles) * (12 + value_size + 1), "the root tiles");
    s.need(uint64_t(children) * (12 + 8192), "the root children");
    std::set<std::array<int32_t, 3>> keys;
    auto origin = [&](const char* what) {
        std::array<int32_t, 3> c;
        s.read(c.data(), 12, what);
        for (int32_t v : c)
            if (v % 4096 != 0 || v < -kMaxCoord || v > kMaxCoord)
                s.fail(std::string(what) + " at byte " + std::to_string(s.pos() - 12) + " has an unaligned or out-of-range origin");
        if (!keys.insert(c).second) s.fail(std::string(what) + " at byte " + std::to_string(s.pos() - 12) + " repeats an origin");
        return c;
    };
    for (uint32_t i = 0; i < tiles; ++i) {
        origin("a root tile");
        s.skip(value_size, "a root tile");
        if (s.get<uint8_t>("a root tile") > 1) s.fail("a root tile's active flag is neither 0 nor 1");
    }
    // Leaf counts per root child, in file order; buffers come in origin order.
    std::map<std::array<int32_t, 3>, size_t> leaves_of;
    auto check_masks = [&](const std::vector<uint64_t>& child, const std::vector<uint64_t>& value, const char* what) {
        for (size_t w = 0; w < child.size(); ++w)
            if (child[w] & value[w]) s.fail(std::string(what) + " at byte " + std::to_string(s.pos()) + " has a child and a value in one slot");
    };
    for (uint32_t i = 0; i < children; ++i) {
        const auto key = origin("a root child");
        size_t leaves = 0;
        const auto c5 = s.mask(512, "an internal node's child mask");
        const auto v5 = s.mask(512, "an internal node's value mask");
        check_masks(c5, v5, "an internal node");
        check_values(s, compression, 32768, v5, value_size, g.half, "an internal node's values");
        const size_t n4 = count_on(c5);
        s.need(uint64_t(n4) * 1024, "internal nodes");
        for (size_t j = 0; j < n4; ++j) {
            const auto c4 = s.mask(64, "an internal node's child mask");
            const auto v4 = s.mask(64, "an internal node's value mask");
            check_masks(c4, v4, "an internal node");
            check_values(s, compression, 4096, v4, value_size, g.half, "an internal node's values");
            const size_t n3 = count_on(c4);
            s.skip(uint64_t(n3) * 64, "leaf value masks");
            leaves += n3;
        }
        leaves_of[key] = leaves;
    }
    if (s.pos() > uint64_t(g.block_pos)) s.fail("grid '" + g.name + "''s topology runs into its data");
    // Grid::readBuffers follows the topology directly.
    size_t total = 0;
    for (const auto& [key, n] : leaves_of) total += n;
    s.need(uint64_t(total) * 65, "the leaf buffers");
    for (const auto& [key, n] : leaves_of)
        for (size_t k = 0; k < n; ++k) {
            const auto m = s.mask(8, "a leaf's value mask");
            check_values(s, compression, 512, m, value_size, g.half, "a leaf's values");
        }
    if (s.pos() > uint64_t(g.end_pos)) s.fail("grid '" + g.name + "''s data runs past the end its descriptor gives");
}

// The header, file metadata and grid descriptors.
VdbLayout check_vdb_structure(const fs::path& path) {
    VdbScanner s(path);
    VdbLayout layout;
    if (s.get<int64_t>("the header") != 0x56444220) s.fail("no VDB magic number at the start");
    layout.version = s.get<uint32_t>("the header");
    // Files older than 222 (OpenVDB before 3.0, 2014) have another header layout that
    // cannot be checked here, and OpenVDB trusts their lengths (a fuzzed version-0
    // header made it allocate 3.4 GB): refused by name. 225 and later: not yet written
    // by any OpenVDB, so their layout is unknown.
    if (layout.version < 222 || layout.version > 224)
        s.fail("file format version " + std::to_string(layout.version) + " is not supported (expected 222..224, written by OpenVDB 3 or later)");
    s.get<uint32_t>("the header"); // library major
    s.get<uint32_t>("the header"); // library minor
    const uint8_t offsets = s.get<uint8_t>("the header");
    char uuid[36];
    s.read(uuid, 36, "the header");
    check_metadata(s, "the file metadata");
    // Without grid offsets (a stream), OpenVDB reads grids back to back with nothing to check them against.
    if (!offsets) s.fail("the file has no grid offsets (written as a stream); save it with openvdb::io::File");
    const uint32_t grids = s.get<uint32_t>("the grid count");
    // A descriptor is at least 3 lengths and 3 offsets.
    s.need(uint64_t(grids) * 36, "the grid descriptors");
    for (uint32_t i = 0; i < grids; ++i) {
        VdbGridEntry g;
        g.name = s.str("a grid name");
        g.type = s.str("a grid type", 256);
        const std::string half = "_HalfFloat";
        if (g.type.size() > half.size() && g.type.compare(g.type.size() - half.size(), half.size(), half) == 0) {
            g.half = true;
            g.type.resize(g.type.size() - half.size());
        }
        g.parent = s.str("a grid's instance parent");
        int64_t offs[3];
        s.read(offs, sizeof offs, "a grid descriptor");
        for (int64_t o : offs)
            if (o < 0 || uint64_t(o) > s.size())
                s.fail("grid " + std::to_string(i) + " claims data up to byte " + std::to_string(o) + ", the file has " + std::to_string(s.size()) + " bytes (truncated?)");
        if (offs[0] > offs[1] || offs[1] > offs[2]) s.fail("grid " + std::to_string(i) + " has inconsistent offsets");
        if (uint64_t(offs[0]) < s.pos()) s.fail("grid " + std::to_string(i) + "'s data starts inside its own descriptor");
        g.grid_pos = offs[0];
        g.block_pos = offs[1];
        g.end_pos = offs[2];
        // The grid's own metadata is read for every grid (File::open reads no
        // grid, but getGrids and readGrid do): compression flags, then the map.
        const uint64_t next = uint64_t(offs[2]);
        s.seek(uint64_t(offs[0]));
        s.get<uint32_t>("a grid's compression flags");
        check_metadata(s, "a grid's metadata");
        if (s.pos() > uint64_t(offs[1])) s.fail("grid " + std::to_string(i) + "'s metadata runs into its data");
        layout.grids.push_back(std::move(g));
        s.seek(next);
    }
    return layout;
}

// The value size of a grid type read_vdb densifies; 0 for others.
size_t densified_value_size(const std::string& type) {
    if (type == "Tree_float_5_4_3") return 4;
    if (type == "Tree_vec3s_5_4_3") return 12;
    return 0;
}

// "Tree_float_5_4_3" -> "float", as Grid::valueType() says.
std::string value_type_of(const std::string& type) {
    std::string t = type;
    if (t.rfind("Tree_", 0) == 0) t = t.substr(5);
    const size_t tail = t.find("_5_4_3");
    if (tail != std::string::npos) t = t.substr(0, tail);
    return t;
}

// Everything OpenVDB reads of one grid: compression, metadata, transform, tree.
void check_grid_data(const fs::path& path, const VdbGridEntry& g) {
    const size_t value_size = densified_value_size(g.type);
    VdbScanner s(path);
    if (!g.parent.empty()) s.fail("grid '" + g.name + "' is an instance of grid '" + g.parent + "' (instanced grids are not supported)");
    if (!value_size) s.fail("grid '" + g.name + "' has type " + g.type + " (only float and vec3s grids are read)");
    s.seek(uint64_t(g.grid_pos));
    const uint32_t compression = s.get<uint32_t>("a grid's compression flags");
    check_metadata(s, "a grid's metadata");
    check_transform(s);
    check_tree(s, g, compression, value_size);
}
} // namespace

std::vector<std::string> list_vdb_grids(const fs::path& path) {
    init_openvdb();
    detail::require_regular_file(path, "VDB");
    check_vdb_structure(path);
    try {
        openvdb::io::File file(path.string());
        file.open(false);
        std::vector<std::string> names;
        for (auto it = file.beginName(); it != file.endName(); ++it) names.push_back(*it);
        file.close();
        return names;
    } catch (const std::exception& e) {
        throw Error(path.string() + ": cannot read VDB: " + e.what());
    }
}

namespace {
// A float grid's values over `bbox` into `out` (x fastest, all +0 on entry):
// what openvdb::tools::copyToDense gives (every voxel's stored value, active
// or not; tiles; the background elsewhere), visiting only the tree's tiles
// and leaves: a sparse grid costs its leaves, not its box (a 1.7 %-occupied
// 512x512x64 density: 12 % of a preview's CPU went to copyToDense).
void densify(const openvdb::FloatGrid& grid, const openvdb::CoordBBox& bbox, float* out) {
    const openvdb::Coord lo = bbox.min(), dim = bbox.dim();
    const size_t sx = size_t(dim.x()), sxy = sx * size_t(dim.y());
    auto fill = [&](openvdb::CoordBBox b, float v) {
        b.intersect(bbox);
        if (b.empty() || (v == 0.0f && !std::signbit(v))) return; // +0: the field is zero-initialised
        for (int z = b.min().z(); z <= b.max().z(); ++z)
            for (int y = b.min().y(); y <= b.max().y(); ++y) {
                float* row = out + size_t(z - lo.z()) * sxy + size_t(y - lo.y()) * sx;
                std::fill(row + (b.min().x() - lo.x()), row + (b.max().x() - lo.x()) + 1, v);
            }
    };
    // The background everywhere, then tiles, then leaves (they do not overlap).
    fill(bbox, grid.background());
    const auto& tree = grid.tree();
    auto it = tree.cbeginValueAll();
    it.setMaxDepth(it.getLeafDepth() - 1); // tiles only: leaf voxels come next
    for (; it; ++it) {
        if (it.isVoxelValue()) continue;
        openvdb::CoordBBox b;
        it.getBoundingBox(b);
        fill(b, *it);
    }
    for (auto leaf = tree.cbeginLeaf(); leaf; ++leaf) {
        openvdb::CoordBBox b = leaf->getNodeBoundingBox();
        b.intersect(bbox);
        if (b.empty()) continue;
        for (int z = b.min().z(); z <= b.max().z(); ++z)
            for (int y = b.min().y(); y <= b.max().y(); ++y)
                for (int x = b.min().x(); x <= b.max().x(); ++x)
                    out[size_t(z - lo.z()) * sxy + size_t(y - lo.y()) * sx + size_t(x - lo.x())] = leaf->getValue(openvdb::Coord(x, y, z));
    }
}

Field3D read_vdb_checked(const fs::path& path, const std::vector<std::string>& wanted, const MemoryBudget* budget) {
    detail::require_regular_file(path, "VDB");
    const VdbLayout layout = check_vdb_structure(path);
    const MemoryBudget fallback;
    const MemoryBudget& bud = detail::budget_or_default(budget, fallback);
    const std::string where = path.string() + ": ";
    if (layout.grids.empty()) throw Error(where + "the VDB file holds no grids");
    // A descriptor's name is "NAME" or, for a repeated name, "NAME\x1eN".
    auto grid_name = [](const VdbGridEntry& g) { return g.name.substr(0, g.name.find('\x1e')); };
    std::vector<std::string> present;
    for (const auto& g : layout.grids) present.push_back("'" + grid_name(g) + "' (" + value_type_of(g.type) + ")");

    // 1. Which grids (only these are parsed further, by us and then by OpenVDB).
    std::vector<const VdbGridEntry*> chosen;
    if (wanted.empty()) {
        for (const auto& g : layout.grids)
            if (densified_value_size(g.type)) chosen.push_back(&g);
        if (chosen.empty()) throw Error(where + "no float or vec3s grid in the file (it has " + list_names(present) + ")");
    } else {
        for (size_t i = 0; i < wanted.size(); ++i) {
            for (size_t j = 0; j < i; ++j)
                if (wanted[i] == wanted[j]) throw Error(where + "grid '" + wanted[i] + "' is asked for twice");
            const VdbGridEntry* found = nullptr;
            for (const auto& g : layout.grids)
                if (!found && grid_name(g) == wanted[i]) found = &g;
            if (!found) throw Error(where + "no grid named '" + wanted[i] + "' (the file has " + list_names(present) + ")");
            if (!densified_value_size(found->type))
                throw Error(where + "grid '" + wanted[i] + "' holds " + value_type_of(found->type) + " values; expected float (or vec3s)");
            chosen.push_back(found);
        }
    }
    for (const VdbGridEntry* g : chosen) check_grid_data(path, *g);
    std::vector<openvdb::GridBase::Ptr> grids;
    try {
        openvdb::io::File file(path.string());
        file.open(false);
        for (const VdbGridEntry* g : chosen) {
            openvdb::GridBase::Ptr grid = file.readGrid(g->name);
            if (!grid) throw Error("grid '" + grid_name(*g) + "' cannot be read");
            if (!grid->isType<openvdb::FloatGrid>() && !grid->isType<openvdb::Vec3SGrid>())
                throw Error("grid '" + grid_name(*g) + "' holds " + grid->valueType() + " values; expected float (or vec3s)");
            grids.push_back(grid);
        }
        file.close();
    } catch (const Error& e) {
        throw Error(where + "cannot read VDB: " + e.what());
    } catch (const std::exception& e) {
        throw Error(where + "cannot read VDB: " + e.what());
    }

    // 2. One shared, axis-aligned transform.
    const auto& xf = grids[0]->transform();
    for (const auto& g : grids)
        if (g->transform() != xf)
            throw Error(where + "grids '" + grids[0]->getName() + "' and '" + g->getName() +
                        "' have different transforms; read them separately (or resample one onto the other)");
    if (!axis_aligned(xf))
        throw Error(where + "grid '" + grids[0]->getName() +
                    "' has a rotated, flipped or non-linear transform; only axis-aligned grids with positive voxel sizes can become a field");

    // 3. The index box: the atlas metadata when it still matches the
    //    transform, else the union of the active bounding boxes.
    openvdb::CoordBBox bbox;
    Box3d bounds;
    const auto meta_min = grids[0]->getMetadata<openvdb::Vec3DMetadata>("atlas_bounds_min");
    const auto meta_max = grids[0]->getMetadata<openvdb::Vec3DMetadata>("atlas_bounds_max");
    const auto meta_res = grids[0]->getMetadata<openvdb::Vec3IMetadata>("atlas_resolution");
    bool from_meta = false;
    if (meta_min && meta_max && meta_res) {
        const auto r = meta_res->value();
        const Box3d b{{{meta_min->value().x(), meta_min->value().y(), meta_min->value().z()}},
                      {{meta_max->value().x(), meta_max->value().y(), meta_max->value().z()}}};
        if (meta_matches(xf, b, r)) {
            bbox = openvdb::CoordBBox(openvdb::Coord(0, 0, 0), openvdb::Coord(r.x() - 1, r.y() - 1, r.z() - 1));
            bounds = b;
            from_meta = true;
        }
    }
    if (!from_meta) {
        std::vector<std::string> names;
        for (const auto& g : grids) {
            bbox.expand(g->evalActiveVoxelBoundingBox());
            names.push_back("'" + g->getName() + "'");
        }
        if (bbox.empty()) throw Error(where + "grid " + list_names(names) + " has no active voxels (nothing to densify)");
        const openvdb::Vec3d lo = xf.indexToWorld(openvdb::Vec3d(bbox.min().x() - 0.5, bbox.min().y() - 0.5, bbox.min().z() - 0.5));
        const openvdb::Vec3d hi = xf.indexToWorld(openvdb::Vec3d(bbox.max().x() + 0.5, bbox.max().y() + 0.5, bbox.max().z() + 0.5));
        bounds = {{{lo.x(), lo.y(), lo.z()}}, {{hi.x(), hi.y(), hi.z()}}};
    }
    const openvdb::Coord dim = bbox.dim();

    // 4. Densify.
    std::vector<std::string> names;
    for (const auto& g : grids) {
        if (g->isType<openvdb::Vec3SGrid>()) {
            for (const char* s : {".x", ".y", ".z"}) names.push_back(g->getName() + s);
        } else {
            names.push_back(g->getName());
        }
    }
    if (names.size() > 64) throw Error(where + std::to_string(names.size()) + " channels; a field holds at most 64");
    try {
        Field3D f({{dim.x(), dim.y(), dim.z()}}, int(names.size()), bounds, names, &bud);
        int c = 0;
        for (const auto& g : grids) {
            if (auto fg = openvdb::gridPtrCast<openvdb::FloatGrid>(g)) {
                densify(*fg, bbox, f.channel(c).data());
                ++c;
            } else if (auto vg = openvdb::gridPtrCast<openvdb::Vec3SGrid>(g)) {
                auto acc = vg->getConstAccessor();
                for (int z = 0; z < dim.z(); ++z)
                    for (int y = 0; y < dim.y(); ++y)
                        for (int x = 0; x < dim.x(); ++x) {
                            const openvdb::Vec3s v = acc.getValue(bbox.min().offsetBy(x, y, z));
                            for (int k = 0; k < 3; ++k) f.at(c + k, x, y, z) = v[k];
                        }
                c += 3;
            }
        }
        return f;
    } catch (const MemoryBudgetError& e) {
        throw MemoryBudgetError(where + e.what());
    } catch (const Error& e) {
        throw Error(where + e.what());
    } catch (const std::exception& e) {
        throw Error(where + "cannot read VDB: " + e.what());
    }
}

} // namespace

Field3D read_vdb(const fs::path& path, const std::vector<std::string>& wanted, const MemoryBudget* budget) {
    init_openvdb();
    // OpenVDB throws its own exceptions (e.g. a nearly singular map from a
    // fuzzed file): every one of them leaves as an atlas::Error naming the file.
    try {
        return read_vdb_checked(path, wanted, budget);
    } catch (const Error&) {
        throw;
    } catch (const std::exception& e) {
        throw Error(path.string() + ": cannot read VDB: " + e.what());
    }
}

} // namespace atlas::io
