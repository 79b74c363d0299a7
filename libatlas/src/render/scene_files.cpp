#include "atlas/render/scene.h"

#include "atlas/core/error.h"
#include "atlas/io/readers.h"

#include <cmath>

namespace atlas::render {

namespace {

Field3DPtr rebound(Field3DPtr f, double voxel) {
    if (voxel <= 0) return f;
    Box3d b{{{0, 0, 0}}, {{f->nx() * voxel, f->ny() * voxel, f->nz() * voxel}}};
    Field3D re(f->resolution(), f->channels(), b, f->channel_names());
    for (int c = 0; c < f->channels(); ++c) std::copy(f->channel(c).begin(), f->channel(c).end(), re.channel(c).begin());
    return std::make_shared<Field3D>(std::move(re));
}

} // namespace

CloudScene load_scene(const std::vector<std::filesystem::path>& files, double voxel_size) {
    if (!(voxel_size >= 0) || !std::isfinite(voxel_size)) throw Error("render: voxel size must be finite and >= 0 metres");
    if (files.empty() || files.size() > 2) throw Error("render: expected one NVDF set file, or a modeling file and an SDF file");
    auto read = [&](const std::filesystem::path& p) { return rebound(io::as_field3d(io::read_field_file(p)), voxel_size); };
    Field3DPtr first = read(files[0]);
    if (files.size() == 1) {
        try {
            return scene_from_nvdf_set(first);
        } catch (const Error& e) {
            throw Error(files[0].string() + ": " + e.what());
        }
    }
    Field3DPtr second = read(files[1]);
    if (first->channels() < 3) throw Error(files[0].string() + ": the modeling NVDF needs 3 channels, got " + std::to_string(first->channels()));
    CloudScene s;
    s.modeling = first;
    int c = second->find_channel("sdf");
    auto sdf = std::make_shared<Field3D>(second->resolution(), 1, second->bounds(), std::vector<std::string>{"sdf"});
    if (c >= 0) {
        std::copy(second->channel(c).begin(), second->channel(c).end(), sdf->channel(0).begin());
    } else {
        // Encoded field data: the Nubis pack range [-256, 4096] m.
        c = second->find_channel("field_data");
        if (c < 0) c = 0;
        auto src = second->channel(c);
        auto dst = sdf->channel(0);
        for (size_t i = 0; i < src.size(); ++i) dst[i] = static_cast<float>(double(src[i]) * 4352.0 - 256.0);
    }
    s.sdf = sdf;
    try {
        validate_scene(s);
    } catch (const Error& e) {
        throw Error(files[0].string() + ", " + files[1].string() + ": " + e.what());
    }
    return s;
}

} // namespace atlas::render
