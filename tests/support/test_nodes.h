// Node types for engine tests: they count their cooks and can misbehave on purpose.
#pragma once

#include "atlas/core/hash.h"
#include "atlas/graph/node.h"

#include <atomic>
#include <map>
#include <memory>
#include <mutex>
#include <string>

namespace atlas::test {

struct CookLog {
    std::mutex mutex;
    std::map<std::string, int> cooks; // node name -> times cooked
    std::atomic<int> leaky_value{1};  // read by test/leaky without hashing it
    std::atomic<bool> fail{false};    // makes test/fail throw

    int count(const std::string& n) {
        std::lock_guard<std::mutex> l(mutex);
        return cooks[n];
    }
    void record(const std::string& n) {
        std::lock_guard<std::mutex> l(mutex);
        ++cooks[n];
    }
};

// builtin_nodes() plus test/source, test/add, test/mesh, test/leaky, test/fail, test/big.
NodeRegistry test_registry(std::shared_ptr<CookLog> log);

} // namespace atlas::test
