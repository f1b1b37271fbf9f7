#pragma once
// Private state of tetseg::Collider, shared by collider*.cpp. Not installed.

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <memory>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "body_shape_data.hpp"
#include "feature_bounds.hpp"
#include "normal_cone.hpp"
#include "orientation_terms.hpp"
#include "plane_filter.hpp"
#include "tetseg/runtime/classify.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/median_bvh.hpp"

namespace tetseg {

inline constexpr std::uint32_t kNone = 0xffffffffu;

/// std::allocator whose value-less construct default-initialises: a vector's resize leaves
/// trivial elements unwritten, so large scratch written before it is read (per-step caches)
/// touches no page it does not use.
template <class T>
struct DefaultInitAllocator : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <class U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) noexcept {}
  template <class U>
  void construct(U* p) noexcept(std::is_nothrow_default_constructible<U>::value) {
    ::new (static_cast<void*>(p)) U;
  }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using ScratchVector = std::vector<T, DefaultInitAllocator<T>>;

/// Axis-aligned box.
struct Box {
  double lo[3];
  double hi[3];
};

inline bool boxes_overlap(const Box& a, const Box& b, double margin) noexcept {
  // Written so that NaN never yields "disjoint" (positions are checked finite anyway). All six
  // comparisons combined without branches: the traversal's outcomes are hard to predict.
#if defined(__SSE2__)
  // x and y in one pair of packed comparisons (the same comparisons, lane by lane).
  const __m128d m = _mm_set1_pd(margin);
  const __m128d apart_xy =
      _mm_or_pd(_mm_cmpgt_pd(_mm_loadu_pd(a.lo), _mm_add_pd(_mm_loadu_pd(b.hi), m)),
                _mm_cmpgt_pd(_mm_loadu_pd(b.lo), _mm_add_pd(_mm_loadu_pd(a.hi), m)));
  const bool apart = (_mm_movemask_pd(apart_xy) != 0) | (a.lo[2] > b.hi[2] + margin) |
                     (b.lo[2] > a.hi[2] + margin);
#else
  const bool apart = (a.lo[0] > b.hi[0] + margin) | (b.lo[0] > a.hi[0] + margin) |
                     (a.lo[1] > b.hi[1] + margin) | (b.lo[1] > a.hi[1] + margin) |
                     (a.lo[2] > b.hi[2] + margin) | (b.lo[2] > a.hi[2] + margin);
#endif
  return !apart;
}

/// a becomes the union of a and b: per coordinate, b's value where it is strictly below
/// (lo) or above (hi) a's, else a's.
inline void box_union(Box& a, const Box& b) noexcept {
#if defined(__SSE2__)
  // The six contiguous doubles as three pairs (lo0 lo1) (lo2 hi0) (hi1 hi2); _mm_min_pd(b, a)
  // is b < a ? b : a lane by lane, so every value is the scalar form's.
  static_assert(sizeof(Box) == 6 * sizeof(double), "Box: six contiguous doubles");
  const double* pb = reinterpret_cast<const double*>(&b);
  double* pa = reinterpret_cast<double*>(&a);
  const __m128d b0 = _mm_loadu_pd(pb), b1 = _mm_loadu_pd(pb + 2), b2 = _mm_loadu_pd(pb + 4);
  const __m128d a0 = _mm_loadu_pd(pa), a1 = _mm_loadu_pd(pa + 2), a2 = _mm_loadu_pd(pa + 4);
  _mm_storeu_pd(pa, _mm_min_pd(b0, a0));
  _mm_storeu_pd(pa + 2, _mm_move_sd(_mm_max_pd(b1, a1), _mm_min_pd(b1, a1)));
  _mm_storeu_pd(pa + 4, _mm_max_pd(b2, a2));
#else
  for (int k = 0; k < 3; ++k) {
    if (b.lo[k] < a.lo[k]) a.lo[k] = b.lo[k];
    if (b.hi[k] > a.hi[k]) a.hi[k] = b.hi[k];
  }
#endif
}

/// A BVH seen by the traversal: node topology plus per-step node data.
struct TreeView {
  const format::BvhNode* nodes = nullptr;
  const std::uint32_t* leaf_tris = nullptr;  // global triangle ids in leaf order
  const Box* box = nullptr;
  const Box* tri_box = nullptr;  // swept box of each triangle (by global id), this step
  const std::uint32_t* ntris = nullptr;
  const std::uint32_t* nmov = nullptr;
  const ConeData* cone = nullptr;  // non-null: node self-tests may be culled by normal cones
  std::uint32_t cone_base = 0;     // cone index of node 0
};

/// Orientation sign bits of a triangle or a wide node (rvbc, this step): kNodeAllPositive /
/// kNodeAllNegative when every triangle under it has that class. Two within one cluster whose
/// bits share one cannot produce a first contact between their triangles.
inline constexpr std::uint8_t kNodeAllPositive = 1;
inline constexpr std::uint8_t kNodeAllNegative = 2;

/// Sign bits of a triangle of class `cls` (an Orientation): kNodeAllPositive, kNodeAllNegative,
/// or 0 when uncertain.
inline std::uint8_t class_sign_bits(std::uint8_t cls) noexcept {
  static_assert(static_cast<int>(Orientation::kPositive) == 0 &&
                    static_cast<int>(Orientation::kNegative) == 1 &&
                    static_cast<int>(Orientation::kUncertain) == 2,
                "sign bits by class: 1 << class, uncertain none");
  return std::uint8_t((1u << cls) & (kNodeAllPositive | kNodeAllNegative));
}

/// Per-step data of a 4-wide node (WideNode): its children's swept boxes in
/// structure-of-arrays form (an empty slot holds an inverted infinite box, which overlaps
/// nothing), and a bit per child: it holds a moving triangle, all its triangles are positive,
/// all are negative.
struct alignas(64) WideStep {
  double lo[3][4];
  double hi[3][4];
  std::uint8_t mov = 0, pos = 0, neg = 0;
};

struct StackItem {
  std::uint32_t a;
  std::uint32_t b;  // kNone: self item of node a
};

/// An item of the 4-wide cluster BVHs with the rules of the traversal it belongs to
/// (traverse_wide's `orient` and `seam`).
struct WideTask {
  StackItem item;
  bool orient;
  bool seam;
};

/// The cluster traversal's shared queue on the OpenMP workers (traverse_clusters_parallel):
/// items[0, count) wait, `running` are being traversed; a worker that finds the queue empty
/// while others run sets `hungry`, and a running traversal then moves the oldest half of its
/// stack (the largest subtrees left) into the queue. Changed only inside the critical section
/// tetseg_wide_queue; the atomics are read outside it as hints.
struct WideQueue {
  WideTask* items = nullptr;
  std::size_t capacity = 0;
  std::atomic<std::size_t> count{0};
  std::atomic<std::size_t> running{0};
  std::atomic<bool> hungry{false};
};

/// Bottom-up refit of one BVH (children after parents, so reverse order is bottom-up): node
/// boxes are the union of their triangles' swept boxes `tbox`, node counters `nmov` the sum of
/// their triangles' moving flags `tmov`. `leaf` maps leaf positions to triangle ids.
inline void refit_bvh(const format::BvhNode* nodes, std::uint32_t node_count,
                      const std::uint32_t* leaf, const Box* tbox, const std::uint8_t* tmov,
                      Box* box, std::uint32_t* nmov) noexcept {
  for (std::uint32_t i = node_count; i-- > 0;) {
    const format::BvhNode& n = nodes[i];
    if (n.count > 0) {
      Box b = tbox[leaf[n.first]];
      std::uint32_t m = 0;
      for (std::uint32_t k = 0; k < n.count; ++k) {
        box_union(b, tbox[leaf[n.first + k]]);
        m += tmov[leaf[n.first + k]];
      }
      box[i] = b;
      nmov[i] = m;
    } else {
      Box b = box[n.first];
      box_union(b, box[n.second]);
      box[i] = b;
      nmov[i] = nmov[n.first] + nmov[n.second];
    }
  }
}

/// One descent step of a node-pair traversal: splits the inner node of pair `item` with more
/// triangles (a leaf is never split) and pushes the child pairs that `live` accepts.
/// `stack` must have room for two more items.
template <class Live>
inline void push_child_pairs(const StackItem& item, const TreeView& ta, const TreeView& tb,
                             Live&& live, StackItem* stack, std::size_t& top) noexcept {
  const format::BvhNode& na = ta.nodes[item.a];
  const format::BvhNode& nb = tb.nodes[item.b];
  const bool split_a = nb.count > 0 || (na.count == 0 && ta.ntris[item.a] >= tb.ntris[item.b]);
  if (split_a) {
    if (live(na.second, item.b)) stack[top++] = {na.second, item.b};
    if (live(na.first, item.b)) stack[top++] = {na.first, item.b};
  } else {
    if (live(item.a, nb.second)) stack[top++] = {item.a, nb.second};
    if (live(item.a, nb.first)) stack[top++] = {item.a, nb.first};
  }
}

enum class QueryKind : std::uint8_t { kAny, kFull };

/// One median-split BVH over a whole surface: topology built once (from rest positions, or
/// from the first step's start) into storage reserved by `reserve`, then refit per step.
struct WholeSurfaceBvh {
  bool built = false;
  std::vector<format::BvhNode> nodes;
  std::uint32_t count = 0;          // nodes in use
  std::vector<std::uint32_t> leaf;  // triangle ids in leaf order
  ScratchVector<double> centroid;   // scratch for the build
  std::vector<MedianBvhTask> build_stack;
  ScratchVector<Box> box;                 // per node, this step (written by refit)
  std::vector<std::uint32_t> ntris, mov;  // per node: triangles, moving triangles

  /// Allocates everything for `tri_count` triangles (may throw).
  void reserve(std::uint32_t tri_count);
  /// Builds the topology from `positions` (3 doubles per node) without allocating.
  void build(const format::Triangle* tris, std::uint32_t tri_count, const double* positions,
             std::uint32_t leaf_size) noexcept;
  /// Node boxes and moving counts from the triangles' swept boxes and moving flags.
  void refit(const Box* tbox, const std::uint8_t* tmov) noexcept {
    refit_bvh(nodes.data(), count, leaf.data(), tbox, tmov, box.data(), mov.data());
  }
};

/// A BVH over item boxes (kFeatures: vertices, edges or triangles of one body) in the Morton
/// order of their centres, built from scratch by `build` into storage reserved by `reserve`.
/// Nodes and leaves hold float bounds rounded outwards (feature_bounds.hpp): the box, inflated
/// by the margin on its hi side, and the slabs (Slabs). The traversal sees the binary tree
/// four-wide: an inner node's FeatureWide holds up to four descendants (the root's and each
/// inner descendant's in turn), so one SIMD test checks a node against four.
struct FeatureTree {
  /// Storage from std::aligned_alloc (large_array in collider_features.cpp).
  struct Free {
    void operator()(void* p) const noexcept { std::free(p); }
  };
  template <class T>
  using Array = std::unique_ptr<T[], Free>;
  /// Leaves (and wide nodes) a tree of `items` items needs at most: every leaf but the last
  /// holds four items.
  static std::size_t leaf_capacity(std::size_t items) noexcept {
    return std::max<std::size_t>(1, (items + 3) / 4);
  }
  FeatureNode* nodes = nullptr;   // the binary tree (the build's; node 0 the root)
  std::uint32_t count = 0;        // nodes in use
  FeatureLeaf* leaves = nullptr;  // leaf_capacity(items) of them
  std::uint32_t leaf_count = 0;
  FeatureWide* wides = nullptr;  // inner nodes seen four-wide (as many as leaves)
  std::uint32_t wide_count = 0;
  std::uint32_t root = 0;  // the root's id: a FeatureWide, or kFeatureLeafBit | its leaf
  /// Builds over `items` items without allocating: item i's double box `item_box(i)`, its
  /// slabs `item_slabs(i)` (when `slabs`; else off, with a minimum separation), `margin` (the
  /// minimum separation: added to every hi before rounding up), and its `nodes_per_item`
  /// nodes at `item_nodes` (1 to 3; kept in the leaves for the shared-node check). `key` and
  /// `key_scratch`: room for `items` each. Defined in collider_features.cpp (its only user).
  template <class ItemBox, class ItemSlabs>
  void build(const ItemBox& item_box, const ItemSlabs& item_slabs, bool slabs, double margin,
             std::uint32_t items, const std::uint32_t* item_nodes, int nodes_per_item,
             std::uint64_t* key, std::uint64_t* key_scratch, MedianBvhTask* stack) noexcept;
};

/// A task of the features mode's parallel traversal: a pair of nodes of the vertex and face
/// trees, or (`edges`) of the edge tree with itself.
struct FeatureTask {
  StackItem item;
  bool edges;
};

/// A caller's contact buffer, shared by every worker of one query: it keeps the `cap`
/// smallest contacts in `contact_less` order (a max-heap on that order while filling; the
/// query sorts it at the end), so its content does not depend on which worker finds what, or
/// when. `written` = min(contacts added, cap). With `locked`, `add` runs under a lock
/// (workers on several threads); contacts are rare next to tests, so the lock costs little.
struct ContactSink {
  Contact* out = nullptr;
  std::size_t cap = 0, written = 0;
  bool locked = false;
  void add(const Contact& c) noexcept;
};

/// Running state of one traversal thread (index 0 is the serial one). Allocated at
/// construction: one per OpenMP thread when `use_openmp`, else one. On its own cache lines:
/// workers lie side by side and each writes its counters on every item it traverses.
struct alignas(64) Worker {
  std::vector<StackItem> stack;
  ColliderStats stats;  // counters only; merged into the collider's stats after a query
  bool stop = false;
  bool overflow = false;
  std::size_t found = 0;
  bool has_best = false;
  Contact best;
  double tests_seconds = 0;
  ContactSink* sink = nullptr;  // the query's buffer (null: none)
  bool rest_hit = false;
  std::uint32_t rest_a = 0, rest_b = 0;
  QueryKind qkind = QueryKind::kFull;
  // Lazy per-step cache of triangles' planes (FacePlaneStatic, plane filters): a collider's worker
  // caches its collider `plane_owner`'s triangles (entry t); a scene's worker every body's (entry
  // plane_base[body_id] + t; plane_owner null). An entry is valid when its plane_step equals
  // the body's step_serial. Sized at construction (scene: add_body).
  const void* plane_owner = nullptr;
  std::vector<std::uint32_t> plane_base;
  ScratchVector<FacePlaneStatic> plane;  // an entry is written before it is valid
  std::vector<std::uint64_t> plane_step;
  /// Counts a contact: stops the traversal for kAny, else keeps the earliest and adds it to
  /// `sink`.
  void record(const Contact& c) noexcept;
  void reset() noexcept {
    stats = ColliderStats{};
    stop = overflow = has_best = rest_hit = false;
    found = 0;
    sink = nullptr;
    tests_seconds = 0;
  }
};

/// How many Workers a collider or a scene allocates: `threads` (0: OpenMP's default) when
/// `use_openmp` in an OpenMP build, else 1. Defined in collider.cpp.
std::size_t worker_count(bool use_openmp, std::uint32_t threads) noexcept;

/// Per-step answers shared by the queries of a Collider or a Scene (reset by `step`).
struct QueryCache {
  bool any_known = false, any_value = false;
  bool full_done = false;  // a full traversal ran: the fields below are valid
  bool has_best = false;
  Contact best;
  std::size_t full_found = 0;
  /// Records the outcome of a complete traversal.
  void set_full(std::size_t found, bool has, const Contact& earliest) noexcept {
    full_done = any_known = true;
    any_value = found > 0;
    full_found = found;
    has_best = has;
    best = earliest;
  }
};

/// Keeps in (has, first) the smaller in `contact_less` of itself and (h, c).
inline void keep_earliest(bool& has, Contact& first, bool h, const Contact& c) noexcept {
  if (h && (!has || contact_less(c, first))) {
    first = c;
    has = true;
  }
}

using Clock = std::chrono::steady_clock;
inline double ms_since(Clock::time_point start) noexcept {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

/// Accumulates the traversal counters of `from` into `to`.
inline void add_counts(ColliderStats& to, const ColliderStats& from) noexcept {
  to.clusters_skipped += from.clusters_skipped;
  to.closure_pairs += from.closure_pairs;
  to.node_pairs_visited += from.node_pairs_visited;
  to.node_pairs_orientation_culled += from.node_pairs_orientation_culled;
  to.triangle_pairs += from.triangle_pairs;
  to.triangle_pairs_plane_filtered += from.triangle_pairs_plane_filtered;
  to.feature_pairs += from.feature_pairs;
  to.feature_pairs_filtered += from.feature_pairs_filtered;
  to.feature_tests += from.feature_tests;
  to.contacts += from.contacts;
}

// The three queries of a Collider or a Scene over one traversal function
// `run(kind, out, capacity, written) -> ColliderStatus`, which on kOk records a kAny answer in
// cache.any_known/any_value and a kFull answer in every cache field (and `written`, the
// contacts written to `out`). Failures leave the out parameter empty.
template <typename Run>
ColliderStatus answer_any(QueryCache& cache, Run&& run, bool& hit) noexcept {
  hit = false;
  if (!cache.any_known) {
    std::size_t written = 0;
    const ColliderStatus st = run(QueryKind::kAny, nullptr, 0, written);
    if (st != ColliderStatus::kOk) return st;
  }
  hit = cache.any_value;
  return ColliderStatus::kOk;
}

template <typename Run>
ColliderStatus answer_earliest(QueryCache& cache, Run&& run, EarliestContact& out) noexcept {
  out = EarliestContact{};
  if (!cache.full_done) {
    std::size_t written = 0;
    const ColliderStatus st = run(QueryKind::kFull, nullptr, 0, written);
    if (st != ColliderStatus::kOk) return st;
  }
  out.found = cache.has_best;
  out.contact = cache.best;
  return ColliderStatus::kOk;
}

template <typename Run>
ColliderStatus answer_contacts(QueryCache& cache, Run&& run, Contact* buffer, std::size_t capacity,
                               ContactsResult& out) noexcept {
  out = ContactsResult{};
  if (!buffer) capacity = 0;
  if (!cache.full_done || capacity > 0) {
    std::size_t written = 0;
    const ColliderStatus st =
        run(QueryKind::kFull, capacity > 0 ? buffer : nullptr, capacity, written);
    if (st != ColliderStatus::kOk) return st;
    out.written = written;
    if (written > 0) std::sort(buffer, buffer + written, contact_less);
  }
  out.found = cache.full_found;
  return ColliderStatus::kOk;
}

struct Collider::Impl {
  // --- construction-time data
  std::shared_ptr<const BodyShape> shape;  // immutable topology, shared
  const BodyShape::Data* topo = nullptr;
  const format::Asset* asset = nullptr;    // topo->asset: null for a surface-only body
  const format::Triangle* tris = nullptr;  // topo->triangles
  ColliderOptions opt;
  ColliderStatus ctor_status = ColliderStatus::kNotReady;
  std::uint32_t node_count = 0;
  std::uint32_t tri_count = 0;
  std::uint32_t body_id = 0;  // stamped on contacts (scene body id; 0 for a Collider)
  bool always_refit = false;  // scene body: boxes are refit even when nothing moved

  // whole-surface BVH of the bvh and cone modes and of surface-only bodies
  WholeSurfaceBvh gbvh;

  // --- per-step data
  const double* x0 = nullptr;
  const double* x1 = nullptr;
  bool have_step = false;
  std::uint64_t step_serial = 0;  // counts begin_step calls (validates the workers' plane caches)
  bool first_step_done = false;
  bool rest_mode = false;            // check_rest_intersection: static positions, no still rule
  std::vector<std::uint8_t> vmoved;  // per surface vertex
  std::vector<Box> vbox;             // per surface vertex, swept
  std::vector<Box> tbox;
  std::vector<std::uint8_t> tcls;  // Orientation
  // Per cluster, this step: the detector point at the start and end (3 doubles each), and
  // whether the cluster is classified at all (0: overlap-only, or a non-finite detector).
  std::vector<double> det0, det1;
  std::vector<std::uint8_t> det_ok;
  // kBones assets: the application's detector positions at both ends of the step (cluster
  // count x 3 doubles each; set_detector_positions), read by every classifying step.
  const double* bone_det0 = nullptr;
  const double* bone_det1 = nullptr;
  std::vector<std::uint8_t> tmov;
  // Whole-surface modes (bvh, cone, surface-only bodies): triangle pairs that share a node are
  // not candidates; the feature pairs only such pairs hold (orphan sets, built at construction)
  // are tested directly every step (docs/runtime.md, "Adjacent triangle pairs").
  bool skip_adjacent = false;
  std::vector<std::array<std::uint32_t, 2>> orphan_vf;  // (node, triangle)
  std::vector<std::array<std::uint32_t, 2>> orphan_ee;  // (edge, edge), first < second
  // rvbc: triangle pairs of two clusters that share a node are culled; the feature pairs that
  // only such pairs hold across clusters (seam orphans, built at construction) are tested
  // directly every step (docs/runtime.md, "Across clusters: seam pairs").
  std::vector<std::array<std::uint32_t, 2>> seam_vf;  // (node, triangle)
  std::vector<std::array<std::uint32_t, 2>> seam_ee;  // (edge, edge), first < second
  std::vector<Box> nbox;  // per asset BVH node (refit for a scene body: traverse_bodies)
  std::vector<std::uint32_t> nmov;
  // 4-wide cluster BVHs (topo->wide_nodes), this step: children's data, own box, own moving
  // flag and own sign bits (rvbc).
  std::vector<WideStep> wstep;
  std::vector<Box> wbox;
  std::vector<std::uint8_t> wmov, wsign;
  std::vector<orientation_detail::StaticErr> cluster_err;  // per cluster, this step (classify)
  std::vector<Worker> workers;
  // Items of the whole-surface BVH handed to the workers (traverse_global_parallel; capacity
  // reserved at construction when there are several workers).
  std::vector<StackItem> frontier;
  // The same for the cluster BVHs (traverse_clusters_parallel's queue): every cluster's own
  // item and every live pair of clusters, then items handed over on the way (sized at
  // construction when there are several workers, empty otherwise).
  std::vector<WideTask> wide_frontier;
  // Contact closure scratch (capacity tri_count, reserved at construction).
  std::vector<std::uint32_t> closure_ring;
  std::vector<std::uint8_t> closure_mark;
  ColliderStats stats;
  RestCheck rest;

  QueryCache cache;  // answers of the current step

  // running query (shared, read-only during traversal) and its merged outcome
  QueryKind qkind = QueryKind::kFull;
  bool query_hit = false;  // kAny: a contact was found

  // --- collider.cpp
  /// Allocates all scratch for `sh` (non-null). Throws on allocation failure.
  void construct(std::shared_ptr<const BodyShape> sh, const ColliderOptions& o);
  std::uint32_t cluster_count() const noexcept {
    return asset ? static_cast<std::uint32_t>(asset->clusters.size()) : 0;
  }
  /// The whole-surface BVH serves this body's queries (bvh and cone modes; every mode but brute
  /// force of a surface-only body, which has no clusters).
  bool uses_global_bvh() const noexcept {
    return opt.mode == ColliderMode::kBvh || opt.mode == ColliderMode::kCone ||
           (!asset && opt.mode != ColliderMode::kBrute && opt.mode != ColliderMode::kFeatures);
  }
  /// The whole-surface BVH is refit and traversed by the current query kind.
  bool global_bvh_active() const noexcept { return rest_mode ? !asset : uses_global_bvh(); }
  /// The asset's cluster BVHs are refit and traversed (rvbc, and the rest check of a tet body).
  bool uses_clusters() const noexcept {
    return asset && (opt.mode == ColliderMode::kRvbc || rest_mode);
  }
  /// Validates a step's inputs (`rest_check`: for a rest check, which classifies nothing, so
  /// bone-carried detector positions are not needed) and makes it current.
  ColliderStatus begin_step(const double* p0, const double* p1, std::size_t count,
                            bool rest_check = false) noexcept;
  /// Collider/Scene::set_detector_positions (a kBones asset's detectors; docs/runtime.md).
  ColliderStatus set_detector_positions(const double* d0, const double* d1,
                                        std::size_t value_count) noexcept;
  /// Cluster c's detector at the start (`a`) and end (`b`) of the current step, by the
  /// asset's detector form (a classified cluster of a validated step).
  void detector_ends(std::uint32_t c, std::array<double, 3>& a,
                     std::array<double, 3>& b) const noexcept;
  void refit_and_classify() noexcept;
  /// kOk when a query can run, else kNotReady or kNoStep.
  ColliderStatus query_status() const noexcept;
  const double* pos0(std::uint32_t node) const noexcept { return x0 + std::size_t(node) * 3; }
  const double* pos1(std::uint32_t node) const noexcept { return x1 + std::size_t(node) * 3; }
  /// Swept box of edge e this step: the union of its end nodes' boxes (computed when asked:
  /// only edges of the few triangle pairs past the plane filter are ever read).
  Box edge_box(std::uint32_t e) const noexcept {
    const std::array<std::uint32_t, 2>& ends = topo->edge_verts[e];
    Box b = vbox[ends[0]];
    box_union(b, vbox[ends[1]]);
    return b;
  }
  /// An end node of edge e moved this step.
  bool edge_moving(std::uint32_t e) const noexcept {
    const std::array<std::uint32_t, 2>& ends = topo->edge_verts[e];
    return vmoved[ends[0]] | vmoved[ends[1]];
  }

  // --- collider_traverse.cpp (traverse_wide, refit_wide and sign_wide: collider_wide.cpp)
  /// Runs the query over all candidates into workers (merged into stats/results); stops early
  /// for kAny. `sink`: optional contact buffer (may be shared with other parts of a scene
  /// query). Parallel with use_openmp (every mode but the rest check). Returns false on stack
  /// overflow.
  bool run_query(ContactSink* sink) noexcept;
  /// The self traversal of tree `t` from `first` (the root: {0, kNone}). False on overflow.
  bool traverse_self(Worker& w, const TreeView& t, StackItem first) const noexcept;
  /// One popped item of the self traversal: leaves are processed, live children pushed on
  /// w.stack above `top`. False when the stack has no room.
  bool self_item(Worker& w, const TreeView& t, const StackItem& it,
                 std::size_t& top) const noexcept;
  /// The self traversal of the whole-surface BVH on the OpenMP workers: the top of the tree
  /// is expanded breadth first on worker 0 into `frontier`, whose items the workers then
  /// traverse (each item once, so counts and contacts are the serial ones).
  bool traverse_global_parallel() noexcept;
  /// The cluster traversal (rvbc) on the OpenMP workers, split below whole clusters: each
  /// cluster's own item and each live pair of clusters queued in `wide_frontier`, and
  /// subtrees handed over from running traversals to idle workers (WideQueue). Each item is
  /// traversed once: counts and contacts are the serial ones.
  bool traverse_clusters_parallel(bool count_skips) noexcept;
  bool non_culled(std::uint32_t t1, std::uint32_t t2) const noexcept;
  /// A pair of two clusters sharing a node that non_culled accepted before the seam rule (both
  /// not still, boxes overlapping): culled only by that rule (rvbc, not the rest check).
  bool seam_culled(std::uint32_t t1, std::uint32_t t2) const noexcept;
  void process_triangle_pair(Worker& w, std::uint32_t t1, std::uint32_t t2) const noexcept;
  /// process_triangle_pair of a pair known to be non-culled (not in the rest check).
  void process_non_culled_pair(Worker& w, std::uint32_t t1, std::uint32_t t2) const noexcept;
  /// Traversal of the 4-wide cluster BVHs from `first` (a self item {node, kNone} or a pair of
  /// child slots); `orient`: cull by the sign bits (within one cluster); `seam`: a pair of
  /// clusters' items (pairs sharing a node culled). With `queue` (parallel traversal), items
  /// of the stack are handed to the queue when a worker is hungry. False on overflow.
  bool traverse_wide(Worker& w, StackItem first, bool orient, bool seam,
                     WideQueue* queue = nullptr) const noexcept;
  /// Refits the 4-wide cluster BVHs from tbox / tmov (wstep boxes and moving bits, wbox, wmov).
  void refit_wide() noexcept;
  /// Sign bits of triangle t from its class tcls[t] (class_sign_bits).
  std::uint8_t triangle_sign(std::uint32_t t) const noexcept { return class_sign_bits(tcls[t]); }
  /// Sign bits of wide nodes and of their children, from tcls.
  void sign_wide() noexcept;
  void brute_vertex_faces(Worker& w, std::uint32_t i) const noexcept;
  void brute_edge_edges(Worker& w, std::uint32_t i) const noexcept;
  /// Intra-cluster work of cluster c1 and its pairs with every cluster c2 > c1.
  bool cluster_tasks(Worker& w, std::uint32_t c1, bool count_skips) const noexcept;
  TreeView cluster_view(std::uint32_t c) const noexcept;
  /// Broad-phase trees of this body against other bodies: its cluster BVHs (rvbc) or its
  /// whole-surface BVH (after a refit).
  std::uint32_t tree_count() const noexcept;
  TreeView tree(std::uint32_t i) const noexcept;
  TreeView global_view() const noexcept;

  // --- collider_orphans.cpp
  /// Calls vertex_face(p, f) for every vertex-face pair (p not in f) and edge_edge(e1, e2)
  /// for every edge pair (e1 < e2, four distinct nodes) held by some triangle pair that shares
  /// a node (construction; allocates, may throw). With `across_clusters`, only those where
  /// such a pair spans two clusters, and maybe some others. With `first_holder_only`, only
  /// those where such a pair holds the first triangle around p (e1), and maybe some others:
  /// enough for the orphans, whose every holding pair shares a node.
  template <typename VertexFace, typename EdgeEdge>
  void for_each_adjacent_feature_pair(bool across_clusters, bool first_holder_only,
                                      VertexFace&& vertex_face, EdgeEdge&& edge_edge) const;
  /// holder(t1, t2) is true for some triangle pair holding the feature pair: (t around p, f),
  /// or (t1 around e1, t2 around e2).
  template <typename Holder>
  bool any_vertex_face_holder(std::uint32_t p, std::uint32_t f, Holder&& holder) const noexcept;
  template <typename Holder>
  bool any_edge_edge_holder(std::uint32_t e1, std::uint32_t e2, Holder&& holder) const noexcept;
  /// Builds orphan_vf / orphan_ee from the topology (construction; allocates, may throw).
  void build_orphan_sets();
  /// Tests every orphan feature pair (filters, then the elementary test).
  void test_orphans(Worker& w) const noexcept;
  /// Builds seam_vf / seam_ee from the topology and clusters (construction; may throw).
  void build_seam_orphans();
  /// Tests every seam orphan that no non-culled triangle pair holds (filters, elementary test).
  void test_seam_orphans(Worker& w) const noexcept;

  // --- collider_features.cpp (kFeatures)
  /// Morton-order BVHs over the swept boxes of the surface vertices, triangles and edges,
  /// rebuilt every step. Sized at construction.
  FeatureTree vertex_tree, face_tree, edge_tree;
  // Their storage: the binary nodes shared (one build at a time), the leaves and wide nodes
  // of the three trees one after the other (reserve_feature_trees).
  FeatureTree::Array<FeatureNode> feature_nodes;
  FeatureTree::Array<FeatureLeaf> feature_leaves;
  FeatureTree::Array<FeatureWide> feature_wides;
  /// Allocates the trees and their scratch (construction; may throw; nothing is written).
  void reserve_feature_trees();
  std::vector<std::uint64_t> feature_key, feature_key_scratch;  // the builds' (largest tree)
  std::vector<Slabs> vslabs;                                    // per surface vertex
  std::vector<MedianBvhTask> feature_build_stack;
  /// Tasks of the parallel traversal (feature_pairs; reserved at construction with several
  /// workers).
  std::vector<FeatureTask> feature_frontier;
  /// Every vertex-face and edge-edge pair with four distinct nodes whose swept boxes overlap,
  /// each once, through process_vertex_face / process_edge_edge: on `w0`, or with `parallel`
  /// on the OpenMP workers (the top of the traversals expanded on `w0` into tasks; a worker's
  /// overflow marked in its `overflow`). False on stack overflow.
  bool feature_pairs(Worker& w0, bool parallel) noexcept;

  // --- collider_cone.cpp (kCone; the cone maths: normal_cone.hpp)
  ConeData cone;  // kCone, indexed by global BVH node
  void build_cone_topology(ConeData& cd, const ConeTree& tree, std::vector<std::uint32_t>& pos);
  void build_global_cones();
  void update_cones() noexcept;
  void update_cone_tree(ConeData& cd, const ConeTree& tree) noexcept;
  bool cone_self_free(const ConeData& cd, std::uint32_t node) const noexcept;
  /// rvbc orientation culling is on (kRvbc; never in the rest check).
  bool orientation_mode() const noexcept { return opt.mode == ColliderMode::kRvbc && !rest_mode; }
  bool orientation_culled(std::uint32_t t1, std::uint32_t t2) const noexcept;
  void close_contacts(Worker& w, double toi) noexcept;

  // --- collider_bvh.cpp
  /// Static intersection check of this body at positions x (check_rest_intersection).
  RestCheck rest_check(const double* x, std::size_t value_count) noexcept;
};

/// Triangles a and b have a node in common.
inline bool share_node(const format::Triangle& a, const format::Triangle& b) noexcept {
  return shared_node_mask(a, b) != 0;
}

// --- collider_narrow.cpp: one feature pair of body P/A and body F/B (P == F within a body).
// Swept boxes, the still rule, the coplanarity and plane filters (exact contact only), the
// elementary test; a contact is recorded in `w`. Options (ccd, timing) are the first body's.
void process_vertex_face(Worker& w, const Collider::Impl& P, std::uint32_t p,
                         const Collider::Impl& F, std::uint32_t face) noexcept;
void process_edge_edge(Worker& w, const Collider::Impl& A, std::uint32_t e1,
                       const Collider::Impl& B, std::uint32_t e2) noexcept;
/// The same with the edges' swept boxes already at hand (`box1` = A.edge_box(e1), `box2` =
/// B.edge_box(e2)) and found overlapping by the caller (boxes_overlap with the options'
/// min_separation): the triangle-pair and feature loops check them before the call.
void process_edge_edge(Worker& w, const Collider::Impl& A, std::uint32_t e1, const Box& box1,
                       const Collider::Impl& B, std::uint32_t e2, const Box& box2) noexcept;
/// Triangle-pair plane filter of triangle t1 of A and t2 of B (plane_filter.hpp): no feature
/// pair of the two can touch (exact contact only).
bool plane_separated(Worker& w, const Collider::Impl& A, std::uint32_t t1, const Collider::Impl& B,
                     std::uint32_t t2) noexcept;

/// Swept boxes of two edges overlap and not all four nodes are still.
inline bool edge_boxes_overlap(const Collider::Impl& A, std::uint32_t e1, const Collider::Impl& B,
                               std::uint32_t e2) noexcept {
  if (!A.edge_moving(e1) && !B.edge_moving(e2)) return false;
  return boxes_overlap(A.edge_box(e1), B.edge_box(e2), A.opt.ccd.min_separation);
}

/// Static check of triangle t1 of A against t2 of B (A == B within a body): an edge of one
/// meeting the other, conservatively; records a witness in `w` and stops it.
void rest_triangle_pair(Worker& w, const Collider::Impl& A, std::uint32_t t1,
                        const Collider::Impl& B, std::uint32_t t2) noexcept;

/// Contacts between two different bodies A and B (scene): every pair of their trees, culled by
/// overlap only, triangle pairs deduplicated over all overlapping pairs of the two bodies.
/// Both bodies refit for the same step. With `rest` (both refit in rest mode): the static
/// check instead (rest_triangle_pair; the witness in `w`). False on stack overflow.
bool traverse_bodies(Worker& w, const Collider::Impl& A, const Collider::Impl& B,
                     bool rest = false) noexcept;

}  // namespace tetseg
