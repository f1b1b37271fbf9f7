// tetseg.BodyShape and tetseg.Scene: the runtime's scene API (several bodies) from Python
// (docs/python.md, "Scenes"). Arrays handed to `set_positions` and `step` are used in place and
// referenced for as long as the C++ scene may read them.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "runtime_binding.hpp"
#include "tetseg/runtime/body_shape.hpp"
#include "tetseg/runtime/scene.hpp"

namespace tetseg::python {
namespace {

using ShapePtr = std::shared_ptr<const BodyShape>;

/// A shape as the scene holds it: it also owns the asset a tet body's shape reads, so a scene
/// keeps working after the caller drops the Asset and the BodyShape.
ShapePtr shape_owning(ShapePtr shape, AssetPtr asset) {
  struct Owner {
    AssetPtr asset;
    ShapePtr shape;
  };
  auto owner = std::make_shared<Owner>(Owner{std::move(asset), std::move(shape)});
  const BodyShape* raw = owner->shape.get();
  return ShapePtr(std::move(owner), raw);
}

struct PyBodyShape {
  ShapePtr shape;
  py::object asset = py::none();  // the Asset of a tet body, None for a surface-only body
};

PyBodyShape shape_from_asset(const py::object& asset) {
  if (!py::isinstance<PyAsset>(asset))
    throw py::type_error("BodyShape.from_asset expects a tetseg.Asset (see tetseg.load_asset)");
  const AssetPtr a = asset.cast<const PyAsset&>().asset;
  ShapePtr shape;
  {
    py::gil_scoped_release release;
    shape = BodyShape::from_asset(*a);
  }
  if (!shape) throw std::bad_alloc();
  return PyBodyShape{shape_owning(std::move(shape), a), asset};
}

/// `triangles`: an integer array-like of shape (M, 3) with node ids in [0, node_count), three
/// distinct per triangle (checked here so that the message says which triangle is wrong).
PyBodyShape shape_from_triangles(const py::object& triangles, std::int64_t node_count) {
  if (node_count < 0 || node_count > std::int64_t(UINT32_MAX))
    throw py::value_error("node_count must be in [0, 2**32), got " + std::to_string(node_count));
  const py::array any = py::array::ensure(triangles);
  if (!any || (any.dtype().kind() != 'i' && any.dtype().kind() != 'u'))
    throw py::type_error("triangles must be an integer array of shape (M, 3)");
  const auto ids =
      py::array_t<std::int64_t, py::array::c_style | py::array::forcecast>::ensure(any);
  if (!ids || ids.ndim() != 2 || ids.shape(1) != 3)
    throw py::value_error("triangles must have shape (M, 3), got " +
                          std::string(py::str(any.attr("shape"))));
  const auto count = static_cast<std::size_t>(ids.shape(0));
  std::vector<std::uint32_t> flat(count * 3);
  const std::int64_t* v = ids.data();
  for (std::size_t t = 0; t < count; ++t) {
    for (int k = 0; k < 3; ++k) {
      if (v[3 * t + k] < 0 || v[3 * t + k] >= node_count)
        throw py::value_error("triangle " + std::to_string(t) + " has node id " +
                              std::to_string(v[3 * t + k]) +
                              " outside [0, node_count = " + std::to_string(node_count) + ")");
      flat[3 * t + k] = static_cast<std::uint32_t>(v[3 * t + k]);
    }
    if (v[3 * t] == v[3 * t + 1] || v[3 * t + 1] == v[3 * t + 2] || v[3 * t] == v[3 * t + 2])
      throw py::value_error("triangle " + std::to_string(t) + " repeats a node");
  }
  ShapePtr shape;
  {
    py::gil_scoped_release release;
    shape = BodyShape::from_triangles(flat.data(), count, static_cast<std::uint32_t>(node_count));
  }
  if (!shape) throw std::bad_alloc();  // the ids were checked above
  return PyBodyShape{std::move(shape), py::none()};
}

py::dict scene_stats_dict(const SceneStats& s) {
  py::dict d;
  d["refit_ms"] = s.refit_ms;
  d["classify_ms"] = s.classify_ms;
  d["self_ms"] = s.self_ms;
  d["pairs_ms"] = s.pairs_ms;
  d["bodies_moved"] = s.bodies_moved;
  d["body_pairs_tested"] = s.body_pairs_tested;
  d["body_pairs_skipped"] = s.body_pairs_skipped;
  d["contacts"] = s.contacts;
  return d;
}

/// What the binding knows of a body: enough for array checks and messages, and the arrays
/// the C++ scene reads (its own layout) kept referenced until replaced.
struct BodyRecord {
  std::uint32_t node_count = 0;
  bool still = false;
  bool global = false;
  std::size_t global_offset = 0;
  std::uint32_t cluster_count = 0;  // of the body's asset (0 for a surface-only body)
  bool bones = false;               // the asset's detectors are carried by bones
  py::object x0 = py::none(), x1 = py::none();
  py::object d0 = py::none(), d1 = py::none();  // detector positions of a 'bones' asset
};

class PyScene {
 public:
  explicit PyScene(const SceneOptions& options) : m_options(options) {
    py::gil_scoped_release release;
    m_scene = std::make_unique<Scene>(options);
  }

  std::uint32_t add_body(const py::object& shape_object, const std::string& mode, bool still,
                         bool self_collision, const py::object& global_offset) {
    if (!py::isinstance<PyBodyShape>(shape_object))
      throw py::type_error("add_body expects a tetseg.BodyShape");
    const ShapePtr& shape = shape_object.cast<const PyBodyShape&>().shape;
    BodyOptions options;
    if (!parse_collider_mode(mode.c_str(), options.mode))
      throw py::value_error("unknown mode '" + mode + "' (rvbc, bvh, cone)");
    options.still = still;
    options.self_collision = self_collision;
    if (!global_offset.is_none()) {
      if (!py::isinstance<py::int_>(global_offset))
        throw py::type_error("global_offset must be an int or None");
      const auto offset = global_offset.cast<std::int64_t>();
      if (offset < 0) throw py::value_error("global_offset must be >= 0 or None");
      options.global_offset = static_cast<std::size_t>(offset);
    }
    Busy busy = m_queries.lock();
    std::uint32_t id = 0;
    ColliderStatus status;
    {
      py::gil_scoped_release release;
      status = m_scene->add_body(shape, options, &id);
    }
    m_queries.invalidated("a body was added: call step() first");
    if (status != ColliderStatus::kOk)
      raise_status(errors().collider, "add_body", to_string(status),
                   options.mode == ColliderMode::kBrute ? "mode 'brute' is not available in a scene"
                   : status == ColliderStatus::kNotReady ? "out of memory"
                                                         : "");
    BodyRecord record;
    record.node_count = shape->node_count();
    record.still = still;
    record.global = !global_offset.is_none();
    record.global_offset = options.global_offset;
    const py::object& asset = shape_object.cast<const PyBodyShape&>().asset;
    if (!asset.is_none()) {
      const AssetPtr& a = asset.cast<const PyAsset&>().asset;
      record.cluster_count = static_cast<std::uint32_t>(a->cluster_count());
      record.bones = a->data().detector_form == format::DetectorForm::kBones;
    }
    m_bodies.push_back(std::move(record));
    return id;
  }

  void set_self_collision(std::int64_t body, bool enabled) {
    Busy busy = m_queries.lock();
    const std::uint32_t b = body_id("set_self_collision", body);
    check(m_scene->set_self_collision(b, enabled), "set_self_collision", "");
  }

  void set_pair_enabled(std::int64_t a, std::int64_t b, bool enabled) {
    Busy busy = m_queries.lock();
    const std::uint32_t ia = body_id("set_pair_enabled", a), ib = body_id("set_pair_enabled", b);
    check(m_scene->set_pair_enabled(ia, ib, enabled), "set_pair_enabled",
          "a pair needs two different bodies");
  }

  void set_positions(std::int64_t body, const py::object& x0, const py::object& x1) {
    Busy busy = m_queries.lock();
    const std::uint32_t b = body_id("set_positions", body);
    BodyRecord& record = m_bodies[b];
    if (record.global)
      raise_status(errors().collider, "set_positions", to_string(ColliderStatus::kInvalidArgument),
                   "body " + std::to_string(b) +
                       " reads the global arrays of step() (global_offset " +
                       std::to_string(record.global_offset) + ")");
    const std::string meaning = "body " + std::to_string(b) + "'s node count";
    const double* p0 = positions_of("x0", x0, record.node_count, meaning.c_str());
    const double* p1 = nullptr;
    if (!x1.is_none()) {
      p1 = positions_of("x1", x1, record.node_count, meaning.c_str());
    } else if (!record.still) {
      throw py::value_error("x1 is required: body " + std::to_string(b) + " is not still");
    }
    check(m_scene->set_positions(b, p0, p1, std::size_t(record.node_count) * 3), "set_positions",
          "");
    // The scene reads them at every step until replaced. set_positions ends the current step
    // (the runtime answers kNoStep); the binding names the reason in its error.
    record.x0 = x0;
    record.x1 = x1;
    m_queries.invalidated("set_positions gave new positions: call step() first");
  }

  void set_detector_positions(std::int64_t body, const py::object& d0, const py::object& d1) {
    Busy busy = m_queries.lock();
    const std::uint32_t b = body_id("set_detector_positions", body);
    BodyRecord& record = m_bodies[b];
    const double* p0 = detector_positions_of("d0", d0, record.cluster_count);
    const double* p1 = detector_positions_of("d1", d1, record.cluster_count);
    check(m_scene->set_detector_positions(b, p0, p1, std::size_t(record.cluster_count) * 3),
          "set_detector_positions",
          "body " + std::to_string(b) + "'s detectors are not carried by bones");
    // Read at every following step: referenced until replaced.
    record.d0 = d0;
    record.d1 = d1;
  }

  void step(const py::object& x0, const py::object& x1) {
    const double *p0 = nullptr, *p1 = nullptr;
    std::size_t values = 0;
    if (!x0.is_none()) {
      p0 = positions_of("x0", x0, kAnyRows, "the global node count");
      values = rows_of(x0) * 3;
    }
    if (!x1.is_none()) {
      if (x0.is_none()) throw py::value_error("x1 without x0: pass the global x0 as well");
      const std::string meaning = "the rows of x0";
      p1 = positions_of("x1", x1, values / 3, meaning.c_str());
    }
    Busy busy = m_queries.lock();
    ColliderStatus status;
    {
      py::gil_scoped_release release;
      status = call_step(*m_scene, p0, p1, values);
    }
    // The scene may keep the global pointers: hold the new arrays whatever the outcome.
    m_x0 = x0;
    m_x1 = x1;
    m_queries.stepped(status);
    if (status != ColliderStatus::kOk)
      raise_status(errors().collider, "step", to_string(status), positions_failure(status));
  }

  py::dict check_rest_intersection(const py::object& x) {
    const double* p = nullptr;
    std::size_t values = 0;
    if (!x.is_none()) {
      p = positions_of("x", x, kAnyRows, "the global node count");
      values = rows_of(x) * 3;
    }
    Busy busy = m_queries.lock();
    RestCheck result;
    ColliderStatus status;
    {
      py::gil_scoped_release release;
      status = call_check_rest_intersection(*m_scene, p, values, result);
    }
    m_queries.invalidated("check_rest_intersection reused the step scratch: call step() again");
    if (status != ColliderStatus::kOk)
      raise_status(errors().collider, "check_rest_intersection", to_string(status),
                   positions_failure(status));
    return rest_check_dict(result);
  }

  bool any_collision() { return m_queries.any_collision(*m_scene); }
  py::object earliest_toi() { return m_queries.earliest_toi(*m_scene); }
  py::array contacts() { return m_queries.contacts(*m_scene); }

  py::dict stats() {
    Busy busy = m_queries.lock();
    return scene_stats_dict(m_scene->stats());
  }
  py::dict body_stats(std::int64_t body) {
    Busy busy = m_queries.lock();
    return stats_dict(m_scene->body_stats(body_id("body_stats", body)));
  }
  py::dict pair_stats(std::int64_t a, std::int64_t b) {
    Busy busy = m_queries.lock();
    const std::uint32_t ia = body_id("pair_stats", a), ib = body_id("pair_stats", b);
    if (ia == ib)
      raise_status(errors().collider, "pair_stats", to_string(ColliderStatus::kInvalidArgument),
                   "a pair needs two different bodies");
    return stats_dict(m_scene->pair_stats(ia, ib));
  }
  std::size_t body_count() const { return m_bodies.size(); }
  py::dict options() const {
    py::dict d;
    d["min_separation"] = m_options.ccd.min_separation;
    d["time_tolerance"] = m_options.ccd.time_tolerance;
    d["max_intervals"] = m_options.ccd.max_intervals;
    d["bvh_leaf_size"] = m_options.bvh_leaf_size;
    d["use_openmp"] = m_options.use_openmp;
    d["time_tests"] = m_options.time_tests;
    d["traversal_stack"] = m_options.traversal_stack;
    d["include_still_pairs"] = m_options.include_still_pairs;
    d["threads"] = m_options.threads;
    return d;
  }

 private:
  /// `body` as a body id, or ColliderError (invalid argument) naming it.
  std::uint32_t body_id(const char* what, std::int64_t body) const {
    if (body < 0 || static_cast<std::uint64_t>(body) >= m_bodies.size())
      raise_status(errors().collider, what, to_string(ColliderStatus::kInvalidArgument),
                   "unknown body " + std::to_string(body) + " (the scene has " +
                       std::to_string(m_bodies.size()) + " bodies)");
    return static_cast<std::uint32_t>(body);
  }

  static void check(ColliderStatus status, const char* what, const std::string& detail) {
    if (status != ColliderStatus::kOk)
      raise_status(errors().collider, what, to_string(status), detail);
  }

  /// Detail of a failed step or static check, from what the binding knows of the bodies.
  std::string positions_failure(ColliderStatus status) const {
    switch (status) {
      case ColliderStatus::kNullInput:
        for (std::size_t b = 0; b < m_bodies.size(); ++b) {
          const BodyRecord& r = m_bodies[b];
          const std::string body = "body " + std::to_string(b);
          if (r.global && m_x0.is_none()) return body + " reads the global x0: pass it to step";
          if (r.global && !r.still && m_x1.is_none())
            return body + " is not still and reads the global x1: pass it to step";
          if (!r.global && r.x0.is_none()) return body + " has no positions: call set_positions";
          if (r.bones && r.d0.is_none())
            return body + "'s detectors are carried by bones: call set_detector_positions";
        }
        return "missing positions";
      case ColliderStatus::kSizeMismatch: {
        const std::size_t rows = m_x0.is_none() ? 0 : rows_of(m_x0);
        for (std::size_t b = 0; b < m_bodies.size(); ++b) {
          const BodyRecord& r = m_bodies[b];
          if (r.global && r.global_offset + r.node_count > rows)
            return "body " + std::to_string(b) + " reads global rows [" +
                   std::to_string(r.global_offset) + ", " +
                   std::to_string(r.global_offset + r.node_count) +
                   ") but the global arrays have " + std::to_string(rows) + " rows (step(x0, x1))";
        }
        return "a body's global range exceeds the rows of the global arrays";
      }
      default:
        return step_failure_detail(status);
    }
  }

  SceneOptions m_options;
  std::unique_ptr<Scene> m_scene;
  std::vector<BodyRecord> m_bodies;  // released before m_scene, whose destructor reads none
  py::object m_x0 = py::none(), m_x1 = py::none();  // the global arrays of the last step
  StepQueries m_queries{"Scene", "step()"};
};

}  // namespace

void bind_scene(py::module_& m) {
  py::class_<PyBodyShape>(m, "BodyShape",
                          "The immutable surface topology of one body, shared by any number of "
                          "scene bodies. Build it with BodyShape.from_asset (a tet body) or "
                          "BodyShape.from_triangles (a surface-only body).")
      .def_static("from_asset", &shape_from_asset, py::arg("asset"),
                  "Topology of an asset's surface (a tet body: radial-view culling inside it). "
                  "The shape keeps the asset alive.")
      .def_static("from_triangles", &shape_from_triangles, py::arg("triangles"),
                  py::arg("node_count"),
                  "Topology of a triangle mesh with no asset (obstacles, cloth, shells, soups; "
                  "overlap culling only): triangles is an integer (M, 3) array of node ids in "
                  "[0, node_count) (e.g. node_count = len(points)), three distinct per "
                  "triangle (else ValueError). Copied.")
      .def_property_readonly(
          "node_count", [](const PyBodyShape& s) { return s.shape->node_count(); },
          "Rows of the body's position arrays.")
      .def_property_readonly(
          "triangle_count", [](const PyBodyShape& s) { return s.shape->triangle_count(); },
          "Surface triangles.")
      .def_property_readonly(
          "has_clusters", [](const PyBodyShape& s) { return s.shape->has_clusters(); },
          "True for a shape from an asset (rvbc culling available).")
      .def_property_readonly(
          "asset", [](const PyBodyShape& s) { return s.asset; },
          "The Asset of a tet body's shape, None for a surface-only shape.")
      .def("__repr__", [](const PyBodyShape& s) {
        return "<tetseg.BodyShape: " + std::to_string(s.shape->node_count()) + " nodes, " +
               std::to_string(s.shape->triangle_count()) + " triangles" +
               (s.shape->has_clusters() ? ", from an asset>" : ", surface only>");
      });

  const SceneOptions defaults;
  py::class_<PyScene>(
      m, "Scene",
      "Continuous collision queries over several bodies, step by step (docs/runtime.md, "
      "'Scenes'): each body's self-collision and every enabled pair of bodies.\n\n"
      "Add bodies with add_body; per step give positions (set_positions per body and/or "
      "global arrays to step), call step(), then any of any_collision(), earliest_toi(), "
      "contacts(). One thread at a time per Scene; shapes may be shared. The GIL is released "
      "during steps and queries.")
      .def(py::init([](double min_separation, double time_tolerance, std::uint32_t max_intervals,
                       std::uint32_t bvh_leaf_size, bool use_openmp, bool time_tests,
                       std::uint32_t traversal_stack, bool include_still_pairs,
                       std::uint32_t threads) {
             SceneOptions o;
             o.ccd.min_separation = min_separation;
             o.ccd.time_tolerance = time_tolerance;
             o.ccd.max_intervals = max_intervals;
             o.bvh_leaf_size = bvh_leaf_size;
             o.use_openmp = use_openmp;
             o.time_tests = time_tests;
             o.traversal_stack = traversal_stack;
             o.include_still_pairs = include_still_pairs;
             o.threads = threads;
             return std::make_unique<PyScene>(o);
           }),
           py::kw_only(), py::arg("min_separation") = defaults.ccd.min_separation,
           py::arg("time_tolerance") = defaults.ccd.time_tolerance,
           py::arg("max_intervals") = defaults.ccd.max_intervals,
           py::arg("bvh_leaf_size") = defaults.bvh_leaf_size,
           py::arg("use_openmp") = defaults.use_openmp, py::arg("time_tests") = defaults.time_tests,
           py::arg("traversal_stack") = defaults.traversal_stack,
           py::arg("include_still_pairs") = defaults.include_still_pairs,
           py::arg("threads") = defaults.threads,
           "An empty scene. Options as tetseg::SceneOptions (docs/runtime.md): min_separation, "
           "time_tolerance and max_intervals go to the elementary tests; traversal_stack 0 "
           "never overflows (small values are for tests: queries then raise ColliderError "
           "'traversal stack overflow'); include_still_pairs also tests feature pairs whose "
           "four nodes do not move, still bodies included (skipped by default); threads is the "
           "OpenMP thread count with use_openmp (0: OpenMP's default).")
      .def("add_body", &PyScene::add_body, py::arg("shape"), py::kw_only(),
           py::arg("mode") = std::string(to_string(BodyOptions{}.mode)), py::arg("still") = false,
           py::arg("self_collision") = true, py::arg("global_offset") = py::none(),
           "Returns the new body's id (0, 1, ... in order). Adds a body over a BodyShape and "
           "allocates its scratch; every pair with it is enabled. mode: self-collision method "
           "'rvbc' (a surface-only body uses 'bvh'), 'bvh' or 'cone' ('brute' raises "
           "ColliderError). still: only x0 is read, for both ends of every step. global_offset: "
           "None (positions by set_positions) or the row of the body's node 0 in the global "
           "arrays passed to step. The scene holds the shape (and its asset).")
      .def("set_self_collision", &PyScene::set_self_collision, py::arg("body"), py::arg("enabled"),
           "Switches a body's self-collision.")
      .def("set_pair_enabled", &PyScene::set_pair_enabled, py::arg("a"), py::arg("b"),
           py::arg("enabled"), "Switches the collision between bodies a != b.")
      .def("set_positions", &PyScene::set_positions, py::arg("body"), py::arg("x0"),
           py::arg("x1") = py::none(),
           "Positions of a body with its own arrays (no global_offset): (node_count, 3) "
           "C-contiguous float64 arrays, used in place (not copied) and referenced by the "
           "scene until replaced, for every following step; do not modify them during a step. "
           "x1 may be None only for a still body. Checked for NaN at step.")
      .def("set_detector_positions", &PyScene::set_detector_positions, py::arg("body"),
           py::arg("d0"), py::arg("d1"),
           "Detector positions of a body whose asset's detectors are carried by bones, as "
           "Collider.set_detector_positions: (cluster_count, 3) C-contiguous float64 arrays "
           "used in place and read at every following step until replaced. ColliderError "
           "('invalid argument') for another body.")
      .def("step", &PyScene::step, py::arg("x0") = py::none(), py::arg("x1") = py::none(),
           "Starts a step of every body: x0, x1 are the global (n, 3) C-contiguous float64 "
           "arrays read by the bodies with a global_offset (None when there are none; x1 None "
           "when those are all still), used in place and referenced until the next step. "
           "Raises ColliderError naming the status ('null input', 'size mismatch', "
           "'non-finite position'); then no step is valid.")
      .def("any_collision", &PyScene::any_collision,
           "Whether any feature pair of the scene is in contact during the step. Raises "
           "ColliderError without a valid step.")
      .def("earliest_toi", &PyScene::earliest_toi,
           "The earliest contact of the step as a numpy.void record of CONTACT_DTYPE, or None. "
           "Raises ColliderError without a valid step.")
      .def("contacts", &PyScene::contacts,
           "An ndarray of CONTACT_DTYPE: all contacts of the step, sorted by toi, kind, bodies, "
           "nodes. nodes are local to their body: nodes[0] (the vertex, or the first edge) in "
           "bodies[0], the rest in bodies[1]. Raises ColliderError without a valid step.")
      .def("check_rest_intersection", &PyScene::check_rest_intersection, py::arg("x") = py::none(),
           "Returns dict(intersecting, triangle_a, triangle_b, bodies). Static check of a start "
           "state: x is the global array (None without global bodies); bodies with their own "
           "arrays are checked at their x0. Conservative. It reuses the step scratch: call "
           "step() again before querying.")
      .def_property_readonly("stats", &PyScene::stats,
                             "dict: scene-wide counts and times (ms) of the current step.")
      .def("body_stats", &PyScene::body_stats, py::arg("body"),
           "dict: the self-collision statistics of a body in the current step (as "
           "Collider.stats).")
      .def("pair_stats", &PyScene::pair_stats, py::arg("a"), py::arg("b"),
           "dict: the statistics of the pair of bodies (a, b) in the current step.")
      .def_property_readonly("body_count", &PyScene::body_count, "Bodies added so far.")
      .def_property_readonly("options", &PyScene::options, "dict: the scene's options.");
}

}  // namespace tetseg::python
