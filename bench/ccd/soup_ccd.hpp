#pragma once
/// \file
/// All contacts of a deforming triangle soup over one linear step, through the runtime: by
/// default a `tetseg::Collider` of the soup in `ColliderMode::kFeatures` (vertex-face and
/// edge-edge candidates from BVHs over per-feature swept boxes, the runtime's filters and
/// elementary tests); `kScene`: one surface-only body of a `tetseg::Scene` (median-split
/// BVH over the swept triangle boxes, self-traversal, feature pairs with four distinct nodes
/// deduplicated exactly, the same filters and tests). By default still feature pairs (four vertices
/// with x0 == x1) are tested too, so the result is every touching pair of the frame; with
/// `StillPairs::kSkip` they are not (the runtime's default rule, docs/runtime.md "Still
/// geometry"). `brute` is an independent reference: all face pairs with overlapping swept
/// boxes, candidate lists deduplicated, elementary tests.

#include <array>
#include <cstdint>
#include <vector>

#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/ccd.hpp"

namespace tetseg::tools::soup {

struct Contact {
  bool vertex_face = true;
  /// vf: vertex, face[0], face[1], face[2] (face order); ee: a, b, c, d with a < b, c < d and
  /// (a, b) < (c, d).
  std::array<std::uint32_t, 4> ids{};
  double toi = 1.0;
};

enum class BroadPhase {
  kFeatures,  ///< the runtime: a Collider in ColliderMode::kFeatures (default)
  kScene,     ///< the runtime: one surface-only scene body (whole-surface BVH)
  kSweep,     ///< sort and sweep along x over swept boxes, the same elementary tests (baseline)
  kBrute,     ///< all face pairs (quadratic; a reference for tests)
};

/// Which feature pairs whose four vertices are all still (x0 == x1 bitwise) are tested.
enum class StillPairs {
  kInclude,  ///< all of them: every pair touching during the step (the frame's exact truth)
  kSkip,     ///< none (the runtime's still rule: such a pair can only touch at t = 0)
};

/// Work of one frame. Sort and sweep: candidates (box-overlapping pairs that share no vertex),
/// thread CPU time of the broad phase and of the pre-filters and elementary tests. Runtime
/// (scene or sweep mode): the `ColliderStats` counts. All: elementary tests run (after the
/// pre-filters).
struct FrameStats {
  std::uint64_t vf_candidates = 0, ee_candidates = 0;
  std::uint64_t orientation_culled = 0;  ///< kScene with an asset: node pairs culled (rvbc)
  double broad_seconds = 0, test_seconds = 0;
  std::uint64_t triangle_pairs = 0, feature_pairs = 0;
  std::uint64_t tests = 0;
};

/// Contacts sorted by kind (vf first), then vertex-face by (vertex, face index) and edge-edge
/// by ids. Vertices not referenced by a face are ignored. Preconditions: face indices <
/// x0.size() == x1.size(). Throws std::runtime_error for a face with a repeated vertex or when
/// the runtime fails. `kBrute` is quadratic (a reference for tests); `stats`
/// (optional) receives the work of the other broad phases. `asset` (kScene only; null: none):
/// the soup is that asset's body (the caller checks that its nodes are the frame's vertices
/// and its triangles the faces, in order) and is culled with its clusters and detectors
/// (rvbc; a kBones asset's detectors stay at their rest positions, which is exact and only
/// culls less); the step is then presumed to start contact-free (docs/runtime.md). `threads`
/// (kFeatures without an asset only): the collider's OpenMP threads (1: serial); the same
/// contacts.
std::vector<Contact> find_contacts(const std::vector<std::array<double, 3>>& x0,
                                   const std::vector<std::array<double, 3>>& x1,
                                   const std::vector<std::array<std::uint32_t, 3>>& faces,
                                   const CcdOptions& options,
                                   BroadPhase broad_phase = BroadPhase::kFeatures,
                                   FrameStats* stats = nullptr,
                                   StillPairs still_pairs = StillPairs::kInclude,
                                   const tetseg::Asset* asset = nullptr, std::uint32_t threads = 1);

/// CPU time of the calling thread, in seconds.
double thread_cpu_seconds();

}  // namespace tetseg::tools::soup
