#pragma once
/// \file
/// Exceptions that carry a library status: `tetseg.AssetError`, `tetseg.ColliderError`, ...
/// Each is a Python class with `status` (the library's short status name) and `detail`
/// attributes; the message reads "<what>: <status>: <detail>".

#include <pybind11/pybind11.h>

#include <string>

namespace tetseg::python {

namespace py = pybind11;

/// Creates exception class `<package>.<name>` deriving from `base`, adds it to `module`.
inline py::object add_status_exception(py::module_& module, const char* package, const char* name,
                                       PyObject* base, const char* doc) {
  const std::string qualified = std::string(package) + "." + name;
  PyObject* type = PyErr_NewExceptionWithDoc(qualified.c_str(), doc, base, nullptr);
  if (type == nullptr) throw py::error_already_set();
  py::object cls = py::reinterpret_steal<py::object>(type);
  module.add_object(name, cls);
  return cls;
}

/// Raises an instance of `cls` with attributes `status` and `detail`.
[[noreturn]] inline void raise_status(const py::object& cls, const std::string& what,
                                      const std::string& status, const std::string& detail) {
  std::string message = what + ": " + status;
  if (!detail.empty()) message += ": " + detail;
  py::object error = cls(message);
  error.attr("status") = status;
  error.attr("detail") = detail;
  PyErr_SetObject(cls.ptr(), error.ptr());
  throw py::error_already_set();
}

}  // namespace tetseg::python
