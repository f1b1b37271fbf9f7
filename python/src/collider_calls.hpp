#pragma once
/// \file
/// The one place where the Python binding calls the C++ step and queries of a `Collider` or a
/// `Scene` (`Engine`: both have the same calls). Each call returns a ColliderStatus; the
/// binding raises `tetseg.ColliderError` (naming the status) on anything but kOk and never
/// returns an answer from a failed call.
///
/// The queries themselves refuse to answer without a valid step (kNoStep), so no
/// answer of a failed call can look like "no collision".

#include <cstddef>

#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/scene.hpp"

namespace tetseg::python {

template <typename Engine>
ColliderStatus call_step(Engine& engine, const double* x0, const double* x1,
                         std::size_t value_count) noexcept {
  return engine.step(x0, x1, value_count);
}

template <typename Engine>
ColliderStatus call_any_collision(Engine& engine, bool& any) noexcept {
  return engine.any_collision(any);
}

template <typename Engine>
ColliderStatus call_earliest_toi(Engine& engine, EarliestContact& earliest) noexcept {
  return engine.earliest_toi(earliest);
}

template <typename Engine>
ColliderStatus call_contacts(Engine& engine, Contact* buffer, std::size_t capacity,
                             ContactsResult& result) noexcept {
  return engine.contacts(buffer, capacity, result);
}

template <typename Engine>
ColliderStatus call_check_rest_intersection(Engine& engine, const double* x,
                                            std::size_t value_count, RestCheck& result) noexcept {
  result = engine.check_rest_intersection(x, value_count);
  return result.status;
}

}  // namespace tetseg::python
