// atlas/core/files.h - atomic file output and output-path safety.
//
// A failed write must never leave a partial or corrupted file where a good
// one is expected. StagedOutputs collects every file of one operation (a cook
// may write dozens) in a hidden staging directory beside the destination and
// moves them into place only when all of them were written; if anything
// fails, or the object is destroyed without commit(), nothing is touched.
//
// Atlas never replaces or writes through what it did not create: a
// destination that is a symbolic link, a directory, a device, a FIFO or a
// socket is refused, as is one that is a protected file (the graph, an input
// of the cook) or that a symlinked folder leads outside the root. The commit
// is all-or-nothing: a journal names every move before the first one, and a
// process killed during the moves has them completed by the next Atlas run in
// that directory (remove_stale_staging), so no mix of old and new remains.
#pragma once

#include "atlas/core/hash.h"

#include <cstdint>
#include <filesystem>
#include <initializer_list>
#include <string>
#include <vector>

namespace atlas {

namespace fs = std::filesystem;

// A file Atlas must not write over, and what it is ("the graph file").
struct ProtectedFile {
    fs::path path;
    std::string what;
};

// Throws atlas::Error naming `path` when Atlas may not write a file there: it
// is a symbolic link or not a regular file, or it is one of `protect`
// (compared as files, so hard links and other spellings of one path are
// caught). Names given by a user are checked with is_reserved_name as well. `what` names the
// file's role in the message ("the report").
void check_destination(const fs::path& path, const std::vector<ProtectedFile>& protect = {}, const std::string& what = "output");

// True for a file or folder name Atlas keeps for its own records and staging
// (".atlas-outputs.json", ".atlas-staging-...": every name starting ".atlas-").
bool is_reserved_name(const std::string& name);

class StagedOutputs {
public:
    // Files will be committed under `root` (created on commit if missing).
    explicit StagedOutputs(fs::path root);
    ~StagedOutputs(); // removes the staging directory if not committed
    StagedOutputs(const StagedOutputs&) = delete;
    StagedOutputs& operator=(const StagedOutputs&) = delete;

    // A path in the staging area for `relative` (its parent directories are
    // created). Write the file there; it is moved to root/relative on commit.
    fs::path stage(const fs::path& relative);
    // The same for a record that describes the other files (a tile's
    // fragment): it is moved into place after every other file.
    fs::path stage_last(const fs::path& relative);
    // Files the commit must refuse to replace (the graph, the cook's inputs).
    void protect(std::vector<ProtectedFile> files) { protect_ = std::move(files); }
    // Moves every staged file into place (rename within one file system),
    // after checking every destination (check_destination, no two staged
    // files reaching one file, none leaving the root through a symlinked
    // folder) and writing the journal. Returns the final paths.
    std::vector<fs::path> commit();
    // The checks and the journal of commit() alone: a caller committing
    // several StagedOutputs prepares them all first, so that a refused
    // destination in one changes nothing in any. Throws atlas::Error.
    void prepare();
    // Where a file staged at `staged` (a path under the staging area) lands on commit.
    fs::path final_path(const fs::path& staged) const;
    // Every file the writers produced in the staging area, as relative paths,
    // in commit order (sorted; the stage_last files at the end).
    std::vector<fs::path> staged_files() const;
    // Removes what a failed writer left staged for `relative`: the files whose relative path
    // starts with it (OUT.dds and OUT.dds.json, a slice stack's STEM.001.tga, ...).
    void discard(const fs::path& relative);

private:
    fs::path root_;
    fs::path staging_;
    int lock_fd_ = -1; // the marker, flock()ed while this lives (remove_stale_staging)
    std::vector<fs::path> last_;
    std::vector<ProtectedFile> protect_;
    std::vector<fs::path> files_; // what prepare() checked and journaled
    bool prepared_ = false;
    bool committed_ = false;
};

// Writes one file atomically: `write` is called with a temporary path in the
// same directory, which is renamed over `path` when it returns normally and
// removed if it throws.
// The destination is checked first (check_destination with `protect`).
template <typename WriteFn>
void write_file_atomic(const fs::path& path, WriteFn&& write, const std::vector<ProtectedFile>& protect = {}) {
    check_destination(path, protect, "file");
    StagedOutputs out(path.parent_path().empty() ? fs::path(".") : path.parent_path());
    out.protect(protect);
    write(out.stage(path.filename()));
    out.commit();
}

// Resolves an output path from a graph against the output directory. Throws
// atlas::Error when it is absolute or climbs out of `out_dir` (through `..`
// or a symlink), unless `allow_outside` is true, and always when it holds a
// control character (a NUL would cut the name short) or a name Atlas keeps
// for itself (is_reserved_name).
fs::path resolve_output_path(const fs::path& out_dir, const std::string& relative, bool allow_outside);
// The name checks alone (the graph parser's, so that `validate` reports them).
void check_output_name(const std::string& relative);

// Reads a whole file; throws atlas::Error naming the file on failure.
std::string read_file_bytes(const fs::path& path);

// Writes `size` bytes to `path` (created or truncated) with every write and
// the close checked: a full disk or a file-size limit throws atlas::Error
// naming the file and the system's reason, never a silently short file.
// Not atomic by itself (write into a StagedOutputs path).
void write_file_checked(const fs::path& path, const void* data, size_t size);
// The same for a file made of several pieces written one after another (a
// header and a payload), so a caller need not join them into one more copy.
struct BytePiece {
    const void* data;
    size_t size;
};
void write_file_checked(const fs::path& path, std::initializer_list<BytePiece> pieces);

// A fast streaming checksum of a byte sequence, for telling whether bytes
// changed or were damaged (cache entries, output files), not for cache keys
// (those use Hasher). Four independent 64-bit lanes in the manner of XXH64,
// several times Hasher's throughput. The result depends only on the bytes,
// not on how they are split into add() calls. Not cryptographic.
class ContentHasher {
public:
    ContentHasher& add(const void* data, size_t size);
    Hash128 finish() const;

private:
    void block(const unsigned char* p);
    uint64_t lane_[4] = {0x9E3779B185EBCA87ull + 0xC2B2AE3D27D4EB4Full, 0xC2B2AE3D27D4EB4Full, 0, 0 - 0x9E3779B185EBCA87ull};
    unsigned char buf_[32] = {};
    size_t buffered_ = 0;
    uint64_t total_ = 0;
};

// ContentHasher of a file's bytes. Throws atlas::Error naming the file.
Hash128 file_content_hash(const fs::path& path);

// Staging directories (".atlas-staging-HOST-PID-N") that a killed process
// left in `dir`: those whose marker no process holds locked (a running cook
// holds its marker's flock, whatever host or PID namespace it runs in; the
// lock dies with the process), and, for folders of older Atlas versions
// (markers without the lock), those of this host whose process no longer
// runs and any older than a day. One whose commit had begun (its journal is there) is
// completed first: the files it had not yet moved are moved into place.
// Removes them and returns how many bytes they held. Only folders that
// Atlas made (they hold its marker file) are touched, whatever their name.
// Never throws (a directory that cannot be listed holds nothing to clean).
uint64_t remove_stale_staging(const fs::path& dir);

} // namespace atlas

namespace atlas {
class Hasher;
// Adds a file's size and contents to a hash (import nodes use it so that
// editing an input file re-cooks what depends on it). Throws atlas::Error
// naming the file when it cannot be read or is not a regular file (a FIFO or
// a device would never end).
void hash_file(Hasher& h, const fs::path& path);

// A file hash_file() read: what a cook depends on (--depfile, the report).
struct FileRead {
    fs::path path;
    uint64_t bytes = 0;
    Hash128 hash; // file_content_hash of the bytes read
};

// While alive, every hash_file() call on this thread appends to `sink`.
// Thread-local: nodes hash on the evaluator's thread. Nests (the innermost wins).
class FileReadRecorder {
public:
    explicit FileReadRecorder(std::vector<FileRead>* sink);
    ~FileReadRecorder();
    FileReadRecorder(const FileReadRecorder&) = delete;
    FileReadRecorder& operator=(const FileReadRecorder&) = delete;

private:
    std::vector<FileRead>* previous_;
};
} // namespace atlas
