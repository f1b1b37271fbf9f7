// Scene: several bodies in one runtime (scene.hpp). Each body is a collider core
// (Collider::Impl over a shared BodyShape); the scene validates and refits every body per
// step, runs each body's self-collision query and traverses every enabled pair of bodies
// whose swept boxes overlap (body boxes, then BVH against BVH; traverse_bodies).

#include "tetseg/runtime/scene.hpp"

#include <algorithm>
#include <chrono>
#include <new>

#include "collider_impl.hpp"

#if defined(TETSEG_HAVE_OPENMP)
#include <omp.h>
#endif

namespace tetseg {

/// Inter-body traversal stack per worker before any body is added (node pairs); add_body grows
/// it to 8 x (deepest tree + 4), above the sum of two trees' depths that a descent can reach.
inline constexpr std::size_t kSceneInitialStack = 8 * 68;

struct SceneBody {
  std::unique_ptr<Collider::Impl> core;
  BodyOptions options;
  const double* own_x0 = nullptr;  // kOwnPositions layout
  const double* own_x1 = nullptr;
  bool moved = false;  // some node moved this step
  Box box{};           // swept box of the body this step
};

struct Scene::Impl {
  SceneOptions opt;
  std::vector<SceneBody> bodies;
  std::vector<std::uint8_t> pair_enabled;  // upper triangle, index pair_index(a, b)
  std::vector<ColliderStats> pair_stats;
  std::vector<Worker> workers;  // inter-body traversal: one per OpenMP thread, else one
  /// Outcome of one body pair's traversal in a query, merged in pair order.
  struct PairOutcome {
    std::uint32_t a = 0, b = 0;
    bool ran = false, overflow = false, hit = false, has_best = false;
    std::size_t found = 0;
    std::uint64_t contacts = 0;
    Contact best;
  };
  std::vector<PairOutcome> live;  // capacity: every pair (reserved in add_body)
  SceneStats stats;
  bool have_step = false;

  QueryCache cache;  // answers of the current step

  std::size_t pair_index(std::uint32_t a, std::uint32_t b) const noexcept {
    if (a > b) std::swap(a, b);
    return std::size_t(b) * (b - 1) / 2 + a;  // pairs (a < b) ordered by b, then a
  }
  /// A body's step arrays from the global arrays (x0, x1, count) or its own; still bodies
  /// get p1 = p0. kSizeMismatch when a global range exceeds `count`.
  ColliderStatus body_positions(const SceneBody& b, const double* x0, const double* x1,
                                std::size_t count, const double*& p0,
                                const double*& p1) const noexcept {
    p0 = b.own_x0;
    p1 = b.own_x1;
    if (b.options.global_offset != kOwnPositions) {
      const std::size_t first = b.options.global_offset;
      if (first > count / 3 || count / 3 - first < b.core->node_count)
        return ColliderStatus::kSizeMismatch;
      p0 = x0 ? x0 + first * 3 : nullptr;
      p1 = x1 ? x1 + first * 3 : nullptr;
    }
    if (b.options.still) p1 = p0;
    return ColliderStatus::kOk;
  }
  /// The body's box: the union of its trees' root boxes (after a refit).
  static void update_box(SceneBody& b) noexcept {
    const Collider::Impl& core = *b.core;
    const std::uint32_t trees = core.tree_count();
    for (std::uint32_t i = 0; i < trees; ++i) {
      const Box& root = core.tree(i).box[0];
      if (i == 0) {
        b.box = root;
      } else {
        box_union(b.box, root);
      }
    }
  }
  /// Traversal function of the scene's queries (answer_any and the others).
  ColliderStatus run(QueryKind kind, Contact* out, std::size_t cap, std::size_t& written) noexcept;
};

Scene::Scene(const SceneOptions& options) noexcept {
  try {
    m_impl = std::make_unique<Impl>();
    m_impl->opt = options;
    m_impl->workers.resize(worker_count(options.use_openmp, options.threads));
    for (Worker& w : m_impl->workers)
      w.stack.resize(options.traversal_stack > 0 ? options.traversal_stack : kSceneInitialStack);
  } catch (...) {
    m_impl.reset();
  }
}

Scene::~Scene() = default;
Scene::Scene(Scene&&) noexcept = default;
Scene& Scene::operator=(Scene&&) noexcept = default;

ColliderStatus Scene::add_body(std::shared_ptr<const BodyShape> shape, const BodyOptions& options,
                               std::uint32_t* id) noexcept {
  if (!m_impl) return ColliderStatus::kNotReady;
  Impl& s = *m_impl;
  if (!shape || options.mode == ColliderMode::kBrute || options.mode == ColliderMode::kFeatures)
    return ColliderStatus::kInvalidArgument;
  s.have_step = false;
  try {
    ColliderOptions co;
    co.mode = options.mode;
    co.ccd = s.opt.ccd;
    co.bvh_leaf_size = s.opt.bvh_leaf_size;
    co.use_openmp = s.opt.use_openmp;
    co.threads = s.opt.threads;
    co.time_tests = s.opt.time_tests;
    co.include_still_pairs = s.opt.include_still_pairs;
    co.traversal_stack = s.opt.traversal_stack;
    SceneBody body;
    body.core = std::make_unique<Collider::Impl>();
    body.core->construct(std::move(shape), co);
    body.core->body_id = static_cast<std::uint32_t>(s.bodies.size());
    body.core->always_refit = true;
    body.options = options;
    // Inter-body descent depth is at most the sum of two trees' depths.
    const std::size_t depth = std::max<std::size_t>(body.core->topo->max_depth, 64) + 4;
    for (Worker& w : s.workers) {
      if (s.opt.traversal_stack == 0 && w.stack.size() < 8 * depth) w.stack.resize(8 * depth);
      // Plane-minor cache entries of the new body's triangles (inter-body plane filters),
      // at plane_base[body id]; an earlier failed add_body may have left unused entries.
      const std::size_t base = std::max(w.plane.size(), w.plane_step.size());
      w.plane_base.reserve(s.bodies.size() + 1);
      w.plane.resize(base + body.core->tri_count);
      w.plane_step.resize(base + body.core->tri_count, 0);
      w.plane_base.resize(s.bodies.size());  // drops a failed add_body's entry
      w.plane_base.push_back(static_cast<std::uint32_t>(base));
    }
    const std::size_t n = s.bodies.size() + 1;
    s.pair_enabled.resize(n * (n - 1) / 2, 1);
    s.pair_stats.resize(n * (n - 1) / 2);
    s.live.reserve(n * (n - 1) / 2);
    s.bodies.push_back(std::move(body));
  } catch (...) {
    return ColliderStatus::kNotReady;
  }
  if (id) *id = static_cast<std::uint32_t>(s.bodies.size() - 1);
  return ColliderStatus::kOk;
}

std::uint32_t Scene::body_count() const noexcept {
  return m_impl ? static_cast<std::uint32_t>(m_impl->bodies.size()) : 0;
}

ColliderStatus Scene::set_self_collision(std::uint32_t body, bool enabled) noexcept {
  if (!m_impl) return ColliderStatus::kNotReady;
  if (body >= m_impl->bodies.size()) return ColliderStatus::kInvalidArgument;
  m_impl->bodies[body].options.self_collision = enabled;
  m_impl->cache = QueryCache{};
  return ColliderStatus::kOk;
}

ColliderStatus Scene::set_pair_enabled(std::uint32_t a, std::uint32_t b, bool enabled) noexcept {
  if (!m_impl) return ColliderStatus::kNotReady;
  Impl& s = *m_impl;
  if (a == b || a >= s.bodies.size() || b >= s.bodies.size())
    return ColliderStatus::kInvalidArgument;
  s.pair_enabled[s.pair_index(a, b)] = enabled ? 1 : 0;
  s.cache = QueryCache{};
  return ColliderStatus::kOk;
}

ColliderStatus Scene::set_positions(std::uint32_t body, const double* x0, const double* x1,
                                    std::size_t value_count) noexcept {
  if (!m_impl) return ColliderStatus::kNotReady;
  Impl& s = *m_impl;
  if (body >= s.bodies.size() || s.bodies[body].options.global_offset != kOwnPositions)
    return ColliderStatus::kInvalidArgument;
  SceneBody& b = s.bodies[body];
  if (value_count != std::size_t(b.core->node_count) * 3) return ColliderStatus::kSizeMismatch;
  b.own_x0 = x0;
  b.own_x1 = x1;
  // The current step read the old arrays: queries now need a new step (never an answer
  // from positions the caller may have released).
  s.have_step = false;
  return ColliderStatus::kOk;
}

ColliderStatus Scene::set_detector_positions(std::uint32_t body, const double* d0, const double* d1,
                                             std::size_t value_count) noexcept {
  if (!m_impl) return ColliderStatus::kNotReady;
  if (body >= m_impl->bodies.size()) return ColliderStatus::kInvalidArgument;
  return m_impl->bodies[body].core->set_detector_positions(d0, d1, value_count);
}

ColliderStatus Scene::step(const double* x0, const double* x1, std::size_t value_count) noexcept {
  if (!m_impl) return ColliderStatus::kNotReady;
  Impl& s = *m_impl;
  s.have_step = false;
  s.stats = SceneStats{};
  s.cache = QueryCache{};
  for (ColliderStats& p : s.pair_stats) p = ColliderStats{};
  // Validate every body before refitting any.
  for (SceneBody& b : s.bodies) {
    Collider::Impl& core = *b.core;
    const double *p0 = nullptr, *p1 = nullptr;
    ColliderStatus st = s.body_positions(b, x0, x1, value_count, p0, p1);
    if (st == ColliderStatus::kOk) st = core.begin_step(p0, p1, std::size_t(core.node_count) * 3);
    if (st != ColliderStatus::kOk) {
      for (SceneBody& other : s.bodies) other.core->have_step = false;
      return st;
    }
  }
  for (SceneBody& b : s.bodies) {
    Collider::Impl& core = *b.core;
    core.refit_and_classify();
    // Without the still rule every body takes part, moved or not.
    b.moved = core.stats.nodes_moved > 0 || s.opt.include_still_pairs;
    s.stats.bodies_moved += b.moved ? 1 : 0;
    s.stats.refit_ms += core.stats.refit_ms;
    s.stats.classify_ms += core.stats.classify_ms;
    Impl::update_box(b);
  }
  s.have_step = true;
  return ColliderStatus::kOk;
}

// Runs one query over the scene: self queries of the bodies, then the enabled pairs of bodies
// in order (a, b) with a < b (ordered by b, then a). `out`/`cap`: optional buffer shared by
// all parts (ContactSink: it keeps the smallest contacts, whoever finds them). Pairs run on
// OpenMP threads when enabled; outcomes are merged in pair order, so every answer and count
// equals the serial one. A kAny query answers
// "hit" when any part finds a contact, and kOverflow only when none does and a part overflowed.
ColliderStatus Scene::Impl::run(QueryKind kind, Contact* out, std::size_t cap,
                                std::size_t& written) noexcept {
  written = 0;
  // One buffer for every part of the query: it keeps the smallest contacts of all of them.
  ContactSink sink{out, out ? cap : 0};
  std::size_t found = 0;
  bool has = false, overflow = false;
  Contact first;
  const auto t_self = Clock::now();
  for (SceneBody& b : bodies) {
    if (!b.options.self_collision || !b.moved) continue;
    Collider::Impl& core = *b.core;
    core.qkind = kind;
    const std::uint64_t contacts_before = core.stats.contacts;
    const bool ok = core.run_query(out ? &sink : nullptr);
    stats.contacts += core.stats.contacts - contacts_before;
    if (!ok) {
      if (kind == QueryKind::kFull) return ColliderStatus::kOverflow;
      overflow = true;
      continue;
    }
    if (kind == QueryKind::kAny) {
      if (core.query_hit) {
        cache.any_known = cache.any_value = true;
        stats.self_ms += ms_since(t_self);
        return ColliderStatus::kOk;
      }
      continue;
    }
    found += core.cache.full_found;
    keep_earliest(has, first, core.cache.has_best, core.cache.best);
  }
  stats.self_ms += ms_since(t_self);

  // Body pairs: culled by the switches, the still rule and the body boxes.
  const auto t_pairs = Clock::now();
  const double ms = opt.ccd.min_separation;
  std::uint64_t skipped = 0;
  live.clear();  // within the capacity reserved by add_body
  const std::uint32_t n = static_cast<std::uint32_t>(bodies.size());
  for (std::uint32_t bi = 1; bi < n; ++bi) {
    for (std::uint32_t ai = 0; ai < bi; ++ai) {
      const SceneBody& A = bodies[ai];
      const SceneBody& B = bodies[bi];
      if (!pair_enabled[pair_index(ai, bi)] || (!A.moved && !B.moved) ||
          !boxes_overlap(A.box, B.box, ms)) {
        ++skipped;
        continue;
      }
      PairOutcome p;
      p.a = ai;
      p.b = bi;
      live.push_back(p);
    }
  }
  bool stop = false;  // kAny: a pair found a contact (read racily: only saves work)
  auto run_pair = [&](Worker& w, PairOutcome& p) {
    w.reset();
    w.qkind = kind;
    w.sink = out ? &sink : nullptr;
    p.overflow = !traverse_bodies(w, *bodies[p.a].core, *bodies[p.b].core);
    p.ran = true;
    p.hit = w.stop;
    p.found = w.found;
    p.has_best = w.has_best;
    p.best = w.best;
    p.contacts = w.stats.contacts;
    add_counts(pair_stats[pair_index(p.a, p.b)], w.stats);
  };
  const std::int64_t count = static_cast<std::int64_t>(live.size());
  stats.pair_threads = 1;
#if defined(TETSEG_HAVE_OPENMP)
  if (workers.size() > 1 && count > 1) {
    sink.locked = true;
#pragma omp parallel num_threads(static_cast <int>(workers.size()))
    {
      Worker& w = workers[static_cast<std::size_t>(omp_get_thread_num())];
#pragma omp single
      stats.pair_threads = static_cast<std::uint32_t>(omp_get_num_threads());
#pragma omp for schedule(dynamic, 1)
      for (std::int64_t k = 0; k < count; ++k) {
        bool stopped;
#pragma omp atomic read
        stopped = stop;
        if (stopped) continue;
        run_pair(w, live[static_cast<std::size_t>(k)]);
        if (kind == QueryKind::kAny && live[static_cast<std::size_t>(k)].hit) {
#pragma omp atomic write
          stop = true;
        }
      }
    }
  } else
#endif
  {
    for (PairOutcome& p : live) {
      run_pair(workers[0], p);
      if (p.overflow && kind == QueryKind::kFull) break;
      if (p.hit && kind == QueryKind::kAny) break;
    }
  }
  // Merge in pair order.
  bool hit = false;
  for (const PairOutcome& p : live) {
    if (!p.ran) continue;
    stats.contacts += p.contacts;
    overflow = overflow || p.overflow;
    hit = hit || p.hit;
    found += p.found;
    keep_earliest(has, first, p.has_best, p.best);
  }
  stats.pairs_ms += ms_since(t_pairs);
  if (kind == QueryKind::kAny && hit) {
    cache.any_known = cache.any_value = true;
    return ColliderStatus::kOk;
  }
  if (overflow) return ColliderStatus::kOverflow;
  cache.any_known = true;
  cache.any_value = found > 0;
  if (kind == QueryKind::kFull) {
    stats.body_pairs_tested = live.size();
    stats.body_pairs_skipped = skipped;
    cache.set_full(found, has, first);
  }
  written = sink.written;
  return ColliderStatus::kOk;
}

namespace {

// The scene's traversal function for answer_any / answer_earliest / answer_contacts.
auto scene_run(Scene::Impl& s) noexcept {
  return [&s](QueryKind kind, Contact* out, std::size_t cap, std::size_t& written) noexcept {
    return s.run(kind, out, cap, written);
  };
}

ColliderStatus scene_ready(const std::unique_ptr<Scene::Impl>& s) noexcept {
  if (!s) return ColliderStatus::kNotReady;
  return s->have_step ? ColliderStatus::kOk : ColliderStatus::kNoStep;
}

}  // namespace

ColliderStatus Scene::any_collision(bool& hit) noexcept {
  hit = false;
  const ColliderStatus st = scene_ready(m_impl);
  return st != ColliderStatus::kOk ? st : answer_any(m_impl->cache, scene_run(*m_impl), hit);
}

ColliderStatus Scene::earliest_toi(EarliestContact& out) noexcept {
  out = EarliestContact{};
  const ColliderStatus st = scene_ready(m_impl);
  return st != ColliderStatus::kOk ? st : answer_earliest(m_impl->cache, scene_run(*m_impl), out);
}

ColliderStatus Scene::contacts(Contact* buffer, std::size_t capacity,
                               ContactsResult& out) noexcept {
  out = ContactsResult{};
  const ColliderStatus st = scene_ready(m_impl);
  return st != ColliderStatus::kOk
             ? st
             : answer_contacts(m_impl->cache, scene_run(*m_impl), buffer, capacity, out);
}

RestCheck Scene::check_rest_intersection(const double* x, std::size_t value_count) noexcept {
  RestCheck r;
  if (!m_impl) {
    r.status = ColliderStatus::kNotReady;
    return r;
  }
  Impl& s = *m_impl;
  s.have_step = false;  // the check reuses the step scratch
  s.cache = QueryCache{};
  auto finish = [&s](RestCheck result) {
    for (SceneBody& b : s.bodies) {
      b.core->rest_mode = false;
      b.core->have_step = false;
      b.core->stats = ColliderStats{};
    }
    return result;
  };
  // Each body with self-collision on, as Collider::check_rest_intersection.
  for (SceneBody& b : s.bodies) {
    const double *p0 = nullptr, *p1 = nullptr;
    r.status = s.body_positions(b, x, x, value_count, p0, p1);
    if (r.status != ColliderStatus::kOk) return finish(r);
    if (!b.options.self_collision) continue;
    r = b.core->rest_check(p0, std::size_t(b.core->node_count) * 3);
    if (r.status != ColliderStatus::kOk || r.intersecting) return finish(r);
  }
  // Every enabled pair of bodies with overlapping boxes: static boxes, every tree pair.
  for (SceneBody& b : s.bodies) {
    Collider::Impl& core = *b.core;
    const double *p0 = nullptr, *p1 = nullptr;
    r.status = s.body_positions(b, x, x, value_count, p0, p1);
    if (r.status == ColliderStatus::kOk)
      r.status = core.begin_step(p0, p0, std::size_t(core.node_count) * 3, true);
    if (r.status != ColliderStatus::kOk) return finish(r);
    core.rest_mode = true;
    core.refit_and_classify();
    Impl::update_box(b);
  }
  Worker& w = s.workers[0];
  const std::uint32_t n = static_cast<std::uint32_t>(s.bodies.size());
  for (std::uint32_t bi = 1; bi < n; ++bi) {
    for (std::uint32_t ai = 0; ai < bi; ++ai) {
      const Collider::Impl& A = *s.bodies[ai].core;
      const Collider::Impl& B = *s.bodies[bi].core;
      if (!s.pair_enabled[s.pair_index(ai, bi)] ||
          !boxes_overlap(s.bodies[ai].box, s.bodies[bi].box, 0.0))
        continue;
      w.reset();
      w.qkind = QueryKind::kAny;
      if (!traverse_bodies(w, A, B, true)) {
        r.status = ColliderStatus::kOverflow;
        return finish(r);
      }
      if (w.rest_hit) {
        r.intersecting = true;
        r.triangle_a = w.rest_a;
        r.triangle_b = w.rest_b;
        r.bodies = {ai, bi};
        return finish(r);
      }
    }
  }
  return finish(r);
}

const SceneStats& Scene::stats() const noexcept {
  static const SceneStats kEmpty{};
  return m_impl ? m_impl->stats : kEmpty;
}

const ColliderStats& Scene::body_stats(std::uint32_t body) const noexcept {
  static const ColliderStats kEmpty{};
  if (!m_impl || body >= m_impl->bodies.size()) return kEmpty;
  return m_impl->bodies[body].core->stats;
}

const ColliderStats& Scene::pair_stats(std::uint32_t a, std::uint32_t b) const noexcept {
  static const ColliderStats kEmpty{};
  if (!m_impl || a == b || a >= m_impl->bodies.size() || b >= m_impl->bodies.size()) return kEmpty;
  return m_impl->pair_stats[m_impl->pair_index(a, b)];
}

}  // namespace tetseg
