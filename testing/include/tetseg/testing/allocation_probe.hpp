#pragma once
// Records the operator-new requests made while a probe is active: how many, and the largest,
// so tests can show that hostile sizes are rejected before anything is allocated and that a
// collider step allocates nothing. The replacement global operator new/delete live in
// allocation_probe.cpp, linked into the format and runtime test executables.

#include <cstddef>

namespace tetseg::test {

class AllocationProbe {
 public:
  AllocationProbe();   ///< starts recording (one probe at a time, test thread only)
  ~AllocationProbe();  ///< stops recording
  AllocationProbe(const AllocationProbe&) = delete;
  AllocationProbe& operator=(const AllocationProbe&) = delete;
  /// Largest request in bytes since construction.
  std::size_t largest() const;
  /// Number of requests since construction.
  std::size_t count() const;
};

}  // namespace tetseg::test
