// Internal: what earlier cooks wrote into an output directory, so that an
// output whose content and options are unchanged, and whose files on disk
// still match, is neither encoded nor written again (its mtime stays).
//
// One small JSON file per output root, ROOT/.atlas-outputs.json, maps each
// output (its path as the graph names it) to its key (a hash of the source
// node's content hash, port, format, options and path) and the files it
// wrote: size, mtime and content hash. A file matches when its size and
// mtime are the recorded ones, or, when the mtime moved (a copy, a touch),
// when its content hash is. The record file is only a hint: a missing or
// corrupt one means "write everything", never an error.
#pragma once

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

namespace atlas {

struct OutputFileRecord {
    std::string path; // relative to the root, generic form
    uint64_t bytes = 0;
    int64_t mtime_ns = 0; // last write time, nanoseconds since the Unix epoch
    std::string hash; // file_content_hash, hex
};

struct OutputRecord {
    std::string key;
    std::string spec;       // hash of format, options, path (the key without the source)
    std::string value_hash; // content hash of the value written (hash_value)
    std::vector<OutputFileRecord> files;
    std::map<std::string, double> metrics; // the writer's, reported again when not rewritten
};

class OutputRecords {
public:
    static constexpr const char* kFileName = ".atlas-outputs.json";
    explicit OutputRecords(std::filesystem::path root);

    // The record of output `name` when its key is `key` and every file it
    // wrote is still on disk unchanged; null otherwise.
    const OutputRecord* current(const std::string& name, const std::string& key);
    // The record of output `name` when every file it wrote is still on disk
    // unchanged, whatever its key; null otherwise.
    const OutputRecord* on_disk(const std::string& name);
    void set(const std::string& name, OutputRecord record);
    // The record of output `name` as known now, unchecked; null when none.
    const OutputRecord* find(const std::string& name) const;
    // Writes the records (merged over what is on disk now, so two cooks into
    // one directory keep each other's). Throws atlas::Error on failure.
    void save();
    bool changed() const { return !updates_.empty(); }

private:
    std::filesystem::path root_;
    std::map<std::string, OutputRecord> records_, updates_;
};

// A record written with the same spec and value hash describes files that
// already hold this output: the new key replaces the old without a write.

// True when every file of `files` (relative to `root`) is on disk unchanged:
// its size and mtime are the recorded ones, or, when the mtime moved, its
// content hash is (the mtime is then refreshed in `files`; *refreshed set).
bool files_unchanged(const std::filesystem::path& root, std::vector<OutputFileRecord>& files, bool* refreshed = nullptr);

// What a session's last writing cook left on disk, by output key (issue 43 item 6):
// the same output with the same key in another folder (the next frame of a
// sequence) copies these files instead of encoding its value again.
struct EarlierOutput {
    std::filesystem::path root;
    OutputRecord record;
};
struct EarlierOutputs {
    std::map<std::string, EarlierOutput> by_key;
};

// The mtime of a file in nanoseconds (0 when it cannot be read).
int64_t file_mtime_ns(const std::filesystem::path& p);

} // namespace atlas
