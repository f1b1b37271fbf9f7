// Collider: construction (topology, scratch), step validation, refit and classification,
// and the public query entry points. Traversal: collider_traverse.cpp; narrow phase:
// collider_narrow.cpp; kBvh mode's BVH and the rest-intersection check: collider_bvh.cpp.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <new>

#include "collider_impl.hpp"

#if defined(TETSEG_HAVE_OPENMP)
#include <omp.h>
#endif

namespace tetseg {
const char* to_string(ColliderMode mode) noexcept {
  switch (mode) {
    case ColliderMode::kRvbc:
      return "rvbc";
    case ColliderMode::kBvh:
      return "bvh";
    case ColliderMode::kBrute:
      return "brute";
    case ColliderMode::kCone:
      return "cone";
    case ColliderMode::kFeatures:
      return "features";
  }
  return "unknown";
}

bool parse_collider_mode(const char* name, ColliderMode& out) noexcept {
  if (!name) return false;
  for (ColliderMode m : {ColliderMode::kRvbc, ColliderMode::kBvh, ColliderMode::kBrute,
                         ColliderMode::kCone, ColliderMode::kFeatures}) {
    if (std::strcmp(name, to_string(m)) == 0) {
      out = m;
      return true;
    }
  }
  return false;
}

const char* to_string(ColliderStatus status) noexcept {
  switch (status) {
    case ColliderStatus::kOk:
      return "ok";
    case ColliderStatus::kNotReady:
      return "not ready";
    case ColliderStatus::kNullInput:
      return "null input";
    case ColliderStatus::kSizeMismatch:
      return "size mismatch";
    case ColliderStatus::kNonFinite:
      return "non-finite position";
    case ColliderStatus::kInternal:
      return "internal error";
    case ColliderStatus::kNoStep:
      return "no valid step";
    case ColliderStatus::kOverflow:
      return "traversal stack overflow";
    case ColliderStatus::kInvalidArgument:
      return "invalid argument";
  }
  return "unknown";
}

bool contact_less(const Contact& a, const Contact& b) noexcept {
  if (a.toi != b.toi) return a.toi < b.toi;
  if (a.kind != b.kind) return a.kind < b.kind;
  if (a.bodies != b.bodies) return a.bodies < b.bodies;
  if (a.nodes != b.nodes) return a.nodes < b.nodes;
  return a.triangle < b.triangle;
}

std::size_t worker_count([[maybe_unused]] bool use_openmp,
                         [[maybe_unused]] std::uint32_t threads) noexcept {
#if defined(TETSEG_HAVE_OPENMP)
  if (use_openmp)
    return threads > 0 ? threads : static_cast<std::size_t>(std::max(1, omp_get_max_threads()));
#endif
  return 1;
}

void Collider::Impl::construct(std::shared_ptr<const BodyShape> sh, const ColliderOptions& o) {
  shape = std::move(sh);
  topo = &shape->data();
  asset = topo->asset;
  tris = topo->triangles;
  opt = o;
  opt.bvh_leaf_size = std::min<std::uint32_t>(16, std::max<std::uint32_t>(1, opt.bvh_leaf_size));
  node_count = topo->node_count;
  tri_count = topo->tri_count;
  if (!asset && opt.mode == ColliderMode::kRvbc) opt.mode = ColliderMode::kBvh;  // no clusters
  const std::size_t nv = topo->surf_nodes.size();
  const std::size_t nn = asset ? asset->bvh_nodes.size() : 0;
  // The kBvh tree is a median split: depth <= log2(triangles) + 1 < 64. A 4-wide traversal
  // pushes at most 16 items per level of its (at most 2 * wide_depth + 2) levels.
  const std::size_t stack_size =
      opt.traversal_stack > 0
          ? opt.traversal_stack
          : std::max(4 * (std::size_t(std::max<std::uint32_t>(topo->max_depth, 64)) + 4),
                     16 * (2 * std::size_t(topo->wide_depth) + 2));
  const std::size_t threads = worker_count(opt.use_openmp, opt.threads);
  workers.resize(threads);
  // The whole-surface BVH's parallel traversal: 16 items per thread, with room for the
  // items expanded on the way (traverse_global_parallel).
  if (threads > 1) frontier.reserve(64 * threads + 4);
  // The cluster traversal's queue (traverse_clusters_parallel): every cluster and pair of
  // clusters, and room for the hand-overs.
  if (threads > 1)
    wide_frontier.resize(std::size_t(cluster_count()) * (cluster_count() + 1) / 2 + 64 * threads);
  const bool plane_cache = opt.mode != ColliderMode::kBrute && opt.ccd.min_separation <= 0;
  for (Worker& w : workers) {
    w.stack.resize(stack_size);
    if (plane_cache) {
      w.plane_owner = this;
      w.plane.resize(tri_count);
      w.plane_step.assign(tri_count, 0);
    }
  }

  // Per-step scratch.
  vmoved.assign(nv, 0);
  vbox.resize(nv);
  tbox.resize(tri_count);
  tcls.assign(tri_count, static_cast<std::uint8_t>(Orientation::kUncertain));
  det0.assign(3 * std::size_t(cluster_count()), 0.0);
  det1.assign(3 * std::size_t(cluster_count()), 0.0);
  det_ok.assign(cluster_count(), 0);
  tmov.assign(tri_count, 0);
  closure_ring.reserve(tri_count);
  closure_mark.assign(tri_count, 0);
  nbox.resize(nn);
  nmov.assign(nn, 0);
  const std::size_t nw = topo->wide_nodes.size();
  wstep.resize(nw);
  for (std::size_t i = 0; i < nw; ++i) {
    for (int k = 0; k < 4; ++k) {
      if (topo->wide_nodes[i].child[k] != kWideEmpty) continue;
      for (int a = 0; a < 3; ++a) {  // never written again: overlaps nothing
        wstep[i].lo[a][k] = INFINITY;
        wstep[i].hi[a][k] = -INFINITY;
      }
    }
  }
  wbox.resize(nw);
  wmov.assign(nw, 0);
  wsign.assign(nw, 0);
  cluster_err.resize(cluster_count());
  if (opt.mode == ColliderMode::kFeatures) reserve_feature_trees();
  skip_adjacent = uses_global_bvh();
  if (skip_adjacent) build_orphan_sets();
  if (opt.mode == ColliderMode::kRvbc && cluster_count() > 1) build_seam_orphans();

  // kBvh topology storage (built from rest positions now when available, else on the first
  // step or rest check, without allocating).
  if (uses_global_bvh() || !asset) {
    gbvh.reserve(tri_count);
    if (asset && asset->rest_positions.size() == node_count && node_count > 0) {
      gbvh.build(tris, tri_count, asset->rest_positions[0].data(), opt.bvh_leaf_size);
      if (opt.mode == ColliderMode::kCone) build_global_cones();
    }
  }
  ctor_status = ColliderStatus::kOk;
}

ColliderStatus Collider::Impl::begin_step(const double* p0, const double* p1, std::size_t count,
                                          bool rest_check) noexcept {
  have_step = false;
  ++step_serial;
  stats = ColliderStats{};
  cache = QueryCache{};
  if (ctor_status != ColliderStatus::kOk) return ColliderStatus::kNotReady;
  if (count != std::size_t(node_count) * 3) return ColliderStatus::kSizeMismatch;
  if (node_count > 0 && (!p0 || !p1)) return ColliderStatus::kNullInput;
  // Only surface vertices and the nodes of detectors that are classified against are read;
  // check exactly those (and a kBones asset's detector positions when the step classifies).
  auto finite = [&](std::uint32_t n) {
    for (int k = 0; k < 3; ++k) {
      if (!std::isfinite(p0[std::size_t(n) * 3 + k]) || !std::isfinite(p1[std::size_t(n) * 3 + k]))
        return false;
    }
    return true;
  };
  for (std::uint32_t n : topo->surf_nodes) {
    if (!finite(n)) return ColliderStatus::kNonFinite;
  }
  const format::DetectorForm form = asset ? asset->detector_form : format::DetectorForm::kTetPoint;
  const bool bones = form == format::DetectorForm::kBones;
  if (bones && !rest_check && opt.mode == ColliderMode::kRvbc && (!bone_det0 || !bone_det1))
    return ColliderStatus::kNullInput;
  for (std::uint32_t c = 0; c < cluster_count(); ++c) {
    const format::Cluster& cl = asset->clusters[c];
    if (cl.flags & format::kClusterOverlapOnly) continue;
    if (form == format::DetectorForm::kTetPoint) {
      for (std::uint32_t n : cl.detector.nodes) {
        if (!finite(n)) return ColliderStatus::kNonFinite;
      }
    } else if (form == format::DetectorForm::kSurfaceWeights) {
      const format::DetectorTerm* terms = asset->detector_terms.data() + cl.detector_term_offset;
      for (std::uint32_t i = 0; i < cl.detector_term_count; ++i) {
        if (!finite(terms[i].index)) return ColliderStatus::kNonFinite;
      }
    } else if (!rest_check && opt.mode == ColliderMode::kRvbc) {
      for (int k = 0; k < 3; ++k) {
        if (!std::isfinite(bone_det0[3 * std::size_t(c) + k]) ||
            !std::isfinite(bone_det1[3 * std::size_t(c) + k]))
          return ColliderStatus::kNonFinite;
      }
    }
  }
  x0 = p0;
  x1 = p1;
  have_step = true;
  return ColliderStatus::kOk;
}

ColliderStatus Collider::Impl::set_detector_positions(const double* d0, const double* d1,
                                                      std::size_t value_count) noexcept {
  if (ctor_status != ColliderStatus::kOk) return ColliderStatus::kNotReady;
  if (!asset || asset->detector_form != format::DetectorForm::kBones)
    return ColliderStatus::kInvalidArgument;
  if (value_count != 3 * std::size_t(cluster_count())) return ColliderStatus::kSizeMismatch;
  bone_det0 = d0;
  bone_det1 = d1;
  return ColliderStatus::kOk;
}

void Collider::Impl::detector_ends(std::uint32_t c, std::array<double, 3>& a,
                                   std::array<double, 3>& b) const noexcept {
  const format::Cluster& cl = asset->clusters[c];
  switch (asset->detector_form) {
    case format::DetectorForm::kTetPoint:
      a = format::detector_position(cl.detector, x0);
      b = format::detector_position(cl.detector, x1);
      return;
    case format::DetectorForm::kSurfaceWeights: {
      const format::DetectorTerm* terms = asset->detector_terms.data() + cl.detector_term_offset;
      a = format::weighted_detector_position(terms, cl.detector_term_count, x0);
      b = format::weighted_detector_position(terms, cl.detector_term_count, x1);
      return;
    }
    case format::DetectorForm::kBones:
      for (int k = 0; k < 3; ++k) {
        a[k] = bone_det0[3 * std::size_t(c) + k];
        b[k] = bone_det1[3 * std::size_t(c) + k];
      }
      return;
  }
}

// The step's loops run on the collider's workers from these many items (nodes, triangles): on 2
// cores a parallel region's fork and join cost about 1 us, a box a few ns, a triangle's
// classification about 10 ns (docs/benchmarks.md, "Contact-rich steps"). Their results do not
// depend on the split.
constexpr std::int64_t kParallelBoxItems = 512;
constexpr std::int64_t kParallelClassifyItems = 1024;

void Collider::Impl::refit_and_classify() noexcept {
  const auto t_refit = Clock::now();
  const std::int64_t nv = static_cast<std::int64_t>(topo->surf_nodes.size());
  [[maybe_unused]] const int threads = static_cast<int>(workers.size());
  [[maybe_unused]] const bool parallel = opt.use_openmp && threads > 1;
  std::uint64_t moved = 0;
  {
    // Local pointers: the byte stores cannot then be taken to alias the collider's members.
    // A still node's box is its point either way (min and max of equal values return it).
    const std::uint32_t* nodes = topo->surf_nodes.data();
    const double* p0 = x0;
    const double* p1 = x1;
    Box* vb = vbox.data();
    std::uint8_t* vm = vmoved.data();
    const bool at_rest = rest_mode;
    // Without the still rule every node counts as moving for the culling (vmoved and all that
    // follows from it); nodes_moved still counts the nodes that moved.
    const bool all_live = !rest_mode && opt.include_still_pairs;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for reduction(+ : moved) num_threads(threads) \
    if (parallel && nv >= kParallelBoxItems)
#endif
    for (std::int64_t i = 0; i < nv; ++i) {
      const double* a = p0 + std::size_t(nodes[i]) * 3;
      const double* b = p1 + std::size_t(nodes[i]) * 3;
      const bool m = !at_rest && (a[0] != b[0] || a[1] != b[1] || a[2] != b[2]);
      vm[i] = (m || all_live) ? 1 : 0;
      moved += m ? 1 : 0;
      for (int k = 0; k < 3; ++k) {
        vb[i].lo[k] = std::min(a[k], b[k]);
        vb[i].hi[k] = std::max(a[k], b[k]);
      }
    }
  }
  stats.nodes_moved = moved;
  stats.nothing_moved = moved == 0 && !rest_mode && !opt.include_still_pairs;
  if (stats.nothing_moved && !always_refit) {
    stats.refit_ms = ms_since(t_refit);
    return;  // every feature pair is still: no test can run this step
  }
  const std::int64_t nt = tri_count;
  {
    // Local pointers: the stores cannot then be taken to alias the collider's members.
    const std::array<std::uint32_t, 3>* tv = topo->tri_verts.data();
    const Box* vb = vbox.data();
    const std::uint8_t* vm = vmoved.data();
    Box* tb = tbox.data();
    std::uint8_t* tm = tmov.data();
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for num_threads(threads) if (parallel && nt >= kParallelBoxItems)
#endif
    for (std::int64_t t = 0; t < nt; ++t) {
      const std::uint32_t i0 = tv[t][0], i1 = tv[t][1], i2 = tv[t][2];
      Box b = vb[i0];
      box_union(b, vb[i1]);
      box_union(b, vb[i2]);
      tb[t] = b;
      tm[t] = (vm[i0] | vm[i1] | vm[i2]) ? 1 : 0;
    }
  }
  if (uses_clusters()) {
    refit_wide();  // collider_wide.cpp
    // A scene body's binary cluster BVHs serve traverse_bodies.
    for (std::uint32_t c = 0; c < cluster_count() && always_refit; ++c) {
      const format::Cluster& cl = asset->clusters[c];
      const format::BvhNode* nodes = asset->bvh_nodes.data() + cl.bvh_offset;
      const std::uint32_t* leaf = asset->cluster_triangles.data() + cl.triangle_offset;
      refit_bvh(nodes, cl.bvh_count, leaf, tbox.data(), tmov.data(), nbox.data() + cl.bvh_offset,
                nmov.data() + cl.bvh_offset);
    }
  } else if (global_bvh_active()) {
    if (!gbvh.built) gbvh.build(tris, tri_count, x0, opt.bvh_leaf_size);
    gbvh.refit(tbox.data(), tmov.data());
  }
  std::uint64_t moving = 0;
  for (std::uint32_t t = 0; t < tri_count; ++t) moving += tmov[t];
  stats.triangles_moving = moving;
  stats.refit_ms = ms_since(t_refit);
  if (stats.nothing_moved) return;  // scene body: boxes only
  if (opt.mode == ColliderMode::kCone && !rest_mode) {
    const auto t_cone = Clock::now();
    update_cones();  // collider_cone.cpp
    stats.cone_ms = ms_since(t_cone);
  }

  if (!orientation_mode()) return;
  const auto t_class = Clock::now();
  // Detector points at both ends of the step (evaluated from the positions, or given for bone-
  // carried detectors); the detector moves linearly between them, like every node, so the
  // orientation stays a cubic in t (docs/runtime.md, "Detector points").
  // Static error bound of each cluster's cubics: its triangles lie in its root box (refit), so
  // the box widened by the detector's two positions bounds every coordinate difference.
  for (std::uint32_t c = 0; c < cluster_count(); ++c) {
    const format::Cluster& cl = asset->clusters[c];
    det_ok[c] = 0;
    if (cl.flags & format::kClusterOverlapOnly) continue;
    std::array<double, 3> a, b;
    detector_ends(c, a, b);
    bool ok = true;
    for (int k = 0; k < 3; ++k) {
      det0[3 * std::size_t(c) + k] = a[k];
      det1[3 * std::size_t(c) + k] = b[k];
      ok = ok && std::isfinite(a[k]) && std::isfinite(b[k]);
    }
    det_ok[c] = ok ? 1 : 0;  // an overflowing combination: the cluster's triangles uncertain
    if (!ok || topo->wide_root[c] == kWideEmpty) continue;
    const Box& root = wbox[topo->wide_root[c]];
    double extent[3];
    for (int k = 0; k < 3; ++k)
      extent[k] = std::max({root.hi[k], a[k], b[k]}) - std::min({root.lo[k], a[k], b[k]});
    cluster_err[c] = orientation_detail::StaticErr::of(extent);
  }
  // Triangle t against its cluster's detector (uncertain when the detector is not usable).
  auto classify_one = [&](std::int64_t t) {
    const auto& tri = tris[t];
    const std::uint32_t c = asset->triangle_cluster[t];
    if (!det_ok[c]) {
      tcls[t] = static_cast<std::uint8_t>(Orientation::kUncertain);
      return;
    }
    const double* o0 = det0.data() + 3 * std::size_t(c);
    const double* o1 = det1.data() + 3 * std::size_t(c);
    tcls[t] = static_cast<std::uint8_t>(orientation_of(o0, pos0(tri[0]), pos0(tri[1]), pos0(tri[2]),
                                                       o1, pos1(tri[0]), pos1(tri[1]), pos1(tri[2]),
                                                       cluster_err[c]));
  };
#if defined(TETSEG_HAVE_LANES2)
  // Two triangles at once, one per lane of a vector of two doubles: the coefficients are the
  // same operations lane by lane (bitwise classify_one's); the sign per lane as classify_one.
  using orientation_detail::Lanes2;
  auto classify_two = [&](std::int64_t t) {
    const std::uint32_t c[2] = {asset->triangle_cluster[t], asset->triangle_cluster[t + 1]};
    if (!det_ok[c[0]] || !det_ok[c[1]]) {
      classify_one(t);
      classify_one(t + 1);
      return;
    }
    const double* q0[2][4];
    const double* q1[2][4];
    for (int l = 0; l < 2; ++l) {
      const auto& tri = tris[t + l];
      q0[l][0] = det0.data() + 3 * std::size_t(c[l]);
      q1[l][0] = det1.data() + 3 * std::size_t(c[l]);
      for (int j = 0; j < 3; ++j) {
        q0[l][j + 1] = pos0(tri[j]);
        q1[l][j + 1] = pos1(tri[j]);
      }
    }
    using orientation_detail::Vec3T;
    Vec3T<Lanes2> p0[4], p1[4];
    for (int j = 0; j < 4; ++j) {
      p0[j] = {Lanes2{q0[0][j][0], q0[1][j][0]}, Lanes2{q0[0][j][1], q0[1][j][1]},
               Lanes2{q0[0][j][2], q0[1][j][2]}};
      p1[j] = {Lanes2{q1[0][j][0], q1[1][j][0]}, Lanes2{q1[0][j][1], q1[1][j][1]},
               Lanes2{q1[0][j][2], q1[1][j][2]}};
    }
    Lanes2 k[4];
    orientation_detail::orientation_k(p0, p1, k);
    for (int l = 0; l < 2; ++l) {
      const double kl[4] = {k[0][l], k[1][l], k[2][l], k[3][l]};
      bool decided;
      const Orientation o = orientation_detail::static_sign(kl, cluster_err[c[l]], decided);
      tcls[t + l] = static_cast<std::uint8_t>(decided ? o
                                                      : orientation_of(q0[l][0], q0[l][1], q0[l][2],
                                                                       q0[l][3], q1[l][0], q1[l][1],
                                                                       q1[l][2], q1[l][3]));
    }
  };
#endif
  // On the workers from kParallelClassifyItems triangles (stats.step_threads: how many ran it).
  stats.step_threads = 1;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel num_threads(threads) if (parallel && nt >= kParallelClassifyItems)
#endif
  {
#if defined(TETSEG_HAVE_OPENMP)
    if (omp_get_thread_num() == 0)
      stats.step_threads = static_cast<std::uint32_t>(omp_get_num_threads());
#endif
#if defined(TETSEG_HAVE_LANES2)
    const std::int64_t pairs = nt / 2;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for
#endif
    for (std::int64_t i = 0; i < pairs; ++i) classify_two(2 * i);
#else
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for
#endif
    for (std::int64_t t = 0; t < nt; ++t) classify_one(t);
#endif
  }
#if defined(TETSEG_HAVE_LANES2)
  if (nt % 2 != 0) classify_one(nt - 1);
#endif
  std::uint64_t count[3] = {0, 0, 0};
  for (std::uint32_t t = 0; t < tri_count; ++t) ++count[tcls[t]];
  stats.triangles_positive = count[0];
  stats.triangles_negative = count[1];
  stats.triangles_uncertain = count[2];
  sign_wide();  // collider_wide.cpp
  stats.classify_ms = ms_since(t_class);
}

// ---------------------------------------------------------------- public API

Collider::Collider(const Asset& asset, const ColliderOptions& options) noexcept
    : Collider(BodyShape::from_asset(asset), options) {}

Collider::Collider(std::shared_ptr<const BodyShape> shape,
                   const ColliderOptions& options) noexcept {
  try {
    m_impl = std::make_unique<Impl>();
    m_impl->opt = options;
    if (shape) m_impl->construct(std::move(shape), options);
  } catch (...) {
    if (m_impl) {
      m_impl->ctor_status = ColliderStatus::kNotReady;
      m_impl->opt = options;
    }
  }
}

Collider::~Collider() = default;
Collider::Collider(Collider&&) noexcept = default;
Collider& Collider::operator=(Collider&&) noexcept = default;

ColliderStatus Collider::status() const noexcept {
  return m_impl ? m_impl->ctor_status : ColliderStatus::kNotReady;
}

const ColliderOptions& Collider::options() const noexcept {
  static const ColliderOptions kDefault{};
  return m_impl ? m_impl->opt : kDefault;
}

ColliderStatus Collider::step(const double* x0, const double* x1) noexcept {
  if (!m_impl) return ColliderStatus::kNotReady;
  return step(x0, x1, std::size_t(m_impl->node_count) * 3);
}

ColliderStatus Collider::step(const double* x0, const double* x1,
                              std::size_t value_count) noexcept {
  if (!m_impl) return ColliderStatus::kNotReady;
  Impl& s = *m_impl;
  const ColliderStatus st = s.begin_step(x0, x1, value_count);
  if (st != ColliderStatus::kOk) return st;
  if (s.opt.check_first_step && !s.first_step_done) {
    s.first_step_done = true;
    s.rest = check_rest_intersection(x0, value_count);
    s.begin_step(x0, x1, value_count);  // the check reused the step's scratch
  }
  s.first_step_done = true;
  s.refit_and_classify();
  return ColliderStatus::kOk;
}

ColliderStatus Collider::Impl::query_status() const noexcept {
  if (ctor_status != ColliderStatus::kOk) return ColliderStatus::kNotReady;
  return have_step ? ColliderStatus::kOk : ColliderStatus::kNoStep;
}

namespace {

// The Collider's traversal function for answer_any / answer_earliest / answer_contacts.
auto collider_run(Collider::Impl& s) noexcept {
  return [&s](QueryKind kind, Contact* out, std::size_t cap, std::size_t& written) noexcept {
    s.qkind = kind;
    ContactSink sink{out, out ? cap : 0};
    if (!s.run_query(out ? &sink : nullptr)) return ColliderStatus::kOverflow;
    if (kind == QueryKind::kAny) {
      s.cache.any_known = true;
      s.cache.any_value = s.query_hit;
    }
    written = sink.written;
    return ColliderStatus::kOk;
  };
}

}  // namespace

ColliderStatus Collider::any_collision(bool& hit) noexcept {
  hit = false;
  if (!m_impl) return ColliderStatus::kNotReady;
  const ColliderStatus st = m_impl->query_status();
  if (st != ColliderStatus::kOk) return st;
  return answer_any(m_impl->cache, collider_run(*m_impl), hit);
}

ColliderStatus Collider::earliest_toi(EarliestContact& out) noexcept {
  out = EarliestContact{};
  if (!m_impl) return ColliderStatus::kNotReady;
  const ColliderStatus st = m_impl->query_status();
  if (st != ColliderStatus::kOk) return st;
  return answer_earliest(m_impl->cache, collider_run(*m_impl), out);
}

ColliderStatus Collider::contacts(Contact* buffer, std::size_t capacity,
                                  ContactsResult& out) noexcept {
  out = ContactsResult{};
  if (!m_impl) return ColliderStatus::kNotReady;
  const ColliderStatus st = m_impl->query_status();
  if (st != ColliderStatus::kOk) return st;
  return answer_contacts(m_impl->cache, collider_run(*m_impl), buffer, capacity, out);
}

const ColliderStats& Collider::stats() const noexcept {
  static const ColliderStats kEmpty{};
  return m_impl ? m_impl->stats : kEmpty;
}

const RestCheck& Collider::rest_intersection() const noexcept {
  static const RestCheck kEmpty{};
  return m_impl ? m_impl->rest : kEmpty;
}

ColliderStatus Collider::set_detector_positions(const double* d0, const double* d1,
                                                std::size_t value_count) noexcept {
  if (!m_impl) return ColliderStatus::kNotReady;
  return m_impl->set_detector_positions(d0, d1, value_count);
}

Orientation Collider::triangle_class(std::size_t t) const noexcept {
  if (!m_impl || !m_impl->have_step || t >= m_impl->tri_count ||
      m_impl->opt.mode != ColliderMode::kRvbc)
    return Orientation::kUncertain;
  return static_cast<Orientation>(m_impl->tcls[t]);
}

}  // namespace tetseg
