#include "value_cache.h"

#include "atlas/core/error.h"
#include "atlas/core/files.h"

#include <cstring>
#include <fstream>
#include <sstream>

namespace atlas {

std::shared_ptr<const NodeOutputs> ValueCache::find(const Hash128& h) const {
    auto it = entries_.find(h);
    return it == entries_.end() ? nullptr : it->second;
}

void ValueCache::put(const Hash128& h, std::shared_ptr<const NodeOutputs> v) { entries_[h] = std::move(v); }

void ValueCache::retain_only(const std::unordered_set<Hash128, Hash128Hasher>& keep) {
    for (auto it = entries_.begin(); it != entries_.end();) {
        if (keep.count(it->first)) ++it;
        else it = entries_.erase(it);
    }
}

namespace disk_cache {

namespace {
constexpr char kMagic[] = "ATLASCACHE\x01";
constexpr size_t kMagicSize = sizeof(kMagic) - 1;
// Values are stored with fixed-width little-endian integers and raw floats;
// Atlas only targets little-endian machines (x86-64, arm64).

// Both sides stream: a cached NVDF set is hundreds of MB, and a whole-file
// string in between would double the memory and the page faults.
struct Writer {
    std::ostream& out;
    void bytes(const void* p, size_t n) { out.write(static_cast<const char*>(p), std::streamsize(n)); }
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
    bool take(void* dst, size_t n) {
        if (!ok || size - pos < n) return ok = false;
        in.read(static_cast<char*>(dst), std::streamsize(n));
        if (uint64_t(in.gcount()) != n) return ok = false;
        pos += n;
        return true;
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

void serialize_to(std::ostream& out, const NodeOutputs& outputs) {
    Writer w{out};
    w.bytes(kMagic, kMagicSize);
    w.u64(outputs.size());
    for (const auto& [port, v] : outputs) {
        w.str(port);
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

std::optional<NodeOutputs> deserialize_from(std::istream& in, uint64_t size, std::string* why_not) {
    auto fail = [&](const char* why) -> std::optional<NodeOutputs> {
        if (why_not) *why_not = why;
        return std::nullopt;
    };
    Reader r{in, size};
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
                Vec2i res{{int(r.u64()), int(r.u64())}};
                Box2d b;
                for (int k = 0; k < 2; ++k) { b.min[k] = r.f64(); b.max[k] = r.f64(); }
                uint64_t ch = r.u64();
                if (!r.ok || ch == 0 || ch > 64 || uint64_t(res[0]) * uint64_t(res[1]) * ch * 4 > size) return fail("corrupt field");
                auto f = std::make_shared<Field2D>(res, int(ch), b);
                if (!read_storage(r, *f, int(ch))) return fail("truncated field");
                out[port] = Field2DPtr(f);
            } else if (kind == 2) {
                Vec3i res{{int(r.u64()), int(r.u64()), int(r.u64())}};
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
    } catch (const Error&) {
        return fail("corrupt value");
    }
    if (!r.ok) return fail("truncated");
    if (r.pos != size) return fail("trailing bytes");
    return out;
}
} // namespace

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
    return deserialize_from(in, size, why_not);
}

void store(const std::filesystem::path& dir, const Hash128& h, const NodeOutputs& outputs) {
    write_file_atomic(entry_path(dir, h), [&](const std::filesystem::path& tmp) {
        std::ofstream f(tmp, std::ios::binary);
        serialize_to(f, outputs);
        f.close();
        if (!f) throw Error(tmp.string() + ": cannot write cache entry (disk full?)");
    });
}

} // namespace disk_cache
} // namespace atlas
