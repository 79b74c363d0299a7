#include "atlas/core/progress.h"

#include "atlas/core/error.h"

namespace atlas {

void ProgressSink::poll() const {
    if (cancelled()) throw CancelledError();
}

} // namespace atlas
