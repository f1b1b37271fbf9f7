#pragma once
// Records the largest single operator-new request made while a probe is active, so tests can
// show that hostile sizes are rejected before anything is allocated. The replacement global
// operator new/delete live in allocation_probe.cpp (this test executable only).

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
};

}  // namespace tetseg::test
