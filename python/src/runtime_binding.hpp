#pragma once
/// \file
/// What the bindings of `tetseg.Collider` (runtime_module.cpp) and `tetseg.Scene`
/// (scene_binding.cpp) share: the exception classes, the contact dtype, the position-array
/// checks, the one-thread-at-a-time guard and the queries of a step (GIL released, a
/// `tetseg.ColliderError` naming the status for anything but kOk).

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "collider_calls.hpp"
#include "python_errors.hpp"
#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/collider.hpp"

namespace tetseg::python {

using AssetPtr = std::shared_ptr<const Asset>;

/// A loaded asset (`tetseg.Asset`).
struct PyAsset {
  AssetPtr asset;
};

struct Errors {
  py::object asset, collider, frames;
};
/// The exception classes, created when the module is imported (runtime_module.cpp).
Errors& errors();

/// The dtype of `tetseg::Contact`, so the runtime writes contacts straight into NumPy memory.
py::dtype contact_dtype();

/// `positions_of` row count meaning "any number of rows" (the global arrays of a scene).
inline constexpr std::size_t kAnyRows = ~std::size_t(0);

/// Checks that `object` is a (rows, 3) C-contiguous, aligned float64 array and returns its
/// data; `rows_meaning` explains the expected row count in messages. Raises TypeError (not an
/// array, wrong dtype) or ValueError (shape, layout).
inline const double* positions_of(const char* name, const py::handle& object, std::size_t rows,
                                  const char* rows_meaning) {
  const std::string expected =
      "(" + (rows == kAnyRows ? std::string("n") : std::to_string(rows)) + ", 3)";
  if (!py::isinstance<py::array>(object)) {
    throw py::type_error(std::string(name) + " must be a numpy.ndarray of float64 with shape " +
                         expected + ", got " +
                         std::string(py::str(py::type::handle_of(object).attr("__name__"))));
  }
  const auto array = py::reinterpret_borrow<py::array>(object);
  if (!array.dtype().equal(py::dtype::of<double>())) {
    throw py::type_error(std::string(name) + " must have dtype float64 (native byte order), got " +
                         std::string(py::str(array.dtype())) +
                         " (convert with numpy.ascontiguousarray(x, dtype=numpy.float64))");
  }
  if (array.ndim() != 2 || array.shape(1) != 3 ||
      (rows != kAnyRows && array.shape(0) != static_cast<py::ssize_t>(rows))) {
    throw py::value_error(std::string(name) + " must have shape " + expected + " (" + rows_meaning +
                          "), got " + std::string(py::str(array.attr("shape"))));
  }
  const int flags = py::detail::array_proxy(array.ptr())->flags;
  if (!(flags & py::detail::npy_api::NPY_ARRAY_C_CONTIGUOUS_) ||
      !(flags & py::detail::npy_api::NPY_ARRAY_ALIGNED_)) {
    throw py::value_error(std::string(name) +
                          " must be C-contiguous and aligned (it is used in place, not copied); "
                          "use numpy.ascontiguousarray(x)");
  }
  return static_cast<const double*>(array.data());
}

/// Checks a (clusters, 3) array of detector positions (as `positions_of`) and returns its data.
inline const double* detector_positions_of(const char* name, const py::handle& object,
                                           std::size_t clusters) {
  return positions_of(name, object, clusters, "the asset's cluster count");
}

/// Rows of an array that passed `positions_of`.
inline std::size_t rows_of(const py::handle& checked) {
  return static_cast<std::size_t>(py::reinterpret_borrow<py::array>(checked).shape(0));
}

/// Refuses concurrent use of one collider or scene from several Python threads (the GIL is
/// released during steps and queries; the C++ objects are single-threaded).
class Busy {
 public:
  Busy(std::mutex& m, const char* owner) : m_lock(m, std::try_to_lock) {
    if (!m_lock.owns_lock())
      throw std::runtime_error(std::string("this ") + owner +
                               " is in use by another thread; use one " + owner + " per thread");
  }

 private:
  std::unique_lock<std::mutex> m_lock;
};

/// Detail of a failed step or static check.
inline std::string step_failure_detail(ColliderStatus status) {
  switch (status) {
    case ColliderStatus::kNonFinite:
      return "a position of a surface or detector node is NaN or infinite (step rejected)";
    case ColliderStatus::kSizeMismatch:
      return "position count differs from node_count * 3";
    case ColliderStatus::kNullInput:
      return "the asset's detectors are carried by bones: call set_detector_positions(d0, d1) "
             "first";
    default:
      return "";
  }
}

py::dict stats_dict(const ColliderStats& s);
/// intersecting, triangle_a, triangle_b, bodies (the witnesses' bodies).
py::dict rest_check_dict(const RestCheck& r);

/// Adds `BodyShape` and `Scene` to the module (scene_binding.cpp).
void bind_scene(py::module_& m);

/// The guard and the queries of one collider or scene (`Engine`: Collider or Scene, through
/// collider_calls.hpp). Records the outcome of the last step so that a refused query says why.
class StepQueries {
 public:
  /// `owner`: "Collider" or "Scene"; `step_call`: how to start a step, for messages.
  StepQueries(const char* owner, const char* step_call) : m_owner(owner), m_step_call(step_call) {}

  /// Held for the whole of any call that touches the C++ object.
  Busy lock() { return Busy(m_mutex, m_owner); }

  /// Records the status of the last `step`.
  void stepped(ColliderStatus status) {
    m_refuse = status != ColliderStatus::kOk;
    m_reason = !m_refuse ? std::string()
                         : std::string("the last step failed (") + to_string(status) + "): call " +
                               m_step_call + " with valid positions first";
  }
  /// No query until the next successful step (`reason` says why). The binding refuses them
  /// itself, whether or not the C++ object would.
  void invalidated(std::string reason) {
    m_refuse = true;
    m_reason = std::move(reason);
  }

  template <typename Engine>
  bool any_collision(Engine& engine) {
    Busy busy = lock();
    refuse_without_step("any_collision");
    bool any = false;
    ColliderStatus status;
    {
      py::gil_scoped_release release;
      status = call_any_collision(engine, any);
    }
    check_query("any_collision", status);
    return any;
  }

  template <typename Engine>
  py::object earliest_toi(Engine& engine) {
    Busy busy = lock();
    refuse_without_step("earliest_toi");
    EarliestContact earliest;
    ColliderStatus status;
    {
      py::gil_scoped_release release;
      status = call_earliest_toi(engine, earliest);
    }
    check_query("earliest_toi", status);
    if (!earliest.found) return py::none();
    py::array one(contact_dtype(), std::vector<py::ssize_t>{1});
    std::memcpy(one.mutable_data(), &earliest.contact, sizeof(Contact));
    return one[py::int_(0)];
  }

  template <typename Engine>
  py::array contacts(Engine& engine) {
    Busy busy = lock();
    refuse_without_step("contacts");
    std::size_t capacity = m_contacts_capacity;
    for (int attempt = 0; attempt < 3; ++attempt) {
      py::array out(contact_dtype(), std::vector<py::ssize_t>{static_cast<py::ssize_t>(capacity)});
      auto* buffer = static_cast<Contact*>(out.mutable_data());
      ContactsResult result;
      ColliderStatus status;
      {
        py::gil_scoped_release release;
        status = call_contacts(engine, buffer, capacity, result);
      }
      check_query("contacts", status);
      if (!result.truncated()) {
        out.resize({static_cast<py::ssize_t>(result.written)});
        return out;
      }
      capacity = result.found;  // a deterministic step finds the same contacts again
      m_contacts_capacity = capacity;
    }
    raise_status(errors().collider, "contacts", to_string(ColliderStatus::kInternal),
                 "the contact count changed between two traversals of one step");
  }

 private:
  void refuse_without_step(const char* what) const {
    if (m_refuse)
      raise_status(errors().collider, what, to_string(ColliderStatus::kNoStep), m_reason);
  }

  void check_query(const char* what, ColliderStatus status) const {
    if (status == ColliderStatus::kOk) return;
    std::string detail = m_reason;
    if (status == ColliderStatus::kOverflow)
      detail = "the traversal stack overflowed (traversal_stack too small): answer unknown";
    raise_status(errors().collider, what, to_string(status), detail);
  }

  const char* m_owner;
  const char* m_step_call;
  bool m_refuse = true;
  std::string m_reason = std::string("no step yet: call ") + m_step_call + " first";
  std::size_t m_contacts_capacity = 256;
  std::mutex m_mutex;
};

}  // namespace tetseg::python
