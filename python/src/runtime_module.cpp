// tetseg._runtime: assets, colliders and frame files from Python (docs/python.md). Links the
// tetseg runtime only (no GPL code). Arrays handed to `Collider.step` are used in place.

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "collider_calls.hpp"
#include "python_errors.hpp"
#include "runtime_binding.hpp"
#include "tetseg/format/asset_json.hpp"
#include "tetseg/format/skin.hpp"
#include "tetseg/format/source_vertices.hpp"
#include "tetseg/runtime/asset.hpp"
#include "tetseg/runtime/collider.hpp"
#include "tetseg/runtime/frames.hpp"

namespace tetseg::python {

Errors& errors() {
  static Errors* e = new Errors();  // never destroyed: outlives module teardown
  return *e;
}

namespace {

// ---------------------------------------------------------------------------------------
// NumPy helpers

/// A read-only array over `data`, kept valid by `owner` (which must keep `data` alive).
py::array read_only_view(const py::dtype& dtype, std::vector<py::ssize_t> shape,
                         std::vector<py::ssize_t> strides, const void* data, py::handle owner) {
  py::array array(dtype, std::move(shape), std::move(strides), data, owner);
  array.attr("setflags")(py::arg("write") = false);
  return array;
}

/// Keeps an asset alive for as long as any array viewing it exists.
py::capsule asset_owner(const AssetPtr& asset) {
  return py::capsule(new AssetPtr(asset), [](void* p) { delete static_cast<AssetPtr*>(p); });
}

py::dtype record_dtype(const std::vector<std::pair<const char*, const char*>>& fields,
                       const std::vector<std::size_t>& offsets, std::size_t itemsize) {
  py::list names, formats, offs;
  for (std::size_t i = 0; i < fields.size(); ++i) {
    names.append(fields[i].first);
    formats.append(fields[i].second);
    offs.append(offsets[i]);
  }
  return py::dtype(names, formats, offs, static_cast<py::ssize_t>(itemsize));
}

py::dtype contact_record_dtype() {
  static_assert(std::is_standard_layout_v<Contact>);
  static_assert(sizeof(ContactKind) == 1 && sizeof(bool) == 1);
  return record_dtype(
      {{"kind", "u1"},
       {"bodies", "(2,)u4"},
       {"nodes", "(4,)u4"},
       {"triangle", "u4"},
       {"toi", "f8"},
       {"at_start", "?"}},
      {offsetof(Contact, kind), offsetof(Contact, bodies), offsetof(Contact, nodes),
       offsetof(Contact, triangle), offsetof(Contact, toi), offsetof(Contact, at_start)},
      sizeof(Contact));
}

py::dtype cluster_dtype() {
  using format::Cluster;
  using format::DetectorPoint;
  static_assert(std::is_standard_layout_v<Cluster> && std::is_standard_layout_v<DetectorPoint>);
  const std::size_t det = offsetof(Cluster, detector);
  return record_dtype(
      {{"detector_nodes", "(4,)u4"},
       {"detector_weights", "(4,)f8"},
       {"detector_tet", "u4"},
       {"flags", "u4"},
       {"rest_positive_fraction", "f4"},
       {"triangle_offset", "u4"},
       {"triangle_count", "u4"},
       {"bvh_offset", "u4"},
       {"bvh_count", "u4"},
       {"detector_term_offset", "u4"},
       {"detector_term_count", "u4"},
       {"detector_rest", "(3,)f8"}},
      {det + offsetof(DetectorPoint, nodes), det + offsetof(DetectorPoint, weights),
       det + offsetof(DetectorPoint, tet), offsetof(Cluster, flags),
       offsetof(Cluster, rest_positive_fraction), offsetof(Cluster, triangle_offset),
       offsetof(Cluster, triangle_count), offsetof(Cluster, bvh_offset),
       offsetof(Cluster, bvh_count), offsetof(Cluster, detector_term_offset),
       offsetof(Cluster, detector_term_count), offsetof(Cluster, detector_rest)},
      sizeof(Cluster));
}

py::dtype detector_term_dtype() {
  using format::DetectorTerm;
  static_assert(std::is_standard_layout_v<DetectorTerm>);
  return record_dtype({{"index", "u4"}, {"weight", "f8"}},
                      {offsetof(DetectorTerm, index), offsetof(DetectorTerm, weight)},
                      sizeof(DetectorTerm));
}

/// format::skinned_detector_positions over a (bones, 3, 4) float64 array of skinning matrices.
py::array skinned_positions(const py::object& asset_object, const py::object& matrices) {
  if (!py::isinstance<PyAsset>(asset_object))
    throw py::type_error("skinned_detector_positions expects a tetseg.Asset");
  const AssetPtr asset = asset_object.cast<const PyAsset&>().asset;
  const std::size_t bones = asset->data().bone_names.size();
  const std::string expected = "(" + std::to_string(bones) + ", 3, 4)";
  if (!py::isinstance<py::array>(matrices))
    throw py::type_error("bone_matrices must be a numpy.ndarray of float64 with shape " + expected);
  const auto array = py::reinterpret_borrow<py::array>(matrices);
  if (!array.dtype().equal(py::dtype::of<double>()))
    throw py::type_error("bone_matrices must have dtype float64, got " +
                         std::string(py::str(array.dtype())));
  if (array.ndim() != 3 || array.shape(0) != static_cast<py::ssize_t>(bones) ||
      array.shape(1) != 3 || array.shape(2) != 4)
    throw py::value_error("bone_matrices must have shape " + expected +
                          " (one row-major 3x4 skinning matrix per bone of the asset), got " +
                          std::string(py::str(array.attr("shape"))));
  const auto contiguous =
      py::array_t<double, py::array::c_style>::ensure(matrices);  // a copy when strided
  const auto clusters = static_cast<py::ssize_t>(asset->cluster_count());
  py::array_t<double> out({clusters, py::ssize_t{3}});
  format::skinned_detector_positions(asset->data(), contiguous.data(), out.mutable_data());
  return std::move(out);
}

/// format::gather_node_positions over an (S, 3) float64 array in the input file's vertex order.
py::array gathered_positions(const py::object& asset_object, const py::object& positions) {
  if (!py::isinstance<PyAsset>(asset_object))
    throw py::type_error("gather_node_positions expects a tetseg.Asset");
  const AssetPtr asset = asset_object.cast<const PyAsset&>().asset;
  const std::size_t sources = format::source_vertex_count(asset->data());
  const std::string expected = "(" + std::to_string(sources) + ", 3)";
  if (!py::isinstance<py::array>(positions))
    throw py::type_error("source_positions must be a numpy.ndarray of float64 with shape " +
                         expected);
  const auto array = py::reinterpret_borrow<py::array>(positions);
  if (!array.dtype().equal(py::dtype::of<double>()))
    throw py::type_error("source_positions must have dtype float64, got " +
                         std::string(py::str(array.dtype())));
  if (array.ndim() != 2 || array.shape(0) != static_cast<py::ssize_t>(sources) ||
      array.shape(1) != 3)
    throw py::value_error("source_positions must have shape " + expected +
                          " (the input file's vertices, in its order), got " +
                          std::string(py::str(array.attr("shape"))));
  const auto contiguous = py::array_t<double, py::array::c_style>::ensure(positions);
  py::array_t<double> out({static_cast<py::ssize_t>(asset->data().node_count), py::ssize_t{3}});
  const format::GatherStatus status =
      format::gather_node_positions(asset->data(), contiguous.data(), sources, out.mutable_data());
  if (status != format::GatherStatus::kOk)  // shape checked above: cannot happen
    throw py::value_error("gather_node_positions failed");
  return std::move(out);
}

py::dtype bvh_node_dtype() {
  using format::BvhNode;
  return record_dtype(
      {{"first", "u4"}, {"second", "u4"}, {"count", "u4"}},
      {offsetof(BvhNode, first), offsetof(BvhNode, second), offsetof(BvhNode, count)},
      sizeof(BvhNode));
}

py::dtype boundary_dtype() {
  using format::BoundaryLoop;
  return record_dtype({{"node_offset", "u4"}, {"node_count", "u4"}},
                      {offsetof(BoundaryLoop, node_offset), offsetof(BoundaryLoop, node_count)},
                      sizeof(BoundaryLoop));
}

/// A (count, columns) or (count,) read-only view of a vector of records / fixed arrays.
template <typename T>
py::array vector_view(const std::vector<T>& values, const py::dtype& dtype, py::ssize_t columns,
                      const AssetPtr& asset) {
  const py::ssize_t count = static_cast<py::ssize_t>(values.size());
  if (columns == 0) {
    return read_only_view(dtype, {count}, {static_cast<py::ssize_t>(sizeof(T))}, values.data(),
                          asset_owner(asset));
  }
  return read_only_view(dtype, {count, columns},
                        {static_cast<py::ssize_t>(sizeof(T)), dtype.itemsize()}, values.data(),
                        asset_owner(asset));
}

// ---------------------------------------------------------------------------------------
// Assets

AssetPtr load_from_bytes(const py::buffer& data) {
  const py::buffer_info info = data.request();
  if (info.ndim != 1 || info.itemsize != 1) {
    throw py::type_error(
        "asset bytes must be a 1-D buffer of bytes (bytes, bytearray, memoryview)");
  }
  auto asset = std::make_shared<Asset>();
  std::string detail;
  Status status;
  {
    py::gil_scoped_release release;
    status = load_asset(static_cast<const std::uint8_t*>(info.ptr),
                        static_cast<std::size_t>(info.size), *asset, &detail);
  }
  if (status != Status::kOk) raise_status(errors().asset, "asset bytes", to_string(status), detail);
  return asset;
}

AssetPtr load_from_path(const std::string& path) {
  auto asset = std::make_shared<Asset>();
  std::string detail;
  Status status;
  {
    py::gil_scoped_release release;
    status = load_asset_file(path, *asset, &detail);
  }
  if (status != Status::kOk) raise_status(errors().asset, path, to_string(status), detail);
  return asset;
}

/// str / os.PathLike -> file; bytes-like -> memory.
PyAsset load_any(const py::object& source) {
  if (py::isinstance<py::str>(source) || py::hasattr(source, "__fspath__")) {
    const py::object path = py::module_::import("os").attr("fspath")(source);
    if (!py::isinstance<py::str>(path))
      throw py::type_error("asset path must be str or os.PathLike[str]");
    return PyAsset{load_from_path(path.cast<std::string>())};
  }
  if (PyObject_CheckBuffer(source.ptr())) {
    return PyAsset{load_from_bytes(py::reinterpret_borrow<py::buffer>(source))};
  }
  throw py::type_error("load_asset expects a path (str or os.PathLike) or bytes, got " +
                       std::string(py::str(py::type::handle_of(source).attr("__name__"))));
}

py::dict provenance_dict(const format::Provenance& p) {
  py::dict options;
  for (const auto& [key, value] : p.options) options[py::str(key)] = value;
  py::dict d;
  d["tool_version"] = p.tool_version;
  d["source"] = p.source;
  d["options"] = options;
  return d;
}

// ---------------------------------------------------------------------------------------
// Collider

py::dict options_dict(const ColliderOptions& o) {
  py::dict d;
  d["mode"] = to_string(o.mode);
  d["min_separation"] = o.ccd.min_separation;
  d["time_tolerance"] = o.ccd.time_tolerance;
  d["max_intervals"] = o.ccd.max_intervals;
  d["bvh_leaf_size"] = o.bvh_leaf_size;
  d["use_openmp"] = o.use_openmp;
  d["check_first_step"] = o.check_first_step;
  d["time_tests"] = o.time_tests;
  d["include_still_pairs"] = o.include_still_pairs;
  d["threads"] = o.threads;
  return d;
}

class PyCollider {
 public:
  PyCollider(py::object asset_object, const ColliderOptions& options)
      : m_asset_object(std::move(asset_object)),
        m_asset(m_asset_object.cast<const PyAsset&>().asset) {
    {
      py::gil_scoped_release release;
      m_collider = std::make_unique<Collider>(*m_asset, options);
    }
    if (m_collider->status() != ColliderStatus::kOk)
      raise_status(errors().collider, "Collider", to_string(m_collider->status()),
                   "cannot create the collider (out of memory)");
  }

  void set_detector_positions(const py::object& d0, const py::object& d1) {
    const std::size_t clusters = m_asset->cluster_count();
    if (m_asset->data().detector_form != format::DetectorForm::kBones)
      raise_status(errors().collider, "set_detector_positions",
                   to_string(ColliderStatus::kInvalidArgument),
                   std::string("the asset's detectors are ") +
                       format::detector_form_name(m_asset->data().detector_form) +
                       ", not carried by bones: they need no positions");
    const double* p0 = detector_positions_of("d0", d0, clusters);
    const double* p1 = detector_positions_of("d1", d1, clusters);
    Busy busy = m_queries.lock();
    const ColliderStatus status = m_collider->set_detector_positions(p0, p1, clusters * 3);
    if (status != ColliderStatus::kOk)
      raise_status(errors().collider, "set_detector_positions", to_string(status), "");
    // Read at every following step: referenced until replaced.
    m_d0 = d0;
    m_d1 = d1;
  }

  void step(const py::object& x0, const py::object& x1) {
    const std::size_t nodes = m_asset->node_count();
    const double* p0 = positions_of("x0", x0, nodes, "the asset's node count");
    const double* p1 = positions_of("x1", x1, nodes, "the asset's node count");
    Busy busy = m_queries.lock();
    // The C++ collider keeps the pointers until the next step: drop the old arrays only
    // after it stopped using them, and keep the new ones while it may read them.
    ColliderStatus status;
    {
      py::gil_scoped_release release;
      status = call_step(*m_collider, p0, p1, nodes * 3);
    }
    m_queries.stepped(status);
    if (status != ColliderStatus::kOk) {
      m_x0 = py::none();
      m_x1 = py::none();
      raise_status(errors().collider, "step", to_string(status), step_failure_detail(status));
    }
    m_x0 = x0;
    m_x1 = x1;
  }

  bool any_collision() { return m_queries.any_collision(*m_collider); }
  py::object earliest_toi() { return m_queries.earliest_toi(*m_collider); }
  py::array contacts() { return m_queries.contacts(*m_collider); }

  py::dict check_rest_intersection(const py::object& x) {
    const std::size_t nodes = m_asset->node_count();
    const double* p = positions_of("x", x, nodes, "the asset's node count");
    Busy busy = m_queries.lock();
    RestCheck result;
    ColliderStatus status;
    {
      py::gil_scoped_release release;
      status = call_check_rest_intersection(*m_collider, p, nodes * 3, result);
    }
    m_queries.invalidated(
        "check_rest_intersection reused the step scratch: call step(x0, x1) again");
    if (status != ColliderStatus::kOk)
      raise_status(errors().collider, "check_rest_intersection", to_string(status),
                   step_failure_detail(status));
    return rest_check_dict(result);
  }

  py::dict stats() {
    Busy busy = m_queries.lock();
    return stats_dict(m_collider->stats());
  }
  py::dict rest_intersection() {
    Busy busy = m_queries.lock();
    return rest_check_dict(m_collider->rest_intersection());
  }
  py::dict options() const { return options_dict(m_collider->options()); }
  std::size_t node_count() const { return m_asset->node_count(); }
  const py::object& asset() const { return m_asset_object; }

  const char* triangle_class(std::size_t triangle) {
    Busy busy = m_queries.lock();
    if (triangle >= m_asset->triangle_count())
      throw py::index_error("triangle " + std::to_string(triangle) + " out of range (" +
                            std::to_string(m_asset->triangle_count()) + " triangles)");
    switch (m_collider->triangle_class(triangle)) {
      case Orientation::kPositive:
        return "positive";
      case Orientation::kNegative:
        return "negative";
      case Orientation::kUncertain:
        break;
    }
    return "uncertain";
  }

 private:
  py::object m_asset_object;  // the Python Asset: the binding's reference keeps it alive
  AssetPtr m_asset;
  std::unique_ptr<Collider> m_collider;             // declared after m_asset: destroyed before it
  py::object m_x0 = py::none(), m_x1 = py::none();  // arrays the collider reads this step
  py::object m_d0 = py::none(), m_d1 = py::none();  // detector positions (kBones), every step
  StepQueries m_queries{"Collider", "step(x0, x1)"};
};

ColliderOptions make_options(const std::string& mode, double min_separation, double time_tolerance,
                             std::uint32_t max_intervals, std::uint32_t bvh_leaf_size,
                             bool use_openmp, bool check_first_step, bool time_tests,
                             bool include_still_pairs, std::uint32_t threads) {
  ColliderOptions o;
  if (!parse_collider_mode(mode.c_str(), o.mode))
    throw py::value_error("unknown mode '" + mode + "' (rvbc, bvh, brute, cone)");
  o.ccd.min_separation = min_separation;
  o.ccd.time_tolerance = time_tolerance;
  o.ccd.max_intervals = max_intervals;
  o.bvh_leaf_size = bvh_leaf_size;
  o.use_openmp = use_openmp;
  o.check_first_step = check_first_step;
  o.time_tests = time_tests;
  o.include_still_pairs = include_still_pairs;
  o.threads = threads;
  return o;
}

// ---------------------------------------------------------------------------------------
// Frame files

py::array read_frames_array(const py::object& path_like) {
  const std::string path = py::module_::import("os").attr("fspath")(path_like).cast<std::string>();
  auto frames = std::make_unique<FrameSequence>();
  std::string detail;
  FramesStatus status;
  {
    py::gil_scoped_release release;
    status = read_frames_file(path, *frames, &detail);
  }
  if (status != FramesStatus::kOk) raise_status(errors().frames, path, to_string(status), detail);
  const auto f = static_cast<py::ssize_t>(frames->frame_count);
  const auto n = static_cast<py::ssize_t>(frames->node_count);
  const double* data = frames->positions.data();
  py::capsule owner(frames.release(), [](void* p) { delete static_cast<FrameSequence*>(p); });
  const py::ssize_t d = sizeof(double);
  return py::array(py::dtype::of<double>(), {f, n, py::ssize_t{3}}, {n * 3 * d, 3 * d, d}, data,
                   owner);
}

}  // namespace

py::dtype contact_dtype() {
  return contact_record_dtype();
}

py::dict stats_dict(const ColliderStats& s) {
  py::dict d;
  d["refit_ms"] = s.refit_ms;
  d["classify_ms"] = s.classify_ms;
  d["traversal_ms"] = s.traversal_ms;
  d["tests_ms"] = s.tests_ms;
  d["cone_ms"] = s.cone_ms;
  d["nodes_moved"] = s.nodes_moved;
  d["triangles_positive"] = s.triangles_positive;
  d["triangles_negative"] = s.triangles_negative;
  d["triangles_uncertain"] = s.triangles_uncertain;
  d["triangles_moving"] = s.triangles_moving;
  d["clusters_skipped"] = s.clusters_skipped;
  d["closure_pairs"] = s.closure_pairs;
  d["node_pairs_visited"] = s.node_pairs_visited;
  d["node_pairs_orientation_culled"] = s.node_pairs_orientation_culled;
  d["triangle_pairs"] = s.triangle_pairs;
  d["triangle_pairs_plane_filtered"] = s.triangle_pairs_plane_filtered;
  d["feature_pairs"] = s.feature_pairs;
  d["feature_pairs_filtered"] = s.feature_pairs_filtered;
  d["feature_tests"] = s.feature_tests;
  d["contacts"] = s.contacts;
  d["nothing_moved"] = s.nothing_moved;
  d["full_traversal"] = s.full_traversal;
  return d;
}

py::dict rest_check_dict(const RestCheck& r) {
  py::dict d;
  d["intersecting"] = r.intersecting;
  d["triangle_a"] = r.triangle_a;
  d["triangle_b"] = r.triangle_b;
  d["bodies"] = py::make_tuple(r.bodies[0], r.bodies[1]);
  return d;
}

}  // namespace tetseg::python

PYBIND11_MODULE(_runtime, m) {
  using namespace tetseg;
  using namespace tetseg::python;
  m.doc() =
      "tetseg runtime: load assets and query continuous self-collisions of a deforming "
      "tetrahedral mesh per step (docs/python.md, docs/runtime.md). Links the runtime only.";
  m.attr("__version__") = TETSEG_VERSION_STRING;

  errors().asset = add_status_exception(
      m, "tetseg", "AssetError", PyExc_ValueError,
      "An asset could not be loaded. Attributes: status (e.g. 'payload checksum', 'i/o error') "
      "and detail (one line).");
  errors().collider = add_status_exception(
      m, "tetseg", "ColliderError", PyExc_RuntimeError,
      "A collider call failed. Attributes: status (e.g. 'non-finite position', 'not ready') and "
      "detail. Queries never answer without a valid step.");
  errors().frames = add_status_exception(
      m, "tetseg", "FramesError", PyExc_ValueError,
      "A frame-sequence file could not be read. Attributes: status and detail.");

  m.attr("CONTACT_DTYPE") = contact_dtype();
  m.attr("VERTEX_FACE") = static_cast<int>(ContactKind::kVertexFace);
  m.attr("EDGE_EDGE") = static_cast<int>(ContactKind::kEdgeEdge);
  m.attr("MODES") = py::make_tuple("rvbc", "bvh", "brute", "cone", "features");

  py::class_<PyAsset>(m, "Asset",
                      "A validated, immutable asset (load with tetseg.load_asset). Arrays are "
                      "read-only views of the asset's memory and keep it alive.")
      .def_static(
          "from_file",
          [](const py::object& path) {
            const py::object p = py::module_::import("os").attr("fspath")(path);
            if (!py::isinstance<py::str>(p))
              throw py::type_error("asset path must be str or os.PathLike[str]");
            return PyAsset{load_from_path(p.cast<std::string>())};
          },
          py::arg("path"), "Loads and validates an asset file. Raises AssetError.")
      .def_static(
          "from_bytes", [](const py::buffer& data) { return PyAsset{load_from_bytes(data)}; },
          py::arg("data"), "Loads and validates an asset from bytes. Raises AssetError.")
      .def_property_readonly(
          "node_count", [](const PyAsset& a) { return a.asset->node_count(); },
          "Tet-mesh nodes expected per step (rows of the position arrays).")
      .def_property_readonly(
          "triangle_count", [](const PyAsset& a) { return a.asset->triangle_count(); },
          "Surface triangles.")
      .def_property_readonly(
          "cluster_count", [](const PyAsset& a) { return a.asset->cluster_count(); }, "Clusters.")
      .def_property_readonly(
          "triangles",
          [](const PyAsset& a) {
            return vector_view(a.asset->data().triangles, py::dtype::of<std::uint32_t>(), 3,
                               a.asset);
          },
          "(T, 3) uint32: surface triangles as tet-mesh node ids, wound outward.")
      .def_property_readonly(
          "triangle_cluster",
          [](const PyAsset& a) {
            return vector_view(a.asset->data().triangle_cluster, py::dtype::of<std::uint32_t>(), 0,
                               a.asset);
          },
          "(T,) uint32: the cluster of each surface triangle.")
      .def_property_readonly(
          "clusters",
          [](const PyAsset& a) {
            return vector_view(a.asset->data().clusters, cluster_dtype(), 0, a.asset);
          },
          "(C,) structured: detector_nodes (4 u4), detector_weights (4 f8), detector_tet, "
          "flags (1 = overlap-only), rest_positive_fraction, triangle_offset, triangle_count, "
          "bvh_offset, bvh_count, detector_term_offset, detector_term_count, detector_rest (3 "
          "f8; format 1.2).")
      .def_property_readonly(
          "detectors",
          [](const PyAsset& a) -> py::object {
            const py::object clusters =
                vector_view(a.asset->data().clusters, cluster_dtype(), 0, a.asset);
            return clusters[py::str("detector_nodes")];
          },
          "(C, 4) uint32: the four tet-mesh nodes of each cluster's detector point (a detector "
          "at a node: that node four times; weights in clusters['detector_weights']). "
          "detector_form 'tet-point' only; the other forms' detectors are detector_terms.")
      .def_property_readonly(
          "body_kind",
          [](const PyAsset& a) { return format::body_kind_name(a.asset->data().body_kind); },
          "'tet' (nodes of a tet mesh) or 'surface' (the input surface's vertices, in order; "
          "format 1.2).")
      .def_property_readonly(
          "detector_form",
          [](const PyAsset& a) {
            return format::detector_form_name(a.asset->data().detector_form);
          },
          "'tet-point' (clusters['detector_nodes'/'detector_weights']), 'surface-weights' "
          "(detector_terms over node ids, evaluated per step) or 'bones' (detector_terms over "
          "bone ids: pass positions with Collider.set_detector_positions).")
      .def_property_readonly(
          "detector_terms",
          [](const PyAsset& a) {
            return vector_view(a.asset->data().detector_terms, detector_term_dtype(), 0, a.asset);
          },
          "(K,) structured: index (u4: a node id, or a bone id for 'bones'), weight (f8); "
          "cluster c's are [clusters['detector_term_offset'][c] ..+ detector_term_count].")
      .def_property_readonly(
          "bone_names",
          [](const PyAsset& a) {
            py::list names;
            for (const std::string& name : a.asset->data().bone_names)
              names.append(py::bytes(name).attr("decode")("utf-8", "replace"));
            return names;
          },
          "list of str: the skeleton's bones of a 'bones' asset, by bone id (else empty).")
      .def_property_readonly(
          "source_vertex_count",
          [](const PyAsset& a) { return format::source_vertex_count(a.asset->data()); },
          "int: vertices of the input file (len(source_vertex_nodes), or nodes without a map).")
      .def_property_readonly(
          "source_vertex_nodes",
          [](const PyAsset& a) {
            return vector_view(a.asset->data().source_vertex_nodes, py::dtype::of<std::uint32_t>(),
                               0, a.asset);
          },
          "(S,) uint32: for each vertex of the input file, in its order, the node it became "
          "(a 'surface' body read from glTF, FBX, STL, ...: readers that merge vertices at "
          "seams); empty when node i is vertex i. See gather_node_positions.")
      .def_property_readonly(
          "cluster_triangles",
          [](const PyAsset& a) {
            return vector_view(a.asset->data().cluster_triangles, py::dtype::of<std::uint32_t>(), 0,
                               a.asset);
          },
          "(T,) uint32: surface triangle ids grouped by cluster (see clusters.triangle_offset).")
      .def_property_readonly(
          "bvh_nodes",
          [](const PyAsset& a) {
            return vector_view(a.asset->data().bvh_nodes, bvh_node_dtype(), 0, a.asset);
          },
          "(B,) structured: first, second, count (docs/format.md).")
      .def_property_readonly(
          "boundaries",
          [](const PyAsset& a) {
            return vector_view(a.asset->data().boundaries, boundary_dtype(), 0, a.asset);
          },
          "(L,) structured: node_offset, node_count of each segment-boundary loop.")
      .def_property_readonly(
          "boundary_nodes",
          [](const PyAsset& a) {
            return vector_view(a.asset->data().boundary_nodes, py::dtype::of<std::uint32_t>(), 0,
                               a.asset);
          },
          "(K,) uint32: the loops' node ids, grouped, in loop order.")
      .def_property_readonly(
          "rest_positions",
          [](const PyAsset& a) -> py::object {
            if (a.asset->data().rest_positions.empty()) return py::none();
            return vector_view(a.asset->data().rest_positions, py::dtype::of<double>(), 3, a.asset);
          },
          "(N, 3) float64 rest positions, or None when the asset was built without them.")
      .def_property_readonly(
          "provenance",
          [](const PyAsset& a) { return provenance_dict(a.asset->data().provenance); },
          "dict: tool_version, source and the build options.")
      .def("__repr__", [](const PyAsset& a) {
        return "<tetseg.Asset: " + std::to_string(a.asset->node_count()) + " nodes, " +
               std::to_string(a.asset->triangle_count()) + " surface triangles, " +
               std::to_string(a.asset->cluster_count()) + " clusters>";
      });

  m.def("load_asset", &load_any, py::arg("source"),
        "Returns an Asset. "
        "Loads and validates an asset from a path (str or os.PathLike) or from bytes. Raises "
        "AssetError (with .status and .detail) when it is unreadable, corrupt or invalid.");

  m.def("skinned_detector_positions", &skinned_positions, py::arg("asset"),
        py::arg("bone_matrices"),
        "Returns a (clusters, 3) float64 array: every cluster's detector for one pose of the "
        "skeleton, by linear blend skinning of its rest position (format::"
        "skinned_detector_positions). bone_matrices: (len(asset.bone_names), 3, 4) float64, "
        "per bone the row-major 3x4 skinning matrix (world transform times inverse bind "
        "matrix; identities give the rest pose). Clusters without terms keep their rest "
        "position.");

  m.def("gather_node_positions", &gathered_positions, py::arg("asset"), py::arg("source_positions"),
        "Returns a (nodes, 3) float64 array: positions given in the input file's vertex order "
        "(an engine's skinned vertex buffer, split at seams: (asset.source_vertex_count, 3) "
        "float64) turned into the node positions Collider.step takes (format::"
        "gather_node_positions): node asset.source_vertex_nodes[i] takes row i (copies of "
        "one node carry equal positions; the last wins), or a copy without a map. Raises "
        "ValueError on another shape.");

  m.def("read_frames", &read_frames_array, py::arg("path"),
        "Returns a (frames, nodes, 3) float64 array. "
        "Reads a frame-sequence file (docs/format.md). Each frames[i] is C-contiguous and can "
        "be passed to Collider.step without a copy. Raises FramesError.");

  const ColliderOptions defaults;
  py::class_<PyCollider>(m, "Collider",
                         "Continuous self-collision queries for one asset, step by step.\n\n"
                         "Per step: step(x0, x1), then any of any_collision(), earliest_toi(), "
                         "contacts(). One thread at a time per Collider; several colliders may "
                         "share an asset. The GIL is released during steps and queries.")
      .def(py::init([](py::object asset, const std::string& mode, double min_separation,
                       double time_tolerance, std::uint32_t max_intervals,
                       std::uint32_t bvh_leaf_size, bool use_openmp, bool check_first_step,
                       bool time_tests, bool include_still_pairs, std::uint32_t threads) {
             if (!py::isinstance<PyAsset>(asset))
               throw py::type_error("Collider expects a tetseg.Asset (see tetseg.load_asset)");
             return std::make_unique<PyCollider>(
                 std::move(asset), make_options(mode, min_separation, time_tolerance, max_intervals,
                                                bvh_leaf_size, use_openmp, check_first_step,
                                                time_tests, include_still_pairs, threads));
           }),
           py::arg("asset"), py::kw_only(), py::arg("mode") = std::string(to_string(defaults.mode)),
           py::arg("min_separation") = defaults.ccd.min_separation,
           py::arg("time_tolerance") = defaults.ccd.time_tolerance,
           py::arg("max_intervals") = defaults.ccd.max_intervals,
           py::arg("bvh_leaf_size") = defaults.bvh_leaf_size,
           py::arg("use_openmp") = defaults.use_openmp,
           py::arg("check_first_step") = defaults.check_first_step,
           py::arg("time_tests") = defaults.time_tests,
           py::arg("include_still_pairs") = defaults.include_still_pairs,
           py::arg("threads") = defaults.threads,
           "Builds a collider (allocates all scratch memory). Options as "
           "tetseg::ColliderOptions (docs/runtime.md): mode is one of MODES; min_separation, "
           "time_tolerance and max_intervals go to the elementary tests; include_still_pairs "
           "also tests feature pairs whose four nodes do not move (skipped by default); threads "
           "is the OpenMP thread count with use_openmp (0: OpenMP's default). The collider "
           "holds a reference to the asset, so it keeps working when the caller drops the "
           "Asset.")
      .def("step", &PyCollider::step, py::arg("x0"), py::arg("x1"),
           "Starts a step from positions x0 (t = 0) to x1 (t = 1): "
           "(node_count, 3) C-contiguous float64 arrays, used in place (not copied) and "
           "referenced by the collider until the next step; do not modify them in between. "
           "TypeError for a non-array or another dtype, ValueError for a wrong shape or a "
           "non-contiguous array, ColliderError ('non-finite position') for NaN/inf.")
      .def("set_detector_positions", &PyCollider::set_detector_positions, py::arg("d0"),
           py::arg("d1"),
           "Detector positions of a 'bones' asset at the start and end of each step: "
           "(cluster_count, 3) C-contiguous float64 arrays (e.g. from "
           "skinned_detector_positions), used in place and read at every following step until "
           "replaced: update them before each step. Entries of overlap-only clusters are not "
           "read. Any positions give exact answers; wrong ones only cull less. ColliderError "
           "('invalid argument') for an asset of another form.")
      .def("any_collision", &PyCollider::any_collision,
           "Whether any feature pair is in contact during the step. "
           "Raises ColliderError without a valid step.")
      .def("earliest_toi", &PyCollider::earliest_toi,
           "The earliest contact of the step as a numpy.void record of CONTACT_DTYPE (fields "
           "kind, nodes, triangle, toi, at_start), or None when there is none. "
           "Raises ColliderError without a valid step.")
      .def("contacts", &PyCollider::contacts,
           "An ndarray of CONTACT_DTYPE: all contacts of the step, sorted by toi, "
           "kind, nodes. kind is VERTEX_FACE (nodes = p, a, b, c) or EDGE_EDGE (edge a-b "
           "against c-d); toi is a lower bound of the first contact time in [0, 1]. Raises "
           "ColliderError without a valid step.")
      .def("check_rest_intersection", &PyCollider::check_rest_intersection, py::arg("x"),
           "Returns dict(intersecting, triangle_a, triangle_b). "
           "Static check of positions x ((node_count, 3) float64): do two non-adjacent parts of "
           "the surface intersect or touch? Conservative.")
      .def_property_readonly("stats", &PyCollider::stats,
                             "dict: counts and times (ms) of the current step.")
      .def_property_readonly("rest_intersection", &PyCollider::rest_intersection,
                             "dict: result of check_first_step (intersecting False when not run).")
      .def_property_readonly("options", &PyCollider::options, "dict: the collider's options.")
      .def_property_readonly("node_count", &PyCollider::node_count, "Rows expected in x0 and x1.")
      .def_property_readonly("asset", &PyCollider::asset, "The Asset this collider was built on.")
      .def("triangle_class", &PyCollider::triangle_class, py::arg("triangle"),
           "Orientation class of a surface triangle in the current step (rvbc mode): "
           "'positive', 'negative' or 'uncertain'. For diagnostics.");

  bind_scene(m);
}
