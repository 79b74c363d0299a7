#include "atlas/sim/sequence.h"

#include "atlas/core/error.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

namespace atlas::sim {
std::vector<std::string> sequence_grid_channels(const std::string& grid) {
    if (grid == "vel") return {"vel.x", "vel.y", "vel.z"};
    return {grid};
}

std::string sequence_channel_name(int frame, const std::string& channel) {
    char prefix[16];
    std::snprintf(prefix, sizeof prefix, "%04d:", frame);
    return prefix + channel;
}

std::vector<int> sequence_frames(const Field3D& sequence, const std::string& grid) {
    const std::string first = sequence_grid_channels(grid).front();
    std::vector<int> frames;
    for (const std::string& name : sequence.channel_names()) {
        const size_t colon = name.find(':');
        if (colon == std::string::npos || name.compare(colon + 1, std::string::npos, first) != 0) continue;
        char* end = nullptr;
        const long f = std::strtol(name.c_str(), &end, 10);
        if (end == name.c_str() + colon && f > 0 && f < 1000000) frames.push_back(int(f));
    }
    std::sort(frames.begin(), frames.end());
    return frames;
}

Field3D sequence_frame(const Field3D& sequence, const std::string& grid, double frame, const MemoryBudget* budget) {
    if (grid != "density" && grid != "temperature" && grid != "vapor" && grid != "vel")
        throw Error("sequence: grid must be density, temperature, vapor or vel, got '" + grid + "'");
    const std::vector<int> frames = sequence_frames(sequence, grid);
    if (frames.empty()) throw Error("sequence: no frames of '" + grid + "' (channels named 'NNNN:" + grid + "', as sim/cloud_growth's 'sequence' writes them)");
    const int last = int(frames.size());
    for (int i = 0; i < last; ++i)
        if (frames[size_t(i)] != i + 1)
            throw Error("sequence: the frames of '" + grid + "' must be numbered 1, 2, ... without gaps; frame " + std::to_string(i + 1) +
                        " is missing");
    if (!(std::isfinite(frame) && frame >= 1 && frame <= last))
        throw Error("sequence: frame " + std::to_string(frame) + " is outside the " + std::to_string(last) + " frames of '" + grid + "' (1 .. " +
                    std::to_string(last) + ")");
    const int f0 = int(std::floor(frame)), f1 = std::min(last, f0 + 1);
    const float u = float(frame - f0);
    const std::vector<std::string> channels = sequence_grid_channels(grid);
    Field3D out(sequence.resolution(), int(channels.size()), sequence.bounds(), channels, budget);
    for (size_t c = 0; c < channels.size(); ++c) {
        const int a = sequence.find_channel(sequence_channel_name(f0, channels[c])), b = sequence.find_channel(sequence_channel_name(f1, channels[c]));
        if (a < 0 || b < 0) throw Error("sequence: frame " + std::to_string(a < 0 ? f0 : f1) + " has no channel '" + channels[c] + "'");
        const auto va = sequence.channel(a), vb = sequence.channel(b);
        auto o = out.channel(int(c));
        if (u == 0.0f) {
            std::copy(va.begin(), va.end(), o.begin());
            continue;
        }
        for (size_t i = 0; i < o.size(); ++i) o[i] = va[i] + (vb[i] - va[i]) * u;
    }
    return out;
}

} // namespace atlas::sim
