#pragma once
/// \file
/// The one place where the Python binding calls the C++ collider's and scene's step and
/// queries. Each call returns a ColliderStatus; the binding raises `tetseg.ColliderError`
/// (naming the status) on anything but kOk and never returns an answer from a failed call.
///
/// The queries themselves refuse to answer without a valid step (kNoStep), so no
/// answer of a failed call can look like "no collision".

#include <cstddef>

#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/scene.hpp"

namespace tetseg::python {

inline ColliderStatus call_step(Collider& collider, const double* x0, const double* x1,
                                std::size_t value_count) noexcept {
  return collider.step(x0, x1, value_count);
}

inline ColliderStatus call_any_collision(Collider& collider, bool& any) noexcept {
  return collider.any_collision(any);
}

inline ColliderStatus call_earliest_toi(Collider& collider, EarliestContact& earliest) noexcept {
  return collider.earliest_toi(earliest);
}

inline ColliderStatus call_contacts(Collider& collider, Contact* buffer, std::size_t capacity,
                                    ContactsResult& result) noexcept {
  return collider.contacts(buffer, capacity, result);
}

inline ColliderStatus call_check_rest_intersection(Collider& collider, const double* x,
                                                   std::size_t value_count,
                                                   RestCheck& result) noexcept {
  result = collider.check_rest_intersection(x, value_count);
  return result.status;
}

// Scene: the same queries over all of its bodies.

inline ColliderStatus call_step(Scene& scene, const double* x0, const double* x1,
                                std::size_t value_count) noexcept {
  return scene.step(x0, x1, value_count);
}

inline ColliderStatus call_any_collision(Scene& scene, bool& any) noexcept {
  return scene.any_collision(any);
}

inline ColliderStatus call_earliest_toi(Scene& scene, EarliestContact& earliest) noexcept {
  return scene.earliest_toi(earliest);
}

inline ColliderStatus call_contacts(Scene& scene, Contact* buffer, std::size_t capacity,
                                    ContactsResult& result) noexcept {
  return scene.contacts(buffer, capacity, result);
}

inline ColliderStatus call_check_rest_intersection(Scene& scene, const double* x,
                                                   std::size_t value_count,
                                                   RestCheck& result) noexcept {
  result = scene.check_rest_intersection(x, value_count);
  return result.status;
}

}  // namespace tetseg::python
