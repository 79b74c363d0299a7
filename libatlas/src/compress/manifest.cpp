// The OUT.dds.json sidecar manifest.
#include "atlas/compress/texture.h"

#include <nlohmann/json.hpp>

#include <cmath>

namespace atlas::compress {

std::string TextureManifest::to_json() const {
    nlohmann::ordered_json j;
    j["atlas_texture"] = 1;
    j["encoding"] = encoding;
    j["dxgi_format"] = dxgi_format;
    j["width"] = width;
    j["height"] = height;
    j["depth"] = depth;
    j["array_size"] = array_size;
    j["mip_levels"] = mip_levels;
    j["volume"] = volume;
    j["channels"] = channel_meanings;
    j["mapping"] = mapping;
    j["value_range"] = {range_lo, range_hi};
    if (max_error) j["max_error"] = *max_error;
    else j["max_error"] = nullptr;
    if (requested_max_error) j["requested_max_error"] = *requested_max_error;
    if (!type_encoding.empty()) j["type_encoding"] = type_encoding;
    j["one_sided"] = one_sided_below ? "below" : "none";
    j["decoders"] = decoders;
    j["mip_filter"] = mip_filter;
    if (world_bounds)
        j["world_bounds"] = {{"min", {world_bounds->min[0], world_bounds->min[1], world_bounds->min[2]}},
                             {"max", {world_bounds->max[0], world_bounds->max[1], world_bounds->max[2]}}};
    if (encoding == "bc1-scalar") j["unpack_weights"] = {unpack_weights[0], unpack_weights[1], unpack_weights[2]};
    return j.dump(2) + "\n";
}

TextureManifest TextureManifest::from_json(const std::string& text, const std::string& what) {
    TextureManifest m;
    try {
        const auto j = nlohmann::json::parse(text);
        m.encoding = j.at("encoding").get<std::string>();
        m.dxgi_format = j.at("dxgi_format").get<std::string>();
        m.width = j.at("width").get<int>();
        m.height = j.at("height").get<int>();
        m.depth = j.value("depth", 1);
        m.array_size = j.value("array_size", 1);
        m.mip_levels = j.value("mip_levels", 1);
        m.volume = j.value("volume", false);
        m.channel_meanings = j.value("channels", std::vector<std::string>{});
        m.mapping = j.at("mapping").get<std::string>();
        m.range_lo = j.at("value_range").at(0).get<float>();
        m.range_hi = j.at("value_range").at(1).get<float>();
        if (j.contains("max_error") && !j["max_error"].is_null()) m.max_error = j["max_error"].get<float>();
        if (j.contains("requested_max_error") && !j["requested_max_error"].is_null())
            m.requested_max_error = j["requested_max_error"].get<float>();
        m.type_encoding = j.value("type_encoding", std::string());
        m.one_sided_below = j.value("one_sided", std::string("none")) == "below";
        m.decoders = j.value("decoders", std::vector<std::string>{});
        m.mip_filter = j.value("mip_filter", std::string("box"));
        if (j.contains("world_bounds")) {
            Box3d b;
            for (size_t i = 0; i < 3; ++i) {
                b.min[i] = j["world_bounds"].at("min").at(i).get<double>();
                b.max[i] = j["world_bounds"].at("max").at(i).get<double>();
                if (!(b.max[i] > b.min[i]) || !std::isfinite(b.min[i]) || !std::isfinite(b.max[i]))
                    throw Error(what + ": invalid texture manifest: world_bounds axis " + std::to_string(i) + " must be finite with min < max");
            }
            m.world_bounds = b;
        }
        if (j.contains("unpack_weights"))
            for (int i = 0; i < 3; ++i) m.unpack_weights[size_t(i)] = j["unpack_weights"].at(size_t(i)).get<float>();
    } catch (const nlohmann::json::exception& e) {
        throw Error(what + ": invalid texture manifest: " + e.what());
    }
    return m;
}

} // namespace atlas::compress
