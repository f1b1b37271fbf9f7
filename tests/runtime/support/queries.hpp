#pragma once
// Collider queries for tests that expect them to succeed: each REQUIREs kOk and returns the
// answer (a failing status is never read as "no contact").

#include <cstddef>

#include <catch2/catch.hpp>

#include "tetseg/runtime/collider.hpp"

namespace tetseg::test {

inline bool any_ok(Collider& c) {
  bool hit = false;
  REQUIRE(c.any_collision(hit) == ColliderStatus::kOk);
  return hit;
}

inline EarliestContact earliest_ok(Collider& c) {
  EarliestContact e;
  REQUIRE(c.earliest_toi(e) == ColliderStatus::kOk);
  return e;
}

inline ContactsResult contacts_ok(Collider& c, Contact* buffer, std::size_t capacity) {
  ContactsResult r;
  REQUIRE(c.contacts(buffer, capacity, r) == ColliderStatus::kOk);
  return r;
}

}  // namespace tetseg::test
