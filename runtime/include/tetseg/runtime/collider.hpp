#pragma once
/// \file
/// Per-frame continuous self-collision queries for the surface of one deformable object, a
/// tet body or a surface body (asset format 1.2) (paper section V; docs/runtime.md). A `Collider`
/// is built once from an `Asset`, allocates all of its scratch memory in the constructor, and then
/// answers queries for each step `x(t) = (1-t) x0 + t x1`, t in [0,1], without allocating.
///
/// Usage per step: `step(x0, x1)`, then any of `any_collision(hit)`, `earliest_toi(e)`,
/// `contacts(buffer, capacity, r)`, each returning a status. Queries do only the work they
/// need and share results within a step.
///
/// Thread safety: one `Collider` is used by one thread at a time. Several colliders may share
/// one `Asset` (read-only) across threads. No function throws; failures are statuses.

#include <array>
#include <cstddef>
#include <cstdint>
#include <memory>

#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/body_shape.hpp"
#include "tetseg/runtime/ccd.hpp"
#include "tetseg/runtime/classify.hpp"

namespace tetseg {

/// How candidate feature pairs are found. All modes use the same elementary tests.
enum class ColliderMode : std::uint8_t {
  kRvbc = 0,   ///< per-cluster BVHs + radial-view orientation culling (default)
  kBvh = 1,    ///< one BVH over the whole surface, overlap culling only
  kBrute = 2,  ///< every feature pair with 4 distinct nodes and overlapping swept boxes
  kCone = 3,   ///< baseline: `kBvh` + continuous normal cones and contour tests (ICCD-like)
  /// Per-feature BVHs: vertex-face and edge-edge candidates straight from trees over the swept
  /// boxes of the vertices, edges and triangles (rebuilt every step), overlap culling only,
  /// no triangle pairs and no orphan sets: for triangle soups and contact-rich steps
  /// (docs/runtime.md, "Features mode"). One thread. Not a scene body mode.
  kFeatures = 4,
};

/// Short stable name: "rvbc", "bvh", "brute", "cone", "features".
const char* to_string(ColliderMode mode) noexcept;
/// Parses a name of `to_string`; false when unknown.
bool parse_collider_mode(const char* name, ColliderMode& out) noexcept;

/// Status of every collider and scene call. Only kOk comes with an answer: a query that does
/// not return kOk leaves its out parameter empty, and that is not "no contact".
enum class ColliderStatus : std::uint8_t {
  kOk = 0,
  kNotReady,         ///< construction failed (out of memory); every call fails
  kNullInput,        ///< a position pointer is null
  kSizeMismatch,     ///< value count differs from node_count * 3
  kNonFinite,        ///< a position is NaN or infinite (step rejected, previous state dropped)
  kInternal,         ///< an internal inconsistency (never expected; not returned by the runtime)
  kNoStep,           ///< query without a valid step (none yet, or the last one was rejected)
  kOverflow,         ///< traversal stack exceeded (`traversal_stack` too small): answer unknown
  kInvalidArgument,  ///< scene: unknown body id, body pair or layout
};
const char* to_string(ColliderStatus status) noexcept;

struct ColliderOptions {
  ColliderMode mode = ColliderMode::kRvbc;
  /// Passed to the elementary tests. With `min_separation > 0` swept boxes are inflated and
  /// the coplanarity filter is off, but orientation culling (rvbc) still only guarantees
  /// exact contacts: use `kBvh` when every near contact must be found.
  CcdOptions ccd;
  /// Test still feature pairs too (all four nodes with x0 == x1 bitwise), which the default
  /// still rule of `step` skips (docs/runtime.md, "Still geometry"): still clusters, still
  /// node pairs and steps where nothing moved are then traversed like moving ones, and kBvh,
  /// kCone and kBrute report every contact a brute-force test of all feature pairs reports,
  /// still pairs included. kRvbc keeps its orientation culling, which presumes a contact-free
  /// start: a still pair already touching inside one cluster may stay culled (use kBvh when a
  /// step may start in contact, e.g. a soup frame or a resting pile). Off by default.
  bool include_still_pairs = false;
  /// Leaf size of the `kBvh` mode's BVH (clamped to [1, 16]).
  std::uint32_t bvh_leaf_size = 4;
  /// Use OpenMP threads inside a step when built with it: refit and classification loops
  /// (large meshes), and the traversal of every query (`any_collision`, `earliest_toi`,
  /// `contacts` with or without a buffer) in rvbc (items of the cluster BVHs per task, handed
  /// from a busy thread to an idle one), bvh and cone
  /// (subtrees of the whole-surface BVH per task) and brute modes (features per task).
  /// Results are identical to serial, contact buffers included (merged in a fixed order; a
  /// buffer keeps the smallest contacts, whichever thread finds them: `contacts`). Scratch per
  /// thread is allocated at construction. Off by default.
  bool use_openmp = false;
  /// Threads with `use_openmp`: 0 (default) takes OpenMP's default (`omp_get_max_threads`,
  /// OMP_NUM_THREADS); ignored without OpenMP.
  std::uint32_t threads = 0;
  /// Run `check_rest_intersection` on the start positions of the first step (cost: one
  /// overlap-only traversal with static triangle tests). Result in `rest_intersection()`.
  bool check_first_step = false;
  /// Time the elementary tests separately (two clock reads per test, which cost about 1 % of
  /// a step). Off by default: test time is then counted as traversal and `tests_ms` is 0.
  bool time_tests = false;
  /// Traversal stack capacity in node pairs; 0 (default) sizes it from the BVH depths so that
  /// it never overflows. A smaller value is for tests: queries then fail with kOverflow.
  std::uint32_t traversal_stack = 0;
};

enum class ContactKind : std::uint8_t {
  kVertexFace = 0,  ///< nodes = {p, a, b, c}: vertex p against triangle (a, b, c)
  kEdgeEdge = 1,    ///< nodes = {a, b, c, d}: edge (a, b) against edge (c, d)
};

/// One feature pair found in contact. Node ids are local to their body: `nodes[0]` (the vertex,
/// or edge (a, b)) belongs to body `bodies[0]`, the rest (the face, or edge (c, d)) to
/// `bodies[1]` (a `Collider` is body 0; a `Scene` numbers its bodies). Edges are normalised:
/// a < b, c < d, and within one body (a, b) < (c, d) lexicographically.
struct Contact {
  ContactKind kind = ContactKind::kVertexFace;
  std::array<std::uint32_t, 2> bodies{};
  std::array<std::uint32_t, 4> nodes{};
  std::uint32_t triangle = 0;  ///< vertex-face: the face's triangle id (in its body)
  double toi = 1.0;            ///< lower bound on the first contact time in [0,1]
  bool at_start = false;       ///< touching at t = 0 (toi == 0)
};

/// Strict total order used for deterministic results: by toi, then kind, bodies, nodes.
bool contact_less(const Contact& a, const Contact& b) noexcept;

struct EarliestContact {
  bool found = false;
  Contact contact;  ///< valid when found: the smallest contact in `contact_less` order
};

struct ContactsResult {
  std::size_t found = 0;    ///< contacts found in this step (all of them)
  std::size_t written = 0;  ///< min(found, capacity): written to the buffer
  bool truncated() const noexcept { return found > written; }
};

/// Counts and times of the current step (reset by `step`; queries add to them).
struct ColliderStats {
  double refit_ms = 0, classify_ms = 0, traversal_ms = 0, tests_ms = 0;
  /// kCone: normal-cone update (contour tests count as traversal)
  double cone_ms = 0;
  std::uint64_t nodes_moved = 0;
  std::uint64_t triangles_positive = 0, triangles_negative = 0, triangles_uncertain = 0;
  std::uint64_t triangles_moving = 0;
  std::uint64_t clusters_skipped = 0;  ///< intra-cluster work skipped (one sign / static)
  /// kRvbc: orientation-culled triangle pairs around the earliest contacts re-examined by the
  /// contact closure (docs/runtime.md)
  std::uint64_t closure_pairs = 0;
  std::uint64_t node_pairs_visited = 0;  ///< BVH node pairs popped (rvbc: 4-wide items)
  std::uint64_t node_pairs_orientation_culled = 0;
  std::uint64_t triangle_pairs = 0;  ///< non-culled triangle pairs examined
  /// of those, dropped by the triangle-pair plane filter (no feature pair can touch;
  /// min_separation = 0 only)
  std::uint64_t triangle_pairs_plane_filtered = 0;
  std::uint64_t feature_pairs = 0;           ///< distinct feature pairs whose boxes overlap
  std::uint64_t feature_pairs_filtered = 0;  ///< of those, rejected by the coplanarity filter
  std::uint64_t feature_tests = 0;           ///< elementary tests run
  std::uint64_t contacts = 0;                ///< elementary tests that reported contact
  bool nothing_moved = false;
  bool full_traversal = false;  ///< a complete traversal ran this step
  /// Threads that ran the last query's traversal: 1 on the serial path, the OpenMP team size
  /// on a parallel one (use_openmp).
  std::uint32_t traversal_threads = 0;
  /// Threads that classified the last step's triangles (rvbc): 1 serially, the OpenMP team
  /// size with use_openmp on a body of at least 1,024 triangles; 0 when nothing was classified.
  std::uint32_t step_threads = 0;
};

/// Result of a static intersection check of the surface at one instant.
struct RestCheck {
  ColliderStatus status = ColliderStatus::kOk;
  bool intersecting = false;                     ///< some pair of triangles may intersect or touch
  std::uint32_t triangle_a = 0, triangle_b = 0;  ///< a witness pair when intersecting
  /// The witnesses' bodies: triangle_a is in bodies[0], triangle_b in bodies[1] ({0, 0} for a
  /// Collider).
  std::array<std::uint32_t, 2> bodies{};
};

class Collider {
 public:
  /// Builds the collider and allocates all scratch memory. `asset` must outlive the collider
  /// and stay unchanged. On allocation failure `status()` is kNotReady and every call fails.
  Collider(const Asset& asset, const ColliderOptions& options = {}) noexcept;
  /// Same over a shared, prebuilt topology (`BodyShape::from_asset` or, for a surface-only
  /// mesh, `from_triangles`: no clusters, so `kRvbc` runs as `kBvh`). Null shape: kNotReady.
  Collider(std::shared_ptr<const BodyShape> shape, const ColliderOptions& options = {}) noexcept;
  ~Collider();
  Collider(Collider&&) noexcept;
  Collider& operator=(Collider&&) noexcept;
  Collider(const Collider&) = delete;
  Collider& operator=(const Collider&) = delete;

  /// kOk when constructed, else kNotReady.
  ColliderStatus status() const noexcept;
  const ColliderOptions& options() const noexcept;

  /// Starts a step. `x0`, `x1`: node_count * 3 doubles each (xyz per tet-mesh node, length
  /// units), `value_count` must equal node_count * 3. The collider keeps the pointers: both
  /// arrays must stay valid and unchanged until the next `step` (queries read them).
  /// Refits and classifies (rvbc). Nodes with x0 == x1 (bitwise) are "still".
  /// Rule for still geometry (default; `ColliderOptions::include_still_pairs` turns it off):
  /// a feature pair whose four nodes are all still is never tested (it can only touch during the
  /// whole step, i.e. at t = 0, which the previous step or `check_rest_intersection` reports); so
  /// still clusters, pairs of still clusters and a step where nothing moved cost no traversal.
  /// Rejects NaN/inf positions of the nodes it reads (surface and detector nodes; no other node is
  /// read). Detectors of a kSurfaceWeights asset are evaluated from x0 and x1; those of a kBones
  /// asset are read from the arrays given to `set_detector_positions` by every kRvbc step
  /// (kNullInput when never given, kNonFinite for NaN/inf in a classified cluster's entries;
  /// other modes classify nothing and do not read them).
  ColliderStatus step(const double* x0, const double* x1, std::size_t value_count) noexcept;
  /// Same with value_count = node_count * 3 assumed.
  ColliderStatus step(const double* x0, const double* x1) noexcept;

  /// Whether any feature pair is in contact during the step, into `hit`. Stops at the first
  /// contact unless a full traversal already ran. Every query returns kOk with its answer,
  /// or kNotReady / kNoStep (no valid step) / kOverflow with an empty answer (`hit` false,
  /// `found` false, zero counts) that must not be read as "no contact".
  [[nodiscard]] ColliderStatus any_collision(bool& hit) noexcept;
  /// The earliest contact of the step (deterministic: smallest in `contact_less`).
  /// Runs a full traversal once per step; later queries reuse it.
  [[nodiscard]] ColliderStatus earliest_toi(EarliestContact& out) noexcept;
  /// All contacts of the step into a caller-owned buffer, without allocating: `out.found`
  /// counts all of them and `out.written` = min(found, capacity) are written, sorted with
  /// `contact_less`. When truncated (`out.truncated()`), the buffer holds the `capacity`
  /// smallest contacts in that order (the earliest ones), so the answer does not depend on the
  /// traversal order or the threads: grow the buffer to `out.found` and call again for all.
  /// `buffer` may be null when capacity is 0 (counting only). Runs a traversal each call with
  /// a buffer (the list is not stored); a count-only call after a full traversal reuses it.
  [[nodiscard]] ColliderStatus contacts(Contact* buffer, std::size_t capacity,
                                        ContactsResult& out) noexcept;

  /// Detector positions of a kBones asset (bones carry the detectors; the application poses
  /// its skeleton, e.g. with `format::skinned_detector_positions`): `d0`, `d1` = cluster_count
  /// * 3 doubles (xyz per cluster at the start and end of the step; entries of overlap-only
  /// clusters are not read), `value_count` must be cluster_count * 3. The collider keeps the
  /// pointers (like `step`'s) and reads them at every following `step`: update the arrays
  /// before each step. Any positions are correct, even wrong ones (a detector far from its
  /// part only culls less; docs/runtime.md). kInvalidArgument for an asset of another form,
  /// kSizeMismatch for a wrong count.
  ColliderStatus set_detector_positions(const double* d0, const double* d1,
                                        std::size_t value_count) noexcept;

  /// Statistics of the current step.
  const ColliderStats& stats() const noexcept;

  /// Static check of positions `x` (node_count * 3 doubles): do two non-adjacent parts of
  /// the surface intersect or touch? Conservative in floating point (an uncertain
  /// orientation counts as touching): may report a false "intersecting" for near-touching
  /// surfaces, never misses a proper edge-through-triangle crossing. Allocation-free.
  /// Culling assumes an intersection-free start: call this on the initial state.
  RestCheck check_rest_intersection(const double* x, std::size_t value_count) noexcept;
  /// Result of `options.check_first_step` (intersecting = false when not run).
  const RestCheck& rest_intersection() const noexcept;

  /// Orientation class of surface triangle `t` in the current step (rvbc mode; kUncertain
  /// otherwise or when out of range). For diagnostics and tests.
  Orientation triangle_class(std::size_t t) const noexcept;

  struct Impl;

 private:
  std::unique_ptr<Impl> m_impl;
};

}  // namespace tetseg
