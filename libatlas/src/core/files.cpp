#include "atlas/core/files.h"
#include "atlas/core/memory.h"
#include "atlas/core/file_limits.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fcntl.h>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <sys/file.h>
#include <sys/stat.h>
#include <system_error>
#include <unistd.h>
#include <vector>

namespace atlas {

namespace {
constexpr char kStagingPrefix[] = ".atlas-staging-";

std::string host_name() {
    char buf[256] = {};
    if (::gethostname(buf, sizeof buf - 1) != 0 || !buf[0]) return "host";
    std::string h(buf);
    for (char& c : h)
        if (!std::isalnum(static_cast<unsigned char>(c))) c = '_'; // '-' separates the name's parts
    return h;
}

// A staging name unique within the process and across processes; it names
// the host and process so that the next cook can tell a killed cook's
// leftovers from a running cook's work (remove_stale_staging).
std::string staging_name() {
    static std::atomic<uint64_t> counter{0};
    uint64_t n = counter.fetch_add(1);
    uint64_t t = uint64_t(std::chrono::steady_clock::now().time_since_epoch().count());
    uint64_t h = mix64(t ^ mix64(uint64_t(::getpid()) ^ (n << 32)));
    char buf[64];
    std::snprintf(buf, sizeof buf, "-%lld-%016llx", static_cast<long long>(::getpid()), static_cast<unsigned long long>(h));
    return kStagingPrefix + host_name() + buf;
}

uint64_t tree_bytes(const fs::path& dir) {
    uint64_t total = 0;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        std::error_code e2;
        if (it->is_regular_file(e2)) total += it->file_size(e2);
    }
    return total;
}
} // namespace

namespace {
// Inside a staging folder: the marker that Atlas made it, the journal of a
// commit that has begun, and the files a commit replaced.
constexpr char kMarkerName[] = ".atlas-staging";
// A marker that starts with this is flock()ed by its cook for as long as the folder
// lives: a folder whose marker nobody holds belongs to no running cook, whatever host
// or PID namespace made it (the host-and-PID test is for older folders).
constexpr char kLockedMarker[] = "atlas staging folder, locked while its cook runs";
constexpr char kJournalName[] = ".atlas-commit";
constexpr char kReplacedName[] = ".atlas-replaced";

bool is_staging_record(const std::string& name) {
    return name == kMarkerName || name == kJournalName || name == std::string(kJournalName) + ".tmp" || name == kReplacedName;
}

// The journal: one relative path a line, hex-encoded (a name may hold any byte).
std::string hex_encode(const std::string& s) {
    static const char* d = "0123456789abcdef";
    std::string out;
    for (unsigned char c : s) out += d[c >> 4], out += d[c & 15];
    return out;
}
std::optional<std::string> hex_decode(const std::string& h) {
    if (h.size() % 2) return std::nullopt;
    std::string out;
    for (size_t i = 0; i < h.size(); i += 2) {
        int v = 0;
        for (size_t k = i; k < i + 2; ++k) {
            const char c = h[k];
            v = v * 16 + (c >= '0' && c <= '9' ? c - '0' : c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1000);
        }
        if (v < 0) return std::nullopt;
        out += char(v);
    }
    return out;
}

// Completes a commit that a killed process began: every file the journal
// names that is still staged moves into place (roll forward; the journal was
// written only once every file was complete). A destination that is now
// something Atlas may not replace is left alone.
void complete_commit(const fs::path& root, const fs::path& staging) {
    std::ifstream in(staging / kJournalName);
    std::string line;
    while (std::getline(in, line)) {
        const auto rel = hex_decode(line);
        if (!rel || rel->empty()) continue;
        const fs::path r(*rel);
        if (r.is_absolute() || (!r.empty() && r.lexically_normal().begin()->string() == "..")) continue;
        std::error_code ec;
        const fs::path src = staging / r, dst = root / r;
        if (!fs::is_regular_file(fs::symlink_status(src, ec))) continue;
        const auto st = fs::symlink_status(dst, ec);
        if (fs::exists(st) && !fs::is_regular_file(st)) continue;
        fs::create_directories(dst.parent_path(), ec);
        fs::rename(src, dst, ec);
    }
}

// A staging folder named HOST-PID-HEX (parts from the end; older names have only HEX)
// whose host is this one and whose process no longer runs.
bool named_for_a_dead_process(const std::string& name, const std::string& host) {
    const std::string rest = name.substr(sizeof kStagingPrefix - 1);
    const auto last = rest.rfind('-');
    const auto mid = last == std::string::npos || last == 0 ? std::string::npos : rest.rfind('-', last - 1);
    if (mid == std::string::npos || rest.substr(0, mid) != host) return false;
    const long long pid = std::atoll(rest.substr(mid + 1, last - mid - 1).c_str());
    return pid > 0 && ::kill(pid_t(pid), 0) != 0 && errno == ESRCH;
}
} // namespace

uint64_t remove_stale_staging(const fs::path& dir) {
    uint64_t removed = 0;
    std::error_code ec;
    const std::string host = host_name();
    const auto now = fs::file_time_type::clock::now();
    for (auto it = fs::directory_iterator(dir, ec); !ec && it != fs::directory_iterator(); it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.rfind(kStagingPrefix, 0) != 0) continue;
        std::error_code e2;
        if (!it->is_directory(e2) || it->is_symlink(e2)) continue;
        // Only a folder Atlas made: a user's folder that happens to have the name is theirs.
        if (!fs::is_regular_file(fs::symlink_status(it->path() / kMarkerName, e2))) continue;
        // The marker's lock: held by a running cook (shared), so an exclusive try fails.
        const int fd = ::open((it->path() / kMarkerName).c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
        if (fd < 0) continue;
        char head[sizeof kLockedMarker - 1] = {};
        const bool locked_kind = ::pread(fd, head, sizeof head, 0) == ssize_t(sizeof head) && std::memcmp(head, kLockedMarker, sizeof head) == 0;
        const bool free = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
        ::close(fd);
        if (!free) continue; // a cook is running in it
        const auto age = now - fs::last_write_time(it->path() / kMarkerName, e2);
        bool stale = locked_kind;
        // An older Atlas's folder (no lock), or one whose marker is being written: by host
        // and PID, once a minute old.
        if (!stale && !e2 && age > std::chrono::minutes(1)) stale = named_for_a_dead_process(name, host);
        if (!stale) {
            const auto t = fs::last_write_time(it->path(), e2);
            stale = !e2 && now - t > std::chrono::hours(24);
        }
        if (!stale) continue;
        if (fs::exists(it->path() / kJournalName, e2)) complete_commit(dir, it->path());
        const uint64_t bytes = tree_bytes(it->path());
        fs::remove_all(it->path(), e2);
        if (!e2) removed += bytes;
    }
    return removed;
}

bool is_reserved_name(const std::string& name) { return name.rfind(".atlas-", 0) == 0; }

void check_destination(const fs::path& path, const std::vector<ProtectedFile>& protect, const std::string& what) {
    std::error_code ec;
    const auto st = fs::symlink_status(path, ec);
    if (fs::is_symlink(st))
        throw Error(path.string() + ": the " + what + " path is a symbolic link; Atlas does not replace or write through links (remove it or choose another path)");
    if (fs::exists(st) && !fs::is_regular_file(st))
        throw Error(path.string() + ": the " + what + " path is " +
                    (fs::is_directory(st) ? "a directory" : fs::is_character_file(st) || fs::is_block_file(st) ? "a device" : fs::is_fifo(st) ? "a FIFO" : "a socket or other special file") +
                    "; Atlas only replaces regular files");
    if (!fs::exists(st)) return;
    for (const auto& p : protect) {
        std::error_code e2;
        if (!p.path.empty() && fs::equivalent(path, p.path, e2) && !e2)
            throw Error(path.string() + ": the " + what + " would overwrite " + p.what + " ('" + p.path.string() + "'); choose another path");
    }
}

void write_file_checked(const fs::path& path, const void* data, size_t size) { write_file_checked(path, {BytePiece{data, size}}); }

void write_file_checked(const fs::path& path, std::initializer_list<BytePiece> pieces) {
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    if (fd < 0) throw Error(path.string() + ": cannot create the file: " + std::strerror(errno));
    size_t size = 0, done = 0;
    for (const BytePiece& piece : pieces) size += piece.size;
    for (const BytePiece& piece : pieces) {
        const auto* p = static_cast<const char*>(piece.data);
        size_t left = piece.size;
        while (left > 0) {
            const ssize_t n = ::write(fd, p, std::min<size_t>(left, size_t(1) << 30));
            if (n < 0 && errno == EINTR) continue;
            if (n <= 0) {
                const int err = n < 0 ? errno : ENOSPC;
                ::close(fd);
                throw Error(path.string() + ": write failed after " + std::to_string(done) + " of " + std::to_string(size) +
                            " bytes: " + std::strerror(err));
            }
            p += n;
            left -= size_t(n);
            done += size_t(n);
        }
    }
    if (::close(fd) != 0) throw Error(path.string() + ": write failed when closing the file: " + std::strerror(errno));
}

namespace {
constexpr uint64_t kP1 = 0x9E3779B185EBCA87ull, kP2 = 0xC2B2AE3D27D4EB4Full, kP3 = 0x165667B19E3779F9ull;
constexpr uint64_t rotl(uint64_t x, int r) { return (x << r) | (x >> (64 - r)); }
constexpr uint64_t round64(uint64_t acc, uint64_t w) { return rotl(acc + w * kP2, 31) * kP1; }
} // namespace

void ContentHasher::block(const unsigned char* p) {
    for (int k = 0; k < 4; ++k) {
        uint64_t w;
        std::memcpy(&w, p + 8 * k, 8);
        lane_[k] = round64(lane_[k], w);
    }
}

ContentHasher& ContentHasher::add(const void* data, size_t size) {
    if (size == 0) return *this; // data may be null then (an empty vector's data())
    const auto* p = static_cast<const unsigned char*>(data);
    total_ += size;
    if (buffered_) {
        const size_t take = std::min(size, 32 - buffered_);
        std::memcpy(buf_ + buffered_, p, take);
        buffered_ += take, p += take, size -= take;
        if (buffered_ < 32) return *this;
        block(buf_);
        buffered_ = 0;
    }
    for (; size >= 32; p += 32, size -= 32) block(p);
    std::memcpy(buf_, p, size);
    buffered_ = size;
    return *this;
}

Hash128 ContentHasher::finish() const {
    uint64_t l[4] = {lane_[0], lane_[1], lane_[2], lane_[3]};
    // The tail, zero-padded, as one more block (the length below tells tails apart).
    if (buffered_) {
        unsigned char tail[32] = {};
        std::memcpy(tail, buf_, buffered_);
        for (int k = 0; k < 4; ++k) {
            uint64_t w;
            std::memcpy(&w, tail + 8 * k, 8);
            l[k] = round64(l[k], w);
        }
    }
    uint64_t a = rotl(l[0], 1) + rotl(l[1], 7) + rotl(l[2], 12) + rotl(l[3], 18);
    for (uint64_t v : l) a = (a ^ round64(0, v)) * kP1 + kP3;
    const uint64_t hi = mix64(a ^ total_);
    const uint64_t lo = mix64(hi ^ l[0] ^ rotl(l[2], 29) ^ (total_ * kP3));
    return {hi, mix64(lo ^ l[1] ^ rotl(l[3], 17))};
}

Hash128 file_content_hash(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path.string() + ": cannot open file for reading");
    ContentHasher h;
    std::vector<char> buf(1 << 20);
    while (in) {
        in.read(buf.data(), std::streamsize(buf.size()));
        if (const auto n = size_t(in.gcount())) h.add(buf.data(), n);
    }
    if (in.bad()) throw Error(path.string() + ": read error");
    return h.finish();
}

StagedOutputs::StagedOutputs(fs::path root) : root_(std::move(root)) {
    std::error_code ec;
    fs::create_directories(root_, ec);
    if (ec) throw Error("cannot create output directory '" + root_.string() + "': " + ec.message());
    staging_ = root_ / staging_name();
    fs::create_directories(staging_, ec);
    if (ec) throw Error("cannot create staging directory in '" + root_.string() + "': " + ec.message());
    // The marker says Atlas made this folder (remove_stale_staging touches no other); it is
    // locked before a byte is written and stays locked while this object lives.
    static const std::string marker = std::string(kLockedMarker) + "; removed or completed by the next Atlas run in this directory\n";
    const fs::path m = staging_ / kMarkerName;
    lock_fd_ = ::open(m.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC | O_NOFOLLOW, 0644);
    if (lock_fd_ < 0 || ::flock(lock_fd_, LOCK_SH) != 0 || ::write(lock_fd_, marker.data(), marker.size()) != ssize_t(marker.size())) {
        const std::string why = std::strerror(errno);
        if (lock_fd_ >= 0) ::close(lock_fd_);
        lock_fd_ = -1;
        fs::remove_all(staging_, ec);
        throw Error("cannot create the staging marker '" + m.string() + "': " + why);
    }
}

StagedOutputs::~StagedOutputs() {
    std::error_code ec;
    fs::remove_all(staging_, ec); // best effort; never throws from a destructor
    if (lock_fd_ >= 0) ::close(lock_fd_);
}

fs::path StagedOutputs::stage_last(const fs::path& relative) {
    last_.push_back(relative.lexically_normal());
    return stage(relative);
}

fs::path StagedOutputs::stage(const fs::path& relative) {
    if (committed_) throw Error("internal: StagedOutputs used after commit");
    fs::path p = staging_ / relative;
    std::error_code ec;
    fs::create_directories(p.parent_path(), ec);
    if (ec) throw Error("cannot create directory '" + p.parent_path().string() + "': " + ec.message());
    return p;
}

std::vector<fs::path> StagedOutputs::staged_files() const {
    std::vector<fs::path> files;
    std::error_code ec;
    for (auto it = fs::recursive_directory_iterator(staging_, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
        if (it.depth() == 0 && is_staging_record(it->path().filename().string())) {
            it.disable_recursion_pending();
            continue;
        }
        if (it->is_regular_file()) files.push_back(fs::relative(it->path(), staging_));
    }
    std::sort(files.begin(), files.end());
    // Records last: whoever reads one finds the files it names in place.
    std::stable_partition(files.begin(), files.end(), [&](const fs::path& f) { return std::find(last_.begin(), last_.end(), f) == last_.end(); });
    return files;
}

void StagedOutputs::discard(const fs::path& relative) {
    if (prepared_ || committed_) throw Error("internal: StagedOutputs::discard after prepare");
    const std::string prefix = relative.lexically_normal().generic_string();
    for (const fs::path& f : staged_files())
        if (f.generic_string().rfind(prefix, 0) == 0) {
            std::error_code ec;
            fs::remove(staging_ / f, ec);
        }
}

fs::path StagedOutputs::final_path(const fs::path& staged) const { return root_ / staged.lexically_relative(staging_); }

void StagedOutputs::prepare() {
    if (prepared_) return;
    if (committed_) throw Error("internal: StagedOutputs used after commit");
    const std::vector<fs::path> files = staged_files();
    // 1. Every destination directory first: a path component that is a file
    //    fails here, before anything moved. Then every destination is one
    //    Atlas may replace, inside the root, and reached by one file only.
    std::error_code rec;
    const fs::path canonical_root = fs::weakly_canonical(fs::absolute(root_), rec);
    std::map<fs::path, fs::path> reached; // canonical destination -> the staged name that reaches it
    for (const auto& rel : files) {
        const fs::path dst = root_ / rel;
        std::error_code ec;
        fs::create_directories(dst.parent_path(), ec);
        if (ec || !fs::is_directory(dst.parent_path()))
            throw Error("cannot move '" + rel.string() + "' into '" + root_.string() + "': cannot create directory '" +
                        dst.parent_path().string() + "'" + (ec ? ": " + ec.message() : ": a file is in the way"));
        check_destination(dst, protect_);
        const fs::path canonical = fs::weakly_canonical(fs::absolute(dst.parent_path()), ec) / dst.filename();
        const auto m = std::mismatch(canonical_root.begin(), canonical_root.end(), canonical.begin(), canonical.end());
        if (rec || ec || m.first != canonical_root.end())
            throw Error(dst.string() + ": a symlinked folder leads this file outside '" + root_.string() + "' (to '" + canonical.string() +
                        "'); Atlas does not write through it (nothing was changed)");
        if (const auto [it, fresh] = reached.emplace(canonical, rel); !fresh)
            throw Error("'" + it->second.string() + "' and '" + rel.string() + "' in '" + root_.string() + "' are one file ('" + canonical.string() +
                        "', through a symlinked folder): one would be lost (nothing was changed)");
    }
    // 2. The journal: from here on the commit is decided. A process killed
    //    during the moves has them completed by the next run (complete_commit).
    {
        std::string journal;
        for (const auto& rel : files) journal += hex_encode(rel.generic_string()) + "\n";
        const fs::path tmp = staging_ / (std::string(kJournalName) + ".tmp");
        write_file_checked(tmp, journal.data(), journal.size());
        std::error_code ec;
        fs::rename(tmp, staging_ / kJournalName, ec);
        if (ec) throw Error("cannot write the commit journal in '" + staging_.string() + "': " + ec.message() + " (nothing was changed)");
    }
    files_ = files;
    prepared_ = true;
}

std::vector<fs::path> StagedOutputs::commit() {
    prepare();
    const std::vector<fs::path>& files = files_;
    // 3. Move; the files replaced are kept in the staging area until every
    //    move succeeded, so a failure puts the old files back.
    const fs::path old_dir = staging_ / kReplacedName;
    struct Move {
        fs::path rel;
        bool replaced;
    };
    std::vector<Move> moved;
    auto undo = [&] {
        std::error_code je;
        fs::remove(staging_ / kJournalName, je); // undone, not to be completed
        for (auto it = moved.rbegin(); it != moved.rend(); ++it) {
            std::error_code e;
            fs::rename(root_ / it->rel, staging_ / it->rel, e);
            if (it->replaced) fs::rename(old_dir / it->rel, root_ / it->rel, e);
        }
    };
    std::vector<fs::path> done;
    for (const auto& rel : files) {
        const fs::path dst = root_ / rel;
        std::error_code ec;
        bool replaced = false;
        if (fs::is_regular_file(fs::symlink_status(dst, ec))) {
            fs::create_directories((old_dir / rel).parent_path(), ec);
            fs::rename(dst, old_dir / rel, ec);
            replaced = !ec;
        }
        ec.clear();
        fs::rename(staging_ / rel, dst, ec);
        if (ec) {
            if (replaced) {
                std::error_code e;
                fs::rename(old_dir / rel, dst, e);
            }
            undo();
            throw Error("cannot move '" + rel.string() + "' into '" + root_.string() + "': " + ec.message() + " (nothing was changed)");
        }
        moved.push_back({rel, replaced});
        done.push_back(dst);
    }
    committed_ = true;
    return done;
}

void check_output_name(const std::string& relative) {
    if (relative.empty()) throw Error("output path is empty");
    const fs::path rel(relative);
    for (unsigned char c : relative)
        if (c < 0x20 || c == 0x7f) {
            std::string shown;
            for (unsigned char d : relative) shown += d < 0x20 || d == 0x7f ? "\\x" + std::string(1, "0123456789abcdef"[d >> 4]) + "0123456789abcdef"[d & 15] : std::string(1, char(d));
            throw Error("output path '" + shown + "' holds a control character (a NUL or a line break); output names must be plain text");
        }
    for (const auto& part : rel)
        if (is_reserved_name(part.string()))
            throw Error("output path '" + relative + "': names starting with '.atlas-' are kept for Atlas's own records and staging; choose another name");
}

fs::path resolve_output_path(const fs::path& out_dir, const std::string& relative, bool allow_outside) {
    fs::path rel(relative);
    check_output_name(relative);
    if (rel.is_absolute()) {
        if (!allow_outside)
            throw Error("output path '" + relative + "' is absolute; paths are relative to --out (pass --allow-outside-out to permit this)");
        return rel.lexically_normal();
    }
    fs::path joined = (out_dir / rel).lexically_normal();
    if (allow_outside) return joined;
    // Absolute first: weakly_canonical of a relative path whose first
    // component does not exist yet ("nvdf/x.exr" under --out .) stays
    // relative and would look like it left the directory.
    fs::path base = fs::weakly_canonical(fs::absolute(out_dir));
    // weakly_canonical follows symlinks in the existing prefix, so a link
    // inside --out that points elsewhere is caught here too.
    fs::path resolved = fs::weakly_canonical(fs::absolute(joined));
    auto mismatch = std::mismatch(base.begin(), base.end(), resolved.begin(), resolved.end());
    if (mismatch.first != base.end())
        throw Error("output path '" + relative + "' leaves the output directory '" + out_dir.string() +
                    "' (through '..' or a symlink); pass --allow-outside-out to permit this");
    return joined;
}

std::string read_file_bytes(const fs::path& path) {
    // By type before opening: a FIFO would block the open, a directory opens
    // and claims an absurd size, a device never ends.
    std::error_code ec;
    const auto st = fs::status(path, ec);
    if (!ec && fs::exists(st) && !fs::is_regular_file(st))
        throw Error(path.string() + ": not a regular file (" + (fs::is_directory(st) ? "a directory" : "a device, FIFO or socket") +
                    "); Atlas reads regular files only");
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path.string() + ": cannot open file for reading");
    in.seekg(0, std::ios::end);
    // One allocation of the file's size and one read (cache entries reach
    // hundreds of MB; a stringstream would copy them twice).
    const std::streamoff size = in.tellg();
    if (size < 0) throw Error(path.string() + ": cannot tell the file's size");
    std::string bytes(size_t(size), '\0');
    in.seekg(0);
    in.read(bytes.data(), size);
    if (in.gcount() != size) throw Error(path.string() + ": read error (file shorter than its size)");
    return bytes;
}

} // namespace atlas

namespace atlas {
namespace {
thread_local std::vector<FileRead>* t_file_reads = nullptr;
thread_local detail::FileReadLimits* t_limits = nullptr;
} // namespace

FileReadRecorder::FileReadRecorder(std::vector<FileRead>* sink) : previous_(t_file_reads) { t_file_reads = sink; }
FileReadRecorder::~FileReadRecorder() { t_file_reads = previous_; }

detail::FileReadLimits::FileReadLimits(uint64_t max, std::function<bool()> c) : max_bytes(max), cancelled(std::move(c)), previous_(t_limits) {
    t_limits = this;
}
detail::FileReadLimits::~FileReadLimits() { t_limits = previous_; }

void hash_file(Hasher& h, const fs::path& path) {
    std::error_code ec;
    const auto st = fs::status(path, ec);
    if (!ec && fs::exists(st) && !fs::is_regular_file(st))
        throw Error(path.string() + ": not a regular file (" + (fs::is_directory(st) ? "a directory" : "a device, FIFO or socket") +
                    "); input files must be regular files");
    if (t_limits && !ec && fs::is_regular_file(st)) {
        std::error_code sec;
        const uint64_t size = fs::file_size(path, sec);
        if (!sec && size > t_limits->max_bytes)
            throw Error(path.string() + ": the input file is " + format_bytes(size) + ", over the memory budget of " +
                        format_bytes(t_limits->max_bytes) + " (raise it with --memory-budget)");
    }
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path.string() + ": cannot open input file (does it exist?)");
    h.add(path.filename().string());
    ContentHasher content; // equals file_content_hash of the same bytes
    std::vector<char> buf(1 << 20);
    uint64_t total = 0;
    while (in) {
        if (t_limits && t_limits->cancelled && (total & ((64u << 20) - 1)) == 0 && t_limits->cancelled()) throw CancelledError();
        in.read(buf.data(), std::streamsize(buf.size()));
        const auto n = size_t(in.gcount());
        if (n) {
            h.add_bytes(buf.data(), n);
            content.add(buf.data(), n);
        }
        total += n;
    }
    if (in.bad()) throw Error(path.string() + ": read error");
    h.add(total);
    if (t_file_reads) t_file_reads->push_back({path, total, content.finish()});
}
} // namespace atlas
