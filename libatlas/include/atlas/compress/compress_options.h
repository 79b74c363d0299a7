// atlas/compress/compress_options.h - the one schema of the compress options that
// `atlas compress` takes as flags and a graph's `dds` output takes as options
// (atlas/core/option_schema.h): both front ends, their help, docs/options.md and
// the validation are built from it, so they accept exactly the same values.
#pragma once

#include "atlas/compress/texture.h"
#include "atlas/core/field.h"
#include "atlas/core/option_schema.h"

#include <span>

namespace atlas::compress {

// In help order: encoding (--format), quality, max_error, one_sided,
// allow_over_bound, decoders, mips, range, channels (names, into
// CompressOptions::channel_names), array. Thread-safe (a static table).
std::span<const TextOption<CompressOptions>> compress_options();

// The format a dds graph output writes without an 'encoding' option (the CLI
// requires --format).
constexpr Format kDdsOutputDefaultFormat = Format::Rgba16F;

// Fills options.channels from options.channel_names (their indices in `field`);
// throws atlas::Error "'channels': the field has no channel 'x' (it has: a, b)".
void resolve_channel_names(CompressOptions& options, const Field3D& field);

} // namespace atlas::compress
