// Atlas errors as Python exceptions (errors.h).
#include "errors.h"

namespace atlas::python {

namespace {

// Exception classes (created once per interpreter; the module holds them).
PyObject* g_error = nullptr;
PyObject* g_parse_error = nullptr;
PyObject* g_cancelled = nullptr;
PyObject* g_memory = nullptr;

void raise_with(PyObject* type, const std::string& message, const SourceLocation* where, const std::string* detail) {
    py::object exc = py::reinterpret_borrow<py::object>(type)(message);
    if (where) {
        exc.attr("file") = where->file;
        exc.attr("line") = where->line;
        exc.attr("column") = where->column;
        exc.attr("where") = where->str();
    }
    if (detail) exc.attr("detail") = *detail;
    PyErr_SetObject(type, exc.ptr());
}

void translate(std::exception_ptr p) {
    try {
        if (p) std::rethrow_exception(p);
    } catch (const ParseError& e) {
        raise_with(g_parse_error, e.what(), &e.where(), &e.detail());
    } catch (const CancelledError& e) {
        raise_with(g_cancelled, e.what(), nullptr, nullptr);
    } catch (const MemoryBudgetError& e) {
        raise_with(g_memory, e.what(), nullptr, nullptr);
    } catch (const Error& e) {
        raise_with(g_error, e.what(), nullptr, nullptr);
    }
}

} // namespace

void bind_errors(py::module_& m) {
    g_error = PyErr_NewExceptionWithDoc("atlas.Error", "Any Atlas failure; str(e) is the full message (file:line:col, node, parameter).",
                                        PyExc_RuntimeError, nullptr);
    g_parse_error = PyErr_NewExceptionWithDoc("atlas.ParseError",
                                              "A graph file or text that cannot be used: .file, .line, .column, .where ('file:line:col'), .detail.",
                                              g_error, nullptr);
    g_cancelled = PyErr_NewExceptionWithDoc("atlas.CancelledError", "The cancel callback asked to stop.", g_error, nullptr);
    g_memory = PyErr_NewExceptionWithDoc("atlas.MemoryBudgetError", "An allocation past the memory budget was refused.", g_error, nullptr);
    // The module keeps references for the interpreter's lifetime.
    m.attr("Error") = py::handle(g_error);
    m.attr("ParseError") = py::handle(g_parse_error);
    m.attr("CancelledError") = py::handle(g_cancelled);
    m.attr("MemoryBudgetError") = py::handle(g_memory);
    py::register_exception_translator(translate);
}

std::string python_error_message(py::error_already_set& e) {
    std::string msg = py::str(e.value()).cast<std::string>();
    if (!PyErr_GivenExceptionMatches(e.type().ptr(), g_error))
        msg = py::str(e.type().attr("__name__")).cast<std::string>() + ": " + msg;
    // The innermost Python frame: where a TD's node code failed.
    py::object tb = e.trace() ? py::reinterpret_borrow<py::object>(e.trace()) : py::none();
    py::object last = py::none();
    while (!tb.is_none()) {
        last = tb;
        tb = tb.attr("tb_next");
    }
    if (!last.is_none()) {
        py::object code = last.attr("tb_frame").attr("f_code");
        msg += " (at " + py::str(code.attr("co_filename")).cast<std::string>() + ":" +
               py::str(last.attr("tb_lineno")).cast<std::string>() + " in " + py::str(code.attr("co_name")).cast<std::string>() + ")";
    }
    return msg;
}

} // namespace atlas::python
