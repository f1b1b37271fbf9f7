#pragma once
/// \file
/// The scene oracle's feature pairs (scene_oracle.hpp) decided by the exact rational CCD
/// oracle (exact_ccd.hpp) instead of the runtime's elementary tests: the exact contacts of a
/// step, against which the floating-point answers are held (nothing missed, no time of impact
/// after the exact one). Tests only (GMP).

#include <vector>

#include "tetseg/testing/exact_ccd.hpp"
#include "tetseg/testing/scene_oracle.hpp"

namespace tetseg::test {

/// Every feature pair of the step that touches at some t in [0, 1] (exactly), named as the
/// runtime names them; `toi` is the exact first contact time rounded up. Sorted by
/// `contact_less`.
inline std::vector<Contact> scene_exact_contacts(const std::vector<OracleBody>& bodies) {
  std::vector<Contact> out;
  auto add = [&](ContactKind kind, std::uint32_t ba, std::uint32_t bb,
                 std::array<std::uint32_t, 4> nodes, std::uint32_t tri, const ExactCcd& r) {
    if (!r.hit) return;
    Contact c;
    c.kind = kind;
    c.bodies = {ba, bb};
    c.nodes = nodes;
    c.triangle = tri;
    c.at_start = r.at_start;
    c.toi = r.toi_upper;
    out.push_back(c);
  };
  auto at = [&](std::uint32_t b, std::uint32_t n, bool end) {
    return oracle_point(bodies[b], n, end);
  };
  for_each_feature_pair(
      bodies,
      [&](std::uint32_t vb, std::uint32_t p, std::uint32_t fb, std::uint32_t tri,
          const std::array<std::uint32_t, 3>& F) {
        add(ContactKind::kVertexFace, vb, fb, {p, F[0], F[1], F[2]}, tri,
            exact_vertex_face(at(vb, p, false), at(fb, F[0], false), at(fb, F[1], false),
                              at(fb, F[2], false), at(vb, p, true), at(fb, F[0], true),
                              at(fb, F[1], true), at(fb, F[2], true)));
      },
      [&](std::uint32_t eb, std::uint32_t a, std::uint32_t b, std::uint32_t gb, std::uint32_t c,
          std::uint32_t d) {
        add(ContactKind::kEdgeEdge, eb, gb, {a, b, c, d}, 0,
            exact_edge_edge(at(eb, a, false), at(eb, b, false), at(gb, c, false), at(gb, d, false),
                            at(eb, a, true), at(eb, b, true), at(gb, c, true), at(gb, d, true)));
      });
  std::sort(out.begin(), out.end(), contact_less);
  return out;
}

}  // namespace tetseg::test
