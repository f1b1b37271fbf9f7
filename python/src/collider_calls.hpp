#pragma once
/// \file
/// The one place where the Python binding calls the C++ collider's step and queries. Each
/// call returns a ColliderStatus; the binding raises `tetseg.ColliderError` (naming the
/// status) on anything but kOk and never returns an answer from a failed call.
///
/// Today's `any_collision()` and `earliest_toi()` return plain answers (false / not found)
/// when there is no valid step, which would look like "no collision". So the binding keeps
/// the status of the last `step` and these calls refuse to query without a valid one. When
/// the collider's queries return statuses themselves, adapt the bodies below only.

#include <cstddef>

#include "tetseg/runtime/collider.hpp"

namespace tetseg::python {

inline ColliderStatus call_step(Collider& collider, const double* x0, const double* x1,
                                std::size_t value_count) noexcept {
  return collider.step(x0, x1, value_count);
}

inline ColliderStatus call_any_collision(Collider& collider, ColliderStatus last_step,
                                         bool& any) noexcept {
  if (last_step != ColliderStatus::kOk) return ColliderStatus::kNotReady;
  any = collider.any_collision();
  return ColliderStatus::kOk;
}

inline ColliderStatus call_earliest_toi(Collider& collider, ColliderStatus last_step,
                                        EarliestContact& earliest) noexcept {
  if (last_step != ColliderStatus::kOk) return ColliderStatus::kNotReady;
  earliest = collider.earliest_toi();
  return ColliderStatus::kOk;
}

inline ColliderStatus call_contacts(Collider& collider, ColliderStatus last_step, Contact* buffer,
                                    std::size_t capacity, ContactsResult& result) noexcept {
  if (last_step != ColliderStatus::kOk) return ColliderStatus::kNotReady;
  result = collider.contacts(buffer, capacity);
  return result.status;
}

inline ColliderStatus call_check_rest_intersection(Collider& collider, const double* x,
                                                   std::size_t value_count,
                                                   RestCheck& result) noexcept {
  result = collider.check_rest_intersection(x, value_count);
  return result.status;
}

}  // namespace tetseg::python
