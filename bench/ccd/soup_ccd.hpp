#pragma once
/// \file
/// All contacts of a deforming triangle soup over one linear step, through the runtime: the
/// soup is one surface-only body of a `tetseg::Scene` (median-split BVH over the swept
/// triangle boxes, self-traversal, feature pairs with four distinct nodes deduplicated exactly,
/// the runtime's filters and elementary tests; feature pairs whose four vertices do not move
/// are not tested, docs/runtime.md "Still geometry"). `brute` is an independent reference: all
/// face pairs with overlapping swept boxes, candidate lists deduplicated, elementary tests.

#include <array>
#include <cstdint>
#include <vector>

#include "tetseg/runtime/ccd.hpp"

namespace tetseg::tools::soup {

struct Contact {
  bool vertex_face = true;
  /// vf: vertex, face[0], face[1], face[2] (face order); ee: a, b, c, d with a < b, c < d and
  /// (a, b) < (c, d).
  std::array<std::uint32_t, 4> ids{};
  double toi = 1.0;
};

/// Contacts sorted by kind (vf first), then vertex-face by (vertex, face index) and edge-edge
/// by ids. Vertices not referenced by a face are ignored. Preconditions: face indices <
/// x0.size() == x1.size(). Throws std::runtime_error for a face with a repeated vertex or when
/// the runtime fails. `brute` is quadratic (a reference for tests).
std::vector<Contact> find_contacts(const std::vector<std::array<double, 3>>& x0,
                                   const std::vector<std::array<double, 3>>& x1,
                                   const std::vector<std::array<std::uint32_t, 3>>& faces,
                                   const CcdOptions& options, bool brute = false);

}  // namespace tetseg::tools::soup
