// atlas/io/dds_file.h - DDS files: the compress module's textures (atlas/compress/texture.h,
// atlas/compress/dds.h, all in memory) written to and read from disk, with the JSON
// manifest OUT.dds.json that carries the value mapping beside each file.
// Thread-safety: pure functions over values and files; writes are atomic (a staged
// temporary renamed into place, so a failed write leaves no partial file).
#pragma once

#include "atlas/compress/dds.h"
#include "atlas/compress/texture.h"
#include "atlas/core/field.h"
#include "atlas/core/progress.h"

#include <filesystem>
#include <optional>
#include <vector>

namespace atlas::io {

// Serialises with compress::encode_dds and writes atomically / reads and parses a DDS
// file. Throws atlas::Error naming the file on I/O errors and bad contents.
void write_dds_file(const std::filesystem::path& path, const compress::DdsTexture& tex);
compress::DdsTexture read_dds_file(const std::filesystem::path& path);

// The manifest beside a DDS file (DDS path + ".json"), or nullopt when there is none.
std::optional<compress::TextureManifest> read_dds_manifest(const std::filesystem::path& dds);

// Encodes a field (compress::encode_texture) and writes OUT.dds and OUT.dds.json; both
// appear atomically or not at all. Throws what encode_texture throws, and
// compress::BoundError (nothing written) when blocks miss the bound and
// options.allow_over_bound is off. A Field2D is encoded as a 1-slice field.
compress::CompressReport compress_to_dds(const Field3D& field, const std::filesystem::path& out,
                                         const compress::CompressOptions& options, const ProgressSink* progress = nullptr);
compress::CompressReport compress_to_dds(const Field2D& field, const std::filesystem::path& out,
                                         const compress::CompressOptions& options, const ProgressSink* progress = nullptr);

// compress::decode_texture of a file, with its manifest when there is one.
Field3D read_dds(const std::filesystem::path& dds, compress::Decoder decoder = compress::Decoder::Reference);

// compress::verify_texture of a file against `source`, with its manifest when there is one.
compress::CompressReport verify_dds(const std::filesystem::path& dds, const Field3D& source,
                                    compress::DecoderSet decoders = compress::kAllDecoders, const std::vector<int>& channels = {});

} // namespace atlas::io
