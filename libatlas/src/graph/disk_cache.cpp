// The on-disk cache of node results and encoded outputs (disk_cache.h; the cook's
// side of it is declared in value_cache.h).
#include "atlas/graph/disk_cache.h"
#include "value_cache.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>

namespace atlas {

namespace disk_cache {

namespace {
// Version 2: the body is followed by its Hash128 checksum (16 bytes), so a
// flipped bit is a detected miss instead of a silently different output.
constexpr char kMagic[] = "ATLASCACHE\x02";
constexpr size_t kChecksumSize = 16;
constexpr size_t kMagicSize = sizeof(kMagic) - 1;
// Values are stored with fixed-width little-endian integers and raw floats;
// Atlas only targets little-endian machines (x86-64, arm64).

// Both sides stream: a cached NVDF set is hundreds of MB, and a whole-file
// string in between would double the memory and the page faults.
struct Writer {
    std::ostream* out; // null: checksum only (content_hash)
    ContentHasher sum{};
    void bytes(const void* p, size_t n) {
        sum.add(p, n);
        if (out) out->write(static_cast<const char*>(p), std::streamsize(n));
    }
    void checksum() {
        const Hash128 h = sum.finish();
        out->write(reinterpret_cast<const char*>(&h.hi), 8);
        out->write(reinterpret_cast<const char*>(&h.lo), 8);
    }
    // Binds the entry to its key: the key enters the checksum (not the file),
    // so an entry copied or forged under another key's name fails its check.
    void bind(const Hash128* key) {
        if (key) sum.add(key, sizeof *key);
    }
    void u64(uint64_t v) { bytes(&v, 8); }
    void f64(double v) { bytes(&v, 8); }
    void str(const std::string& s) { u64(s.size()); bytes(s.data(), s.size()); }
    void raw(const void* p, size_t n) { u64(n); bytes(p, n); }
};

struct Reader {
    std::istream& in;
    uint64_t size; // bytes in the entry: every length is checked against what is left
    uint64_t pos = 0;
    bool ok = true;
    ContentHasher sum{};
    void bind(const Hash128* key) {
        if (key) sum.add(key, sizeof *key);
    }
    bool take(void* dst, size_t n) {
        if (!ok || size - pos < n) return ok = false;
        in.read(static_cast<char*>(dst), std::streamsize(n));
        if (uint64_t(in.gcount()) != n) return ok = false;
        sum.add(dst, n);
        pos += n;
        return true;
    }
    // After the body: the stored checksum must match what was read.
    bool checksum_matches() {
        uint64_t stored[2] = {0, 0};
        in.read(reinterpret_cast<char*>(stored), 16);
        if (in.gcount() != 16) return false;
        const Hash128 h = sum.finish();
        return stored[0] == h.hi && stored[1] == h.lo;
    }
    uint64_t u64() { uint64_t v = 0; take(&v, 8); return v; }
    double f64() { double v = 0; take(&v, 8); return v; }
    std::string str() {
        uint64_t n = u64();
        if (!ok || n > size - pos) { ok = false; return {}; }
        std::string s(n, '\0');
        take(s.data(), n);
        return s;
    }
    template <typename T>
    void vec(std::vector<T>& v) {
        uint64_t n = u64();
        if (!ok || n % sizeof(T) != 0 || n > size - pos) { ok = false; return; }
        v.resize(n / sizeof(T));
        take(v.data(), n);
    }
};

void write_storage(Writer& w, const detail::FieldStorage& f) {
    w.u64(uint64_t(f.channels()));
    for (int c = 0; c < f.channels(); ++c) {
        w.str(f.channel_name(c));
        w.raw(f.channel(c).data(), f.channel(c).size_bytes());
    }
}

// Channel data goes straight from the file's bytes into the field (a cached
// NVDF set is hundreds of MB; no intermediate copy).
bool read_storage(Reader& r, detail::FieldStorage& f, int channels) {
    std::vector<std::string> names;
    for (int c = 0; c < channels && r.ok; ++c) {
        names.push_back(r.str());
        const uint64_t n = r.u64();
        if (!r.ok || n != f.channel(c).size_bytes() || !r.take(f.channel(c).data(), n)) return false;
    }
    if (!r.ok) return false;
    f.set_channel_names(names);
    return true;
}

void write_value(Writer& w, const Value& v);

void serialize_to(std::ostream& out, const NodeOutputs& outputs, const Hash128* key = nullptr) {
    Writer w{&out};
    w.bind(key);
    w.bytes(kMagic, kMagicSize);
    w.u64(outputs.size());
    for (const auto& [port, v] : outputs) {
        w.str(port);
        write_value(w, v);
    }
    w.checksum();
}

void write_value(Writer& w, const Value& v) {
    {
        w.u64(v.index());
        if (auto f = std::get_if<Field2DPtr>(&v)) {
            w.u64(uint64_t((*f)->width())); w.u64(uint64_t((*f)->height()));
            for (int i = 0; i < 2; ++i) { w.f64((*f)->bounds().min[i]); w.f64((*f)->bounds().max[i]); }
            write_storage(w, **f);
        } else if (auto f3 = std::get_if<Field3DPtr>(&v)) {
            for (int i = 0; i < 3; ++i) w.u64(uint64_t((*f3)->resolution()[i]));
            for (int i = 0; i < 3; ++i) { w.f64((*f3)->bounds().min[i]); w.f64((*f3)->bounds().max[i]); }
            write_storage(w, **f3);
        } else if (auto m = std::get_if<MeshPtr>(&v)) {
            w.raw((*m)->vertices.data(), (*m)->vertices.size() * sizeof(Vec3f));
            w.raw((*m)->triangles.data(), (*m)->triangles.size() * sizeof((*m)->triangles[0]));
        } else if (auto p = std::get_if<PointsPtr>(&v)) {
            w.raw((*p)->positions.data(), (*p)->positions.size() * sizeof(Vec3f));
            w.u64((*p)->attributes.size());
            for (const auto& [name, vals] : (*p)->attributes) { w.str(name); w.raw(vals.data(), vals.size() * sizeof(float)); }
        }
    }
}

// With `key`, the entry must have been stored under it (Writer::bind).
std::optional<NodeOutputs> deserialize_from(std::istream& in, uint64_t size, std::string* why_not, const Hash128* key = nullptr) {
    auto fail = [&](const char* why) -> std::optional<NodeOutputs> {
        if (why_not) *why_not = why;
        return std::nullopt;
    };
    if (size < kMagicSize + kChecksumSize) return fail("truncated");
    Reader r{in, size - kChecksumSize};
    r.bind(key);
    char magic[kMagicSize];
    if (!r.take(magic, kMagicSize) || std::memcmp(magic, kMagic, kMagicSize) != 0) return fail("not an Atlas cache file of this version");
    NodeOutputs out;
    uint64_t n = r.u64();
    if (n > 1024) return fail("corrupt header");
    try {
        for (uint64_t i = 0; i < n && r.ok; ++i) {
            std::string port = r.str();
            uint64_t kind = r.u64();
            if (kind == 1) {
                // Dimensions are checked as read: each in 1..2^30, and the data they
                // imply no larger than the entry (no absurd allocation from a damaged header).
                const uint64_t w = r.u64(), h = r.u64();
                if (!r.ok || w == 0 || h == 0 || w > (1u << 30) || h > (1u << 30) || w * h > size) return fail("corrupt field");
                Vec2i res{{int(w), int(h)}};
                Box2d b;
                for (int k = 0; k < 2; ++k) { b.min[k] = r.f64(); b.max[k] = r.f64(); }
                uint64_t ch = r.u64();
                if (!r.ok || ch == 0 || ch > 64 || uint64_t(res[0]) * uint64_t(res[1]) * ch * 4 > size) return fail("corrupt field");
                auto f = std::make_shared<Field2D>(res, int(ch), b);
                if (!read_storage(r, *f, int(ch))) return fail("truncated field");
                out[port] = Field2DPtr(f);
            } else if (kind == 2) {
                const uint64_t nx = r.u64(), ny = r.u64(), nz = r.u64();
                if (!r.ok || nx == 0 || ny == 0 || nz == 0 || nx > (1u << 30) || ny > (1u << 30) || nz > (1u << 30) || nx * ny > size ||
                    nz > size / (nx * ny))
                    return fail("corrupt field");
                Vec3i res{{int(nx), int(ny), int(nz)}};
                Box3d b;
                for (int k = 0; k < 3; ++k) { b.min[k] = r.f64(); b.max[k] = r.f64(); }
                uint64_t ch = r.u64();
                if (!r.ok || ch == 0 || ch > 64 || uint64_t(res[0]) * uint64_t(res[1]) * uint64_t(res[2]) * ch * 4 > size)
                    return fail("corrupt field");
                auto f = std::make_shared<Field3D>(res, int(ch), b);
                if (!read_storage(r, *f, int(ch))) return fail("truncated field");
                out[port] = Field3DPtr(f);
            } else if (kind == 3) {
                auto m = std::make_shared<Mesh>();
                r.vec(m->vertices);
                r.vec(m->triangles);
                out[port] = MeshPtr(m);
            } else if (kind == 4) {
                auto p = std::make_shared<Points>();
                r.vec(p->positions);
                uint64_t na = r.u64();
                if (na > 4096) return fail("corrupt points");
                for (uint64_t a = 0; a < na && r.ok; ++a) {
                    std::string name = r.str();
                    r.vec(p->attributes[name]);
                }
                out[port] = PointsPtr(p);
            } else {
                return fail("unknown value kind");
            }
        }
    } catch (const std::exception&) { // atlas::Error from a field's checks, or a refused allocation
        return fail("corrupt value");
    }
    if (!r.ok) return fail("truncated");
    if (r.pos != r.size) return fail("trailing bytes");
    if (!r.checksum_matches())
        return fail(key ? "checksum mismatch (the entry is corrupt, or was stored under another key: swapped or forged)" : "checksum mismatch (the entry is corrupt)");
    return out;
}
} // namespace

Hash128 content_hash(const Value& v) {
    Writer w{nullptr};
    write_value(w, v);
    return w.sum.finish();
}

std::string serialize(const NodeOutputs& outputs) {
    std::ostringstream out;
    serialize_to(out, outputs);
    return std::move(out).str();
}

std::optional<NodeOutputs> deserialize(const std::string& bytes, std::string* why_not) {
    std::istringstream in(bytes);
    return deserialize_from(in, bytes.size(), why_not);
}

std::filesystem::path entry_path(const std::filesystem::path& dir, const Hash128& h) { return dir / (h.hex() + ".atlascache"); }

bool contains(const std::filesystem::path& dir, const Hash128& h) {
    std::error_code ec;
    return std::filesystem::is_regular_file(entry_path(dir, h), ec);
}

std::optional<NodeOutputs> load(const std::filesystem::path& dir, const Hash128& h, std::string* why_not) {
    const std::filesystem::path path = entry_path(dir, h);
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    std::ifstream in(path, std::ios::binary);
    if (ec || !in) {
        if (why_not) *why_not = path.string() + ": cannot open cache entry";
        return std::nullopt;
    }
    auto v = deserialize_from(in, size, why_not, &h);
    if (v) touch(path);
    return v;
}

void touch(const std::filesystem::path& entry) {
    std::error_code ec;
    std::filesystem::last_write_time(entry, std::filesystem::file_time_type::clock::now(), ec);
}

void store(const std::filesystem::path& dir, const Hash128& h, const NodeOutputs& outputs) {
    write_file_atomic(entry_path(dir, h), [&](const std::filesystem::path& tmp) {
        std::ofstream f(tmp, std::ios::binary);
        serialize_to(f, outputs, &h);
        f.close();
        if (!f) throw Error(tmp.string() + ": cannot write cache entry (disk full?)");
    });
}

// ------------------------------------------------------------ output files

namespace {
constexpr char kFilesMagic[] = "ATLASFILES\x01";
constexpr size_t kFilesMagicSize = sizeof(kFilesMagic) - 1;
} // namespace

std::filesystem::path files_entry_path(const std::filesystem::path& dir, const Hash128& key) { return dir / (key.hex() + ".atlasout"); }

void store_files(const std::filesystem::path& dir, const Hash128& key,
                 const std::vector<std::pair<std::string, std::filesystem::path>>& files, const std::map<std::string, double>& metrics) {
    write_file_atomic(files_entry_path(dir, key), [&](const std::filesystem::path& tmp) {
        std::ofstream f(tmp, std::ios::binary);
        Writer w{&f};
        w.bind(&key);
        w.bytes(kFilesMagic, kFilesMagicSize);
        w.u64(metrics.size());
        for (const auto& [k, v] : metrics) { w.str(k); w.f64(v); }
        w.u64(files.size());
        for (const auto& [name, path] : files) {
            w.str(name);
            w.str(read_file_bytes(path));
        }
        w.checksum();
        f.close();
        if (!f) throw Error(tmp.string() + ": cannot write cache entry (disk full?)");
    });
}

std::optional<CachedFiles> load_files(const std::filesystem::path& dir, const Hash128& key, std::string* why_not) {
    const std::filesystem::path path = files_entry_path(dir, key);
    std::error_code ec;
    const uint64_t size = std::filesystem::file_size(path, ec);
    std::ifstream in(path, std::ios::binary);
    auto fail = [&](const std::string& why) -> std::optional<CachedFiles> {
        if (why_not) *why_not = why;
        return std::nullopt;
    };
    if (ec || !in) return fail("cannot open cache entry");
    if (size < kFilesMagicSize + kChecksumSize) return fail("truncated");
    Reader r{in, size - kChecksumSize};
    r.bind(&key);
    char magic[kFilesMagicSize];
    if (!r.take(magic, kFilesMagicSize) || std::memcmp(magic, kFilesMagic, kFilesMagicSize) != 0) return fail("not an Atlas output cache entry");
    CachedFiles out;
    const uint64_t nm = r.u64();
    if (nm > 4096) return fail("corrupt header");
    for (uint64_t i = 0; i < nm && r.ok; ++i) {
        std::string k = r.str();
        out.metrics[k] = r.f64();
    }
    const uint64_t nf = r.u64();
    if (nf > 100000) return fail("corrupt header");
    for (uint64_t i = 0; i < nf && r.ok; ++i) {
        std::string name = r.str();
        out.files.emplace_back(name, r.str());
    }
    if (!r.ok) return fail("truncated");
    if (r.pos != r.size) return fail("trailing bytes");
    if (!r.checksum_matches()) return fail("checksum mismatch (the entry is corrupt, or was stored under another key: swapped or forged)");
    // Names come from the file: only plain relative paths inside the output,
    // none of Atlas's own names (the commit refuses a symlinked folder).
    for (const auto& [name, bytes] : out.files) {
        const std::filesystem::path p(name);
        if (p.empty() || p.is_absolute() || p.lexically_normal().begin()->string() == "..") return fail("corrupt file name");
        try {
            check_output_name(name);
        } catch (const Error&) {
            return fail("corrupt file name");
        }
    }
    touch(path);
    return out;
}

// ------------------------------------------------------------ pruning

PruneResult prune(const std::filesystem::path& dir, uint64_t max_bytes) {
    namespace fs = std::filesystem;
    PruneResult res;
    res.stale_staging_bytes = remove_stale_staging(dir);
    struct Entry {
        fs::file_time_type time;
        uint64_t bytes;
        fs::path path;
    };
    std::vector<Entry> entries;
    std::error_code ec;
    for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
        const std::string ext = it->path().extension().string();
        if (ext != ".atlascache" && ext != ".atlasout") continue;
        std::error_code e2;
        if (!it->is_regular_file(e2)) continue;
        Entry e{it->last_write_time(e2), it->file_size(e2), it->path()};
        if (e2) continue;
        entries.push_back(e);
        res.bytes_before += e.bytes;
    }
    // Least recently used first (loads refresh an entry's time); ties by name, for a fixed order.
    std::sort(entries.begin(), entries.end(), [](const Entry& a, const Entry& b) { return a.time != b.time ? a.time < b.time : a.path < b.path; });
    uint64_t total = res.bytes_before;
    for (const auto& e : entries) {
        if (total <= max_bytes) break;
        std::error_code e2;
        if (fs::remove(e.path, e2)) {
            total -= e.bytes;
            res.removed_files += 1;
            res.removed_bytes += e.bytes;
        }
    }
    res.bytes_after = total;
    return res;
}

} // namespace disk_cache

} // namespace atlas
