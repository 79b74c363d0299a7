// atlas/core/file_limits.h - limits on hash_file() (core/files.h) for the evaluator's thread (graph);
// hosts do not need it. Implemented in files.cpp, beside hash_file.
#pragma once

#include <cstdint>
#include <functional>

namespace atlas::detail {

// While alive, hash_file() on this thread refuses a file larger than
// `max_bytes` (the memory budget: no reader could hold it) before reading a
// byte, and polls `cancelled` between chunks (CancelledError): a 20 GB file
// takes seconds to hash. Nests (the innermost wins).
class FileReadLimits {
public:
    FileReadLimits(uint64_t max_bytes, std::function<bool()> cancelled);
    ~FileReadLimits();
    FileReadLimits(const FileReadLimits&) = delete;
    FileReadLimits& operator=(const FileReadLimits&) = delete;

    uint64_t max_bytes;
    std::function<bool()> cancelled;

private:
    FileReadLimits* previous_;
};

} // namespace atlas::detail
