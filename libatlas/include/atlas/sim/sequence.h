// atlas/sim/sequence.h - the solver's frame sequence (sim/cloud_growth's
// 'sequence' output: channels 'NNNN:GRID', NNNN = 1, 2, ...) read one frame at
// a time, so a graph with a time range (a keyed frame) turns the frames into a
// sequence of NVDF sets.
//
// Pure, deterministic; errors are atlas::Error.
#pragma once

#include "atlas/core/field.h"
#include "atlas/core/memory.h"

#include <string>
#include <vector>

namespace atlas::sim {

// The channels of one grid in a frame: "vel" is vel.x, vel.y, vel.z; every other
// grid is one channel of its own name.
std::vector<std::string> sequence_grid_channels(const std::string& grid);

// A frame's channel name: frame 7's "density" is "0007:density".
std::string sequence_channel_name(int frame, const std::string& channel);

// The frame numbers the sequence holds for `grid` ("density", "temperature",
// "vapor", "vel": vel.x, vel.y, vel.z), ascending; empty when it holds none.
std::vector<int> sequence_frames(const Field3D& sequence, const std::string& grid);

// `grid` at `frame` (1 .. the last frame): a whole frame is its channels copied;
// between two frames (a fractional frame) each voxel is the linear crossfade of
// the two, a + u (b - a), so a sequence sampled at any rate moves without
// steps (it does not advect: a fast feature fades out in one place and in at the
// next). The frames must be numbered 1, 2, ... without gaps. Throws naming the
// grid and the frames held when the frame is out of range or the grid missing.
Field3D sequence_frame(const Field3D& sequence, const std::string& grid, double frame, const MemoryBudget* budget = nullptr);

} // namespace atlas::sim
