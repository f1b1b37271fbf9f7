#pragma once
/// \file
/// Continuous collision queries over several bodies in one runtime (docs/runtime.md, "Scenes").
/// Bodies: a tet or surface body from an asset (radial-view culling inside it), a surface-only body
/// (a triangle mesh with no asset: obstacles, cloth, shells, soups; overlap culling only); any body
/// may be still. Per step: the self-collision of each body plus every pair of bodies whose swept
/// boxes overlap, culled hierarchically (body boxes, then BVH against BVH); a pair of still bodies
/// costs nothing. Same guarantees as `Collider`: scratch allocated when bodies are added, no
/// allocation per step, no exceptions, every query returns a status.
///
/// Thread safety: one `Scene` per thread; shapes (`BodyShape`) may be shared across scenes.

#include <cstddef>
#include <cstdint>
#include <memory>

#include "tetseg/runtime/body_shape.hpp"
#include "tetseg/runtime/collider.hpp"

namespace tetseg {

struct SceneOptions {
  /// Passed to the elementary tests (as in `ColliderOptions::ccd`).
  CcdOptions ccd;
  /// As `ColliderOptions::include_still_pairs`, for every body and pair of bodies: still
  /// feature pairs (still bodies included) are tested too. Off by default (the still rule).
  bool include_still_pairs = false;
  /// Leaf size of whole-surface BVHs (surface-only bodies, `kBvh` bodies).
  std::uint32_t bvh_leaf_size = 4;
  /// OpenMP threads (when built with it): inside each body's self-collision queries (as
  /// `ColliderOptions::use_openmp`), and over the pairs of bodies (one pair per task, a worker
  /// with its own stack per thread, outcomes merged in pair order; a contact buffer is shared
  /// by all parts and keeps the smallest contacts, as `Collider::contacts`). Results and counts
  /// are identical to serial ones. Off by default.
  bool use_openmp = false;
  /// As `ColliderOptions::threads` (0: OpenMP's default).
  std::uint32_t threads = 0;
  /// As `ColliderOptions::time_tests` (off by default).
  bool time_tests = false;
  /// Traversal stack capacity in node pairs (0: never overflows). Small values are for tests.
  std::uint32_t traversal_stack = 0;
};

/// `BodyOptions::global_offset` of a body whose positions come in its own arrays.
inline constexpr std::size_t kOwnPositions = ~std::size_t(0);

struct BodyOptions {
  /// Self-collision method: `kRvbc` (default; a surface-only body uses `kBvh`), `kBvh` or
  /// `kCone`. Between bodies the body's BVHs (cluster BVHs for `kRvbc`, else its whole-surface
  /// BVH) are culled by overlap only. `kBrute` and `kFeatures` are rejected (kInvalidArgument).
  ColliderMode mode = ColliderMode::kRvbc;
  /// The body never moves: only its `x0` is read (x1 may be null), for both ends of every step.
  bool still = false;
  /// Test the body against itself (off: rigid obstacles, bodies that cannot fold).
  bool self_collision = true;
  /// Positions layout: `kOwnPositions` (set with `Scene::set_positions`), or the index of the
  /// body's node 0 in the global arrays passed to `Scene::step` (node i at global node
  /// global_offset + i). Contacts always carry the body's local node ids.
  std::size_t global_offset = kOwnPositions;
};

/// Scene-wide figures of the current step (reset by `step`, accumulated over its queries).
struct SceneStats {
  double refit_ms = 0, classify_ms = 0;  ///< sums over the bodies
  double self_ms = 0;                    ///< self-collision queries of all bodies
  double pairs_ms = 0;                   ///< inter-body traversal and tests
  std::uint64_t bodies_moved = 0;
  std::uint64_t body_pairs_tested = 0;   ///< pairs traversed BVH against BVH (last full query)
  std::uint64_t body_pairs_skipped = 0;  ///< disabled, both still, or body boxes apart
  std::uint64_t contacts = 0;            ///< elementary tests that reported contact
  /// Threads that ran the last inter-body traversal (1 when serial; see ColliderStats).
  std::uint32_t pair_threads = 0;
};

class Scene {
 public:
  explicit Scene(const SceneOptions& options = {}) noexcept;
  ~Scene();
  Scene(Scene&&) noexcept;
  Scene& operator=(Scene&&) noexcept;
  Scene(const Scene&) = delete;
  Scene& operator=(const Scene&) = delete;

  /// Adds a body over `shape` (non-null) and allocates its scratch. Its id (0, 1, ... in
  /// order of addition) goes to `*id` when given. Every pair with the new body is enabled.
  /// kInvalidArgument for a null shape, `kBrute` or `kFeatures`; kNotReady when out of memory.
  /// Invalidates the current step.
  ColliderStatus add_body(std::shared_ptr<const BodyShape> shape, const BodyOptions& options,
                          std::uint32_t* id = nullptr) noexcept;
  std::uint32_t body_count() const noexcept;

  /// Switches a body's self-collision (kInvalidArgument for an unknown body).
  ColliderStatus set_self_collision(std::uint32_t body, bool enabled) noexcept;
  /// Switches the collision between bodies a != b (kInvalidArgument otherwise).
  ColliderStatus set_pair_enabled(std::uint32_t a, std::uint32_t b, bool enabled) noexcept;

  /// Positions of a body with its own arrays: node_count * 3 doubles each, `value_count` must
  /// be node_count * 3; x1 may be null for a still body. The scene keeps the pointers for
  /// the following steps: the arrays must stay valid until replaced or the scene is gone.
  /// Checked at `step` (kNullInput, kNonFinite); kInvalidArgument for an unknown body or a
  /// body of the global layout, kSizeMismatch for a wrong count. Ends the current step:
  /// queries answer kNoStep until the next `step`.
  ColliderStatus set_positions(std::uint32_t body, const double* x0, const double* x1,
                               std::size_t value_count) noexcept;

  /// Detector positions of a body over a kBones asset, as `Collider::set_detector_positions`
  /// (kept and read at every step; kInvalidArgument for an unknown body or another form).
  ColliderStatus set_detector_positions(std::uint32_t body, const double* d0, const double* d1,
                                        std::size_t value_count) noexcept;

  /// Starts a step `x(t) = (1-t) x0 + t x1` of every body: `x0`/`x1`/`value_count` are the
  /// global arrays read by the bodies with a `global_offset` (may be null when there are
  /// none; x1 may be null when all of those are still). Validates every body's positions
  /// (kNullInput, kSizeMismatch when a body's range exceeds value_count, kNonFinite), then
  /// refits every body and classifies the moving ones. On failure no step is valid.
  ColliderStatus step(const double* x0 = nullptr, const double* x1 = nullptr,
                      std::size_t value_count = 0) noexcept;

  /// The queries of `Collider` over the whole scene: self contacts of every body with
  /// self-collision on, and contacts between the bodies of every enabled pair. Statuses and
  /// guarantees as in `Collider` (a failure leaves an empty answer: never "no contact").
  [[nodiscard]] ColliderStatus any_collision(bool& hit) noexcept;
  [[nodiscard]] ColliderStatus earliest_toi(EarliestContact& out) noexcept;
  [[nodiscard]] ColliderStatus contacts(Contact* buffer, std::size_t capacity,
                                        ContactsResult& out) noexcept;

  /// Static check of a start state (culling inside tet bodies assumes it is free of
  /// intersections): does a body with self-collision on touch itself, or an enabled pair of
  /// bodies touch each other, at positions `x` (the global array, `value_count` values, for
  /// bodies with a `global_offset`; the own arrays' x0 for the others)? Conservative as
  /// `Collider::check_rest_intersection` (within a body edge-adjacent triangles are not
  /// checked); the witness names its bodies. Statuses as `step` (and kOverflow); it reuses the
  /// step scratch: call it before `step`, not between `step` and the queries.
  RestCheck check_rest_intersection(const double* x = nullptr,
                                    std::size_t value_count = 0) noexcept;

  const SceneStats& stats() const noexcept;
  /// Self-collision statistics of a body in the current step (empty for an unknown body).
  const ColliderStats& body_stats(std::uint32_t body) const noexcept;
  /// Statistics of the pair (a, b) in the current step: node pairs, triangle pairs, feature
  /// pairs and tests, contacts between the two bodies (empty for an invalid pair).
  const ColliderStats& pair_stats(std::uint32_t a, std::uint32_t b) const noexcept;

  struct Impl;

 private:
  std::unique_ptr<Impl> m_impl;
};

}  // namespace tetseg
