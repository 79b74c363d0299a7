#include "atlas/core/files.h"

#include "atlas/core/error.h"
#include "atlas/core/hash.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <fstream>
#include <sstream>
#include <system_error>
#include <unistd.h>
#include <vector>

namespace atlas {

namespace {
// A staging name unique within the process and across processes.
std::string staging_name() {
    static std::atomic<uint64_t> counter{0};
    uint64_t n = counter.fetch_add(1);
    uint64_t t = uint64_t(std::chrono::steady_clock::now().time_since_epoch().count());
    uint64_t h = mix64(t ^ mix64(uint64_t(::getpid()) ^ (n << 32)));
    char buf[40];
    std::snprintf(buf, sizeof buf, ".atlas-staging-%016llx", static_cast<unsigned long long>(h));
    return buf;
}
} // namespace

StagedOutputs::StagedOutputs(fs::path root) : root_(std::move(root)) {
    std::error_code ec;
    fs::create_directories(root_, ec);
    if (ec) throw Error("cannot create output directory '" + root_.string() + "': " + ec.message());
    staging_ = root_ / staging_name();
    fs::create_directories(staging_, ec);
    if (ec) throw Error("cannot create staging directory in '" + root_.string() + "': " + ec.message());
}

StagedOutputs::~StagedOutputs() {
    std::error_code ec;
    fs::remove_all(staging_, ec); // best effort; never throws from a destructor
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
    for (auto it = fs::recursive_directory_iterator(staging_, ec); !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
        if (it->is_regular_file()) files.push_back(fs::relative(it->path(), staging_));
    std::sort(files.begin(), files.end());
    return files;
}

fs::path StagedOutputs::final_path(const fs::path& staged) const { return root_ / staged.lexically_relative(staging_); }

std::vector<fs::path> StagedOutputs::commit() {
    std::vector<fs::path> done;
    for (const auto& rel : staged_files()) {
        fs::path dst = root_ / rel;
        std::error_code ec;
        fs::create_directories(dst.parent_path(), ec);
        fs::rename(staging_ / rel, dst, ec);
        if (ec) throw Error("cannot move '" + rel.string() + "' into '" + root_.string() + "': " + ec.message());
        done.push_back(dst);
    }
    committed_ = true;
    return done;
}

fs::path resolve_output_path(const fs::path& out_dir, const std::string& relative, bool allow_outside) {
    fs::path rel(relative);
    if (relative.empty()) throw Error("output path is empty");
    if (rel.is_absolute()) {
        if (!allow_outside)
            throw Error("output path '" + relative + "' is absolute; paths are relative to --out (pass --allow-outside-out to permit this)");
        return rel.lexically_normal();
    }
    fs::path joined = (out_dir / rel).lexically_normal();
    if (allow_outside) return joined;
    fs::path base = fs::weakly_canonical(out_dir);
    // weakly_canonical follows symlinks in the existing prefix, so a link
    // inside --out that points elsewhere is caught here too.
    fs::path resolved = fs::weakly_canonical(joined);
    auto mismatch = std::mismatch(base.begin(), base.end(), resolved.begin(), resolved.end());
    if (mismatch.first != base.end())
        throw Error("output path '" + relative + "' leaves the output directory '" + out_dir.string() +
                    "' (through '..' or a symlink); pass --allow-outside-out to permit this");
    return joined;
}

std::string read_file_bytes(const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path.string() + ": cannot open file for reading");
    in.seekg(0, std::ios::end);
    // One allocation of the file's size and one read (cache entries reach
    // hundreds of MB; a stringstream would copy them twice).
    const std::streamoff size = in.tellg();
    if (size < 0) { // a pipe or device (e.g. /dev/stdin): no size, read it as a stream
        in.clear();
        std::ostringstream ss;
        ss << in.rdbuf();
        if (in.bad()) throw Error(path.string() + ": read error");
        return ss.str();
    }
    std::string bytes(size_t(size), '\0');
    in.seekg(0);
    in.read(bytes.data(), size);
    if (in.gcount() != size) throw Error(path.string() + ": read error (file shorter than its size)");
    return bytes;
}

} // namespace atlas

namespace atlas {
void hash_file(Hasher& h, const fs::path& path) {
    std::ifstream in(path, std::ios::binary);
    if (!in) throw Error(path.string() + ": cannot open input file (does it exist?)");
    h.add(path.filename().string());
    std::vector<char> buf(1 << 20);
    uint64_t total = 0;
    while (in) {
        in.read(buf.data(), std::streamsize(buf.size()));
        const auto n = size_t(in.gcount());
        if (n) h.add_bytes(buf.data(), n);
        total += n;
    }
    h.add(total);
}
} // namespace atlas
