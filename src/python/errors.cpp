// plenoptic.Error and its two kinds, and the translation of the library's exceptions
// (core/error.h) into them (bindings.h).
#include <pybind11/eval.h>

#include "bindings.h"
#include "core/error.h"

namespace pl::python {

void bindErrors(py::module_& m) {
  // plenoptic.Error for every failure (the CLI's message, without 'plenoptic: error: '),
  // plenoptic.UsageError (also a ValueError) for a wrong request — what the CLI exits 2 for —
  // and plenoptic.FileError (also an OSError, with `filename`) for a file that cannot be opened,
  // read or written (pl::FileError).
  static py::exception<pl::Error> error(m, "Error", PyExc_RuntimeError);
  static py::handle usageError = [&] {
    py::object type = py::reinterpret_steal<py::object>(PyErr_NewExceptionWithDoc(
        "plenoptic.UsageError", "A wrong request (bad argument or value): the command line's usage errors.",
        py::make_tuple(error, py::handle(PyExc_ValueError)).ptr(), nullptr));
    m.attr("UsageError") = type;
    return type.release();
  }();
  static py::handle fileError = [&] {
    // Defined in Python for its __str__: the message alone, as for the other errors (OSError's
    // own str would print "[Errno None] None: 'filename'" once filename is set).
    py::dict scope;
    scope["__builtins__"] = py::module_::import("builtins");
    scope["Error"] = error;
    py::exec(R"(
class FileError(Error, OSError):
    """A file that cannot be opened, read or written; `filename` names it."""
    __module__ = "plenoptic"
    def __str__(self):
        return str(self.args[0]) if self.args else ""
)",
             scope);
    py::object type = scope["FileError"];
    m.attr("FileError") = type;
    return type.release();
  }();
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const pl::FileError& e) {
      py::object exception = fileError(e.what());
      exception.attr("filename") = e.path();
      PyErr_SetObject(fileError.ptr(), exception.ptr());
    } catch (const pl::UsageError& e) {
      PyErr_SetString(usageError.ptr(), e.what());
    } catch (const pl::Error& e) {
      PyErr_SetString(error.ptr(), e.what());
    }
  });
}

}  // namespace pl::python
