// Shared by the binding files of the atlas Python module. Bindings only: no
// logic of Atlas's own lives here.
#pragma once

#include "atlas/graph/evaluator.h"

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <memory>
#include <string>

namespace atlas::python {

namespace py = pybind11;

// A Python object that C++ may copy and destroy on any thread without the
// GIL (copies share one reference; the last one drops it under the GIL).
class SharedPyObject {
public:
    SharedPyObject() = default;
    explicit SharedPyObject(py::object o)
        : p_(new py::object(std::move(o)), [](py::object* q) {
              py::gil_scoped_acquire gil;
              delete q;
          }) {}
    // Call with the GIL held.
    const py::object& get() const { return *p_; }
    explicit operator bool() const { return p_ && *p_ && !p_->is_none(); }

private:
    std::shared_ptr<py::object> p_;
};

// Fields (fields.cpp): Python views of immutable Atlas fields.
void bind_fields(py::module_& m);
// A Value as a Python object: Field2D, Field3D, a dict of arrays for a mesh
// or points, None when empty. Arrays share the value's memory (read-only).
py::object value_to_python(const Value& v);
// A Python Field2D/Field3D object back to the Value it wraps (none: monostate).
Value python_to_value(const py::handle& o);
// A field from a NumPy array: (ny, nx) or (C, ny, nx) for 2D, (nz, ny, nx) or
// (C, nz, ny, nx) for 3D; `dims` 2 or 3 (0: from the array's rank, 2 or 3
// meaning one channel, 4 meaning channels of a 3D field).
Value field_from_array(const py::array& a, int dims, const py::object& bounds, const py::object& channel_names,
                       const MemoryBudget* budget);

// Errors (errors.h) and parameters (params.h) have headers of their own: the module
// and the Python node types both use them.

// Python node types (python_nodes.cpp).
void bind_python_nodes(py::module_& m);

} // namespace atlas::python
