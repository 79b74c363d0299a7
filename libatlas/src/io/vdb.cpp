#include "atlas/io/vdb.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"

#include <openvdb/openvdb.h>
#include <openvdb/tools/Dense.h>

#include <cstdio>
#include <fstream>
#include <mutex>

namespace atlas::io {

namespace {

void init_openvdb() {
    static std::once_flag once; // openvdb::initialize() is idempotent; this just avoids repeated locking inside it
    std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::math::Transform::Ptr field_transform(const Field3D& f) {
    const Vec3d v = f.voxel_size();
    openvdb::math::Mat4d m;
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
// derived from the file's content so the same field gives the same bytes.
void make_uuid_deterministic(const fs::path& path) {
    std::fstream file(path, std::ios::in | std::ios::out | std::ios::binary);
    std::string bytes((std::istreambuf_iterator<char>(file)), std::istreambuf_iterator<char>());
    // Header: magic (8), file version (4), library version (4 + 4), offsets flag (1), UUID text (36).
    const size_t at = 21, len = 36;
    if (bytes.size() < at + len) return;
    const std::string uuid = bytes.substr(at, len);
    if (uuid[8] != '-' || uuid[13] != '-' || uuid[18] != '-' || uuid[23] != '-') return; // unknown layout: leave it
    std::string rest = bytes.substr(0, at) + bytes.substr(at + len);
    Hash128 h = Hasher().add(rest).finish();
    std::string hex = h.hex();
    std::string det = hex.substr(0, 8) + "-" + hex.substr(8, 4) + "-" + hex.substr(12, 4) + "-" + hex.substr(16, 4) + "-" + hex.substr(20, 12);
    file.clear();
    file.seekp(std::streamoff(at));
    file.write(det.data(), std::streamsize(len));
    if (!file) throw Error(path.string() + ": cannot finish VDB header");
}

} // namespace

void write_vdb(const Field3D& f, const fs::path& path, const VdbOptions& o) {
    init_openvdb();
    std::vector<std::string> names = o.grid_names.empty() ? f.channel_names() : o.grid_names;
    openvdb::GridPtrVec grids;
    const openvdb::CoordBBox bbox(openvdb::Coord(0, 0, 0), openvdb::Coord(f.nx() - 1, f.ny() - 1, f.nz() - 1));
    auto xf = field_transform(f);
    if (o.vector3) {
        if (f.channels() != 3) throw Error(path.string() + ": vector3 needs a 3-channel field, got " + std::to_string(f.channels()));
        auto g = openvdb::Vec3SGrid::create(openvdb::Vec3s(0.0f));
        auto acc = g->getAccessor();
        for (int z = 0; z < f.nz(); ++z)
            for (int y = 0; y < f.ny(); ++y)
                for (int x = 0; x < f.nx(); ++x) {
                    openvdb::Vec3s v(f.at(0, x, y, z), f.at(1, x, y, z), f.at(2, x, y, z));
                    if (std::fabs(v[0]) > o.tolerance || std::fabs(v[1]) > o.tolerance || std::fabs(v[2]) > o.tolerance)
                        acc.setValue(openvdb::Coord(x, y, z), v);
                }
        g->setName(o.grid_names.empty() ? std::string("vector") : o.grid_names[0]);
        g->setTransform(xf);
        g->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
        add_atlas_meta(*g, f);
        grids.push_back(g);
    } else {
        if (names.size() != size_t(f.channels()))
            throw Error(path.string() + ": " + std::to_string(names.size()) + " grid names for " + std::to_string(f.channels()) + " channels");
        for (int c = 0; c < f.channels(); ++c) {
            auto g = openvdb::FloatGrid::create(0.0f);
            // copyFromDense builds the tree in parallel; the result depends only on the values.
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
        openvdb::io::File file(path.string());
        file.write(grids);
        file.close();
    } catch (const std::exception& e) {
        throw Error(path.string() + ": cannot write VDB: " + e.what());
    }
    make_uuid_deterministic(path);
}

std::vector<std::string> list_vdb_grids(const fs::path& path) {
    init_openvdb();
    if (!fs::exists(path)) throw Error(path.string() + ": cannot open VDB file (no such file)");
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
    if (!fs::exists(path)) throw Error(path.string() + ": cannot open VDB file (no such file)");
    openvdb::GridPtrVecPtr all;
    try {
        openvdb::io::File file(path.string());
        file.open(false);
        all = file.getGrids();
        file.close();
    } catch (const std::exception& e) {
        throw Error(path.string() + ": cannot read VDB: " + e.what());
    }
    std::vector<openvdb::GridBase::Ptr> grids;
    std::string present;
    for (const auto& g : *all) present += (present.empty() ? "" : ", ") + g->getName() + " (" + g->valueType() + ")";
    if (wanted.empty()) {
        for (const auto& g : *all)
            if (g->isType<openvdb::FloatGrid>() || g->isType<openvdb::Vec3SGrid>()) grids.push_back(g);
        if (grids.empty()) throw Error(path.string() + ": no float or vec3s grid in the file (it has: " + present + ")");
    } else {
        for (const auto& name : wanted) {
            openvdb::GridBase::Ptr found;
            for (const auto& g : *all)
                if (g->getName() == name) found = g;
            if (!found) throw Error(path.string() + ": no grid named '" + name + "' (the file has: " + present + ")");
            if (!found->isType<openvdb::FloatGrid>() && !found->isType<openvdb::Vec3SGrid>())
                throw Error(path.string() + ": grid '" + name + "' holds " + found->valueType() + "; expected float or vec3s");
            grids.push_back(found);
        }
    }
    // One transform for all, axis-aligned (a scale and a translation).
    const auto& xf = grids[0]->transform();
    for (const auto& g : grids)
        if (g->transform() != xf) throw Error(path.string() + ": grids '" + grids[0]->getName() + "' and '" + g->getName() + "' have different transforms");
    if (!xf.isLinear()) throw Error(path.string() + ": grid '" + grids[0]->getName() + "' has a non-linear transform (frustum); resample it first");
    const openvdb::Vec3d vs = xf.voxelSize();
    const openvdb::Vec3d o0 = xf.indexToWorld(openvdb::Vec3d(0, 0, 0));
    const openvdb::Vec3d ox = xf.indexToWorld(openvdb::Vec3d(1, 0, 0)) - o0;
    if (std::fabs(ox.y()) > 1e-9 * vs.x() || std::fabs(ox.z()) > 1e-9 * vs.x())
        throw Error(path.string() + ": grid '" + grids[0]->getName() + "' is rotated; only axis-aligned grids are supported");

    // The index box: atlas metadata when present, else the union of active boxes.
    openvdb::CoordBBox bbox;
    Box3d bounds;
    const auto meta_min = grids[0]->getMetadata<openvdb::Vec3DMetadata>("atlas_bounds_min");
    const auto meta_max = grids[0]->getMetadata<openvdb::Vec3DMetadata>("atlas_bounds_max");
    const auto meta_res = grids[0]->getMetadata<openvdb::Vec3IMetadata>("atlas_resolution");
    if (meta_min && meta_max && meta_res) {
        const auto r = meta_res->value();
        bbox = openvdb::CoordBBox(openvdb::Coord(0, 0, 0), openvdb::Coord(r.x() - 1, r.y() - 1, r.z() - 1));
        bounds = {{{meta_min->value().x(), meta_min->value().y(), meta_min->value().z()}},
                  {{meta_max->value().x(), meta_max->value().y(), meta_max->value().z()}}};
    } else {
        for (const auto& g : grids) bbox.expand(g->evalActiveVoxelBoundingBox());
        if (bbox.empty()) throw Error(path.string() + ": grid '" + grids[0]->getName() + "' has no active voxels");
        const openvdb::Vec3d lo = xf.indexToWorld(openvdb::Vec3d(bbox.min().x() - 0.5, bbox.min().y() - 0.5, bbox.min().z() - 0.5));
        const openvdb::Vec3d hi = xf.indexToWorld(openvdb::Vec3d(bbox.max().x() + 0.5, bbox.max().y() + 0.5, bbox.max().z() + 0.5));
        bounds = {{{std::min(lo.x(), hi.x()), std::min(lo.y(), hi.y()), std::min(lo.z(), hi.z())}},
                  {{std::max(lo.x(), hi.x()), std::max(lo.y(), hi.y()), std::max(lo.z(), hi.z())}}};
    }
    const openvdb::Coord dim = bbox.dim();
    std::vector<std::string> names;
    for (const auto& g : grids) {
        if (g->isType<openvdb::Vec3SGrid>()) {
            for (const char* s : {".x", ".y", ".z"}) names.push_back(g->getName() + s);
        } else {
            names.push_back(g->getName());
        }
    }
    Field3D f({{dim.x(), dim.y(), dim.z()}}, int(names.size()), bounds, names, budget);
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
}

} // namespace atlas::io
