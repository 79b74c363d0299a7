// OpenVDB files: dense Field3D <-> sparse float / vec3s grids (see vdb.h).
#include "atlas/io/vdb.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"
#include "io_common.h"
#include "vdb_internal.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <mutex>

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
// OpenVDB trusts the lengths and offsets in a file: one truncated to 173 bytes
// took 43 s and 5 GB (later 12 GB) to fail. The header and grid descriptors
// are walked here first, every length and offset checked against the size.
void check_vdb_structure(const fs::path& path) {
    const std::string where = path.string() + ": not a readable VDB file: ";
    std::error_code ec;
    const uint64_t size = fs::file_size(path, ec);
    if (ec) throw Error(where + ec.message());
    std::ifstream in(path, std::ios::binary);
    uint64_t pos = 0;
    auto need = [&](uint64_t n, const char* what) {
        if (n > size - std::min(pos, size)) throw Error(where + std::string(what) + " at byte " + std::to_string(pos) + " runs past the end of the file (" + std::to_string(size) + " bytes)");
    };
    auto read = [&](void* dst, uint64_t n, const char* what) {
        need(n, what);
        in.read(static_cast<char*>(dst), std::streamsize(n));
        if (!in) throw Error(where + "read error at byte " + std::to_string(pos));
        pos += n;
    };
    auto u32 = [&](const char* what) {
        uint32_t v = 0;
        read(&v, 4, what);
        return v;
    };
    auto skip_string = [&](const char* what) {
        const uint32_t n = u32(what);
        need(n, what);
        in.seekg(std::streamoff(n), std::ios::cur);
        pos += n;
    };
    int64_t magic = 0;
    read(&magic, 8, "the header");
    if (magic != 0x56444220) throw Error(where + "no VDB magic number at the start");
    const uint32_t version = u32("the header");
    // Files older than 222 (OpenVDB before 3.0, 2014) have another header layout that
    // cannot be checked here, and OpenVDB trusts their lengths (a fuzzed version-0
    // header made it allocate 3.4 GB): refused by name.
    if (version < 222 || version > 255)
        throw Error(where + "file format version " + std::to_string(version) +
                    " is not supported (expected 222..224, written by OpenVDB 3 or later)");
    u32("the header"); // library major
    u32("the header"); // library minor
    char offsets = 0;
    read(&offsets, 1, "the header");
    char uuid[36];
    read(uuid, 36, "the header");
    const uint32_t metas = u32("the file metadata");
    for (uint32_t i = 0; i < metas; ++i) {
        skip_string("a metadata name");
        skip_string("a metadata type");
        skip_string("a metadata value");
    }
    if (!offsets) return; // no grid offsets to check
    const uint32_t grids = u32("the grid count");
    // A descriptor is at least 3 lengths and 3 offsets.
    need(uint64_t(grids) * 36, "the grid descriptors");
    for (uint32_t i = 0; i < grids; ++i) {
        skip_string("a grid name");
        skip_string("a grid type");
        skip_string("a grid's instance parent");
        int64_t offs[3];
        read(offs, sizeof offs, "a grid descriptor");
        for (int64_t o : offs)
            if (o < 0 || uint64_t(o) > size)
                throw Error(where + "grid " + std::to_string(i) + " claims data up to byte " + std::to_string(o) + ", the file has " +
                            std::to_string(size) + " bytes (truncated?)");
        if (offs[0] > offs[1] || offs[1] > offs[2]) throw Error(where + "grid " + std::to_string(i) + " has inconsistent offsets");
        const uint64_t next = uint64_t(offs[2]);
        // The grid's own metadata (OpenVDB allocates what an unknown type's
        // length field says): compression flags, then name/type/value triples.
        in.seekg(std::streamoff(offs[0]));
        pos = uint64_t(offs[0]);
        u32("a grid's compression flags");
        const uint32_t grid_metas = u32("a grid's metadata count");
        need(uint64_t(grid_metas) * 12, "a grid's metadata");
        for (uint32_t k = 0; k < grid_metas; ++k) {
            skip_string("a grid metadata name");
            skip_string("a grid metadata type");
            skip_string("a grid metadata value");
        }
        if (pos > uint64_t(offs[1])) throw Error(where + "grid " + std::to_string(i) + "'s metadata runs into its data");
        in.seekg(std::streamoff(next));
        pos = next;
    }
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

Field3D read_vdb(const fs::path& path, const std::vector<std::string>& wanted, const MemoryBudget* budget) {
    init_openvdb();
    detail::require_regular_file(path, "VDB");
    check_vdb_structure(path);
    const MemoryBudget fallback;
    const MemoryBudget& bud = detail::budget_or_default(budget, fallback);
    const std::string where = path.string() + ": ";
    openvdb::GridPtrVecPtr all;
    try {
        openvdb::io::File file(path.string());
        file.open(false);
        all = file.getGrids();
        file.close();
    } catch (const std::exception& e) {
        throw Error(where + "cannot read VDB: " + e.what());
    }
    if (!all || all->empty()) throw Error(where + "the VDB file holds no grids");
    std::vector<std::string> present;
    for (const auto& g : *all) present.push_back("'" + g->getName() + "' (" + g->valueType() + ")");

    // 1. Which grids.
    std::vector<openvdb::GridBase::Ptr> grids;
    if (wanted.empty()) {
        for (const auto& g : *all)
            if (g->isType<openvdb::FloatGrid>() || g->isType<openvdb::Vec3SGrid>()) grids.push_back(g);
        if (grids.empty()) throw Error(where + "no float or vec3s grid in the file (it has " + list_names(present) + ")");
    } else {
        for (size_t i = 0; i < wanted.size(); ++i) {
            for (size_t j = 0; j < i; ++j)
                if (wanted[i] == wanted[j]) throw Error(where + "grid '" + wanted[i] + "' is asked for twice");
            openvdb::GridBase::Ptr found;
            for (const auto& g : *all)
                if (!found && g->getName() == wanted[i]) found = g;
            if (!found) throw Error(where + "no grid named '" + wanted[i] + "' (the file has " + list_names(present) + ")");
            if (!found->isType<openvdb::FloatGrid>() && !found->isType<openvdb::Vec3SGrid>())
                throw Error(where + "grid '" + wanted[i] + "' holds " + found->valueType() + " values; expected float (or vec3s)");
            grids.push_back(found);
        }
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
                openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(bbox, f.channel(c).data());
                openvdb::tools::copyToDense(*fg, dense);
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

} // namespace atlas::io
