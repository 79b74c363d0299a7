// Atlas errors as Python exceptions, and Python exceptions as the one-line messages of
// atlas::Error. Used by the module (callbacks) and by Python node types (their cook),
// so it lives apart from both.
#pragma once

#include "bindings.h"

#include <string>

namespace atlas::python {

// Creates atlas.Error (a RuntimeError), atlas.ParseError (.file, .line, .column,
// .where, .detail), atlas.CancelledError and atlas.MemoryBudgetError in `m`, and
// translates the atlas::Error family into them. Once, at import.
void bind_errors(py::module_& m);

// A Python exception as one line for an atlas::Error: "ValueError: message
// (at file.py:12 in cook)"; an atlas.Error raised in Python keeps its text.
std::string python_error_message(py::error_already_set& e);

} // namespace atlas::python
