// tetseg.preprocess: build assets and charge densities from Python (docs/python.md). Links
// tetseg::preprocess, hence CGAL (GPL); tetseg's runtime package never imports this module.
// Options and defaults are those of `tetseg build` and `tetseg charge` (docs/cli.md): the
// defaults come from the library's option structs, the ranges from option_ranges.hpp, and
// the work and the reports from the same library jobs (jobs.hpp) as the CLI's.

#include <pybind11/functional.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <string>
#include <utility>
#include <vector>

#include "python_errors.hpp"
#include "tetseg/format/asset_io.hpp"
#include "tetseg/preprocess/charge.hpp"
#include "tetseg/preprocess/io.hpp"
#include "tetseg/preprocess/jobs.hpp"
#include "tetseg/preprocess/meshing.hpp"
#include "tetseg/preprocess/names.hpp"
#include "tetseg/preprocess/option_ranges.hpp"

namespace tetseg::python {
namespace {

using namespace tetseg::preprocess;

// Option names: the library's name tables (tetseg/preprocess/names.hpp), as in the CLI.

template <typename Enum>
Enum enum_from_name(const char* option, const std::string& name) {
  Enum value{};
  if (parse_name(name, value)) return value;
  throw py::value_error(std::string(option) + ": unknown value '" + name + "' (" +
                        name_list<Enum>(", ") + ")");
}

// ---------------------------------------------------------------------------------------
// Input: a mesh file, or (nodes, tets) / (points, triangles) arrays.

py::object numpy() {
  return py::module_::import("numpy");
}

std::vector<Vec3> points_from(const py::handle& object) {
  const py::array a = numpy().attr("ascontiguousarray")(object, py::arg("dtype") = "float64");
  if (a.ndim() != 2 || a.shape(1) != 3 || a.shape(0) == 0)
    throw py::value_error("nodes must be an (N, 3) array of coordinates, got shape " +
                          py::str(a.attr("shape")).cast<std::string>());
  std::vector<Vec3> points(static_cast<std::size_t>(a.shape(0)));
  std::memcpy(points.data(), a.data(), points.size() * sizeof(Vec3));
  return points;
}

/// (M, columns) integer array of node ids, each in [0, 2^32).
template <std::size_t Columns>
std::vector<std::array<std::uint32_t, Columns>> cells_from(const char* what, const py::array& a) {
  const char kind = a.dtype().kind();
  if (kind != 'i' && kind != 'u')
    throw py::type_error(std::string(what) + " must be an integer array, got dtype " +
                         py::str(a.dtype()).cast<std::string>());
  if (a.size() > 0) {
    const py::int_ low = a.attr("min")(), high = a.attr("max")();
    if (low.cast<long long>() < 0 || high.cast<unsigned long long>() > 0xffffffffull)
      throw py::value_error(std::string(what) + " hold node ids outside [0, 2^32)");
  }
  const py::array ids = numpy().attr("ascontiguousarray")(a, py::arg("dtype") = "uint32");
  std::vector<std::array<std::uint32_t, Columns>> cells(static_cast<std::size_t>(ids.shape(0)));
  std::memcpy(cells.data(), ids.data(), cells.size() * sizeof(cells[0]));
  return cells;
}

/// What the caller passed: a path, or arrays of a tet mesh or of a closed surface.
struct Input {
  std::string path;  // empty for arrays
  std::string source;
  bool is_tet_mesh = false;
  TetMesh tet_mesh;
  TriangleMesh surface;
};

Input input_from(const py::object& mesh, const py::object& source) {
  Input in;
  if (py::isinstance<py::str>(mesh) || py::hasattr(mesh, "__fspath__")) {
    const py::object p = py::module_::import("os").attr("fspath")(mesh);
    if (!py::isinstance<py::str>(p))
      throw py::type_error("mesh path must be str or os.PathLike[str]");
    in.path = p.cast<std::string>();
    in.source = source.is_none() ? in.path : source.cast<std::string>();
    in.is_tet_mesh = is_tet_mesh_path(in.path);
    return in;
  }
  if (!py::isinstance<py::sequence>(mesh) || py::len(mesh) != 2)
    throw py::type_error(
        "mesh must be a file path or a pair of arrays: (nodes (N, 3), tets (M, 4)) or "
        "(points (N, 3), triangles (M, 3))");
  const py::sequence pair = mesh;
  in.source = source.is_none() ? std::string("arrays") : source.cast<std::string>();
  const py::array cells = numpy().attr("asarray")(pair[1]);
  if (cells.ndim() != 2 || (cells.shape(1) != 4 && cells.shape(1) != 3))
    throw py::value_error(
        "the second array must have shape (M, 4) (tets) or (M, 3) "
        "(surface triangles), got " +
        py::str(cells.attr("shape")).cast<std::string>());
  in.is_tet_mesh = cells.shape(1) == 4;
  if (in.is_tet_mesh) {
    in.tet_mesh.nodes = points_from(pair[0]);
    in.tet_mesh.tets = cells_from<4>("tets", cells);
  } else {
    in.surface.vertices = points_from(pair[0]);
    in.surface.triangles = cells_from<3>("triangles", cells);
  }
  return in;
}

/// CGAL's meshing resets a global random generator and Eigen's thread count is global: one
/// preprocess call at a time. Lock it only after releasing the GIL (a stage callback takes
/// the GIL while the lock is held).
std::mutex& preprocess_mutex() {
  static std::mutex m;
  return m;
}

py::array_t<double> nodes_array(const std::vector<Vec3>& nodes) {
  py::array_t<double> a({static_cast<py::ssize_t>(nodes.size()), py::ssize_t{3}});
  std::memcpy(a.mutable_data(), nodes.data(), nodes.size() * sizeof(Vec3));
  return a;
}

template <std::size_t Columns>
py::array_t<std::uint32_t> cells_array(const std::vector<std::array<std::uint32_t, Columns>>& c) {
  py::array_t<std::uint32_t> a(
      {static_cast<py::ssize_t>(c.size()), static_cast<py::ssize_t>(Columns)});
  std::memcpy(a.mutable_data(), c.data(), c.size() * sizeof(c[0]));
  return a;
}

py::array_t<double> doubles_array(const std::vector<double>& v) {
  py::array_t<double> a(static_cast<py::ssize_t>(v.size()));
  std::memcpy(a.mutable_data(), v.data(), v.size() * sizeof(double));
  return a;
}

// ---------------------------------------------------------------------------------------
// build

/// Python calls on_stage(name, seconds, summary) after each stage, with the GIL.
StageCallback stage_callback_from(const py::object& on_stage) {
  if (on_stage.is_none()) return {};
  return [&on_stage](const StageReport& stage) {
    py::gil_scoped_acquire gil;
    on_stage(stage.name, stage.seconds, stage.summary);
  };
}

py::tuple build(const py::object& mesh, const py::object& source, const std::string& clusters,
                double refine_visibility, std::uint32_t refine_max_clusters, double refine_gain,
                bool refine_merge, double alpha, double beta_divisor,
                const std::string& equalization, double growth_bound, bool grow_through_marked,
                std::uint32_t min_cluster_triangles, const std::string& detector,
                double min_visibility, const std::string& solver, double tolerance,
                double cell_size, double facet_size, double facet_distance, bool optimize,
                int threads, const std::string& repair, double wrap_alpha, double wrap_offset,
                double wrap_sheet_offset, bool keep_largest_component, double max_deviation,
                double time_limit, bool rest_positions, const std::string& body,
                const py::object& detectors, const py::object& on_stage) {
  BuildJobOptions job;
  BuildOptions& options = job.build;
  options.body = enum_from_name<format::BodyKind>("body", body);
  if (!detectors.is_none())
    options.detectors =
        enum_from_name<format::DetectorForm>("detectors", detectors.cast<std::string>());
  options.clusters = enum_from_name<ClusterMethod>("clusters", clusters);
  options.refinement.min_visibility = refine_visibility;
  options.refinement.max_clusters = refine_max_clusters;
  options.refinement.gain_per_cut_edge = refine_gain;
  options.refinement.merge = refine_merge;
  options.segmentation.alpha = alpha;
  options.segmentation.beta_divisor = beta_divisor;
  options.segmentation.equalization = enum_from_name<Equalization>("equalization", equalization);
  options.segmentation.growth_bound = growth_bound;
  options.segmentation.grow_through_marked = grow_through_marked;
  options.segmentation.min_cluster_triangles = min_cluster_triangles;
  options.segmentation.detector = enum_from_name<DetectorStrategy>("detector", detector);
  options.segmentation.min_visibility = min_visibility;
  options.charge.solver = enum_from_name<ChargeSolver>("solver", solver);
  options.charge.tolerance = tolerance;
  options.keep_rest_positions = rest_positions;
  MeshingOptions& meshing = job.meshing;
  meshing.cell_size = cell_size;
  meshing.facet_size = facet_size;
  meshing.facet_distance = facet_distance;
  meshing.optimize = optimize;
  meshing.threads = threads;
  meshing.repair = enum_from_name<MeshingOptions::Repair>("repair", repair);
  meshing.wrap_alpha = wrap_alpha;
  meshing.wrap_offset = wrap_offset;
  meshing.wrap_sheet_offset = wrap_sheet_offset;
  meshing.keep_largest_component = keep_largest_component;
  meshing.max_deviation = max_deviation;
  job.time_limit = time_limit;
  validate_options(job);  // std::invalid_argument: ValueError, before any work

  Input in = input_from(mesh, source);
  const StageCallback stage_callback = stage_callback_from(on_stage);
  BuildJobResult result;
  {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(preprocess_mutex());
    // As `tetseg build`: the same job, so the same stages, checks and report.
    if (!in.path.empty())
      result = build_asset_from_file(in.path, job, stage_callback, in.source);
    else if (in.is_tet_mesh)
      result = build_asset_from_tet_mesh(std::move(in.tet_mesh), in.source, job, stage_callback);
    else
      result = build_asset_from_surface(std::move(in.surface), in.source, job, stage_callback);
  }
  // The report of `tetseg build --report` (without "output": no file is written), plus the
  // stages as (name, seconds, summary).
  py::dict report = py::module_::import("json").attr("loads")(
      build_report_json(result, in.source, /*output=*/""));
  py::list stages;
  for (const StageReport& s : result.report.stages)
    stages.append(py::make_tuple(s.name, s.seconds, s.summary));
  report["stages"] = stages;
  py::bytes data(reinterpret_cast<const char*>(result.asset_bytes.data()),
                 result.asset_bytes.size());
  return py::make_tuple(data, report);
}

// ---------------------------------------------------------------------------------------
// charge

py::dict charge(const py::object& mesh, const py::object& source, const std::string& solver,
                double tolerance, int max_iterations, double theta, int order,
                bool relaxed_products, const std::string& equalize_name, int bins) {
  ChargeJobOptions job;
  job.charge.solver = enum_from_name<ChargeSolver>("solver", solver);
  job.equalization = enum_from_name<Equalization>("equalize", equalize_name);
  job.charge.tolerance = tolerance;
  job.charge.max_iterations = max_iterations;
  job.charge.fast_theta = theta;
  job.charge.fast_order = order;
  job.charge.relaxed_products = relaxed_products;
  job.bins = bins;
  validate_options(job);

  Input in = input_from(mesh, source);
  ChargeJobResult result;
  {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(preprocess_mutex());
    // As `tetseg charge`: a tet mesh's boundary, or a closed surface as given.
    if (!in.path.empty())
      result = charge_from_file(in.path, job, {}, in.source);
    else if (in.is_tet_mesh)
      result = charge_tet_mesh(std::move(in.tet_mesh), in.source, job);
    else
      result = charge_surface(std::move(in.surface), in.source, job);
  }
  // The report of `tetseg charge --report` but input and triangles, plus the arrays.
  py::dict d = py::module_::import("json").attr("loads")(charge_report_json(result, in.source));
  d.attr("pop")("input");
  d.attr("pop")("triangles");
  d["density"] = doubles_array(result.charge.density);
  d["equalized"] = doubles_array(result.equalized);
  d["points"] = nodes_array(result.points);
  d["triangles"] = cells_array(result.triangles);
  return d;
}

// ---------------------------------------------------------------------------------------
// generate

py::tuple generate(const std::string& shape_name, double size, double radius,
                   const std::array<double, 3>& axes, double cell_size, double facet_size,
                   double facet_distance, double facet_angle, double radius_edge_ratio,
                   bool optimize, int threads) {
  const Shape shape = shape_from_name(shape_name);
  ShapeOptions shape_options;
  shape_options.size = size;
  shape_options.radius = radius;
  for (int k = 0; k < 3; ++k) shape_options.axes[k] = axes[static_cast<std::size_t>(k)];
  MeshingOptions meshing;
  meshing.cell_size = cell_size;
  meshing.facet_size = facet_size;
  meshing.facet_distance = facet_distance;
  meshing.facet_angle = facet_angle;
  meshing.cell_radius_edge_ratio = radius_edge_ratio;
  meshing.optimize = optimize;
  check_option(option_ranges::kThreads, threads);
  meshing.threads = threads;
  TetMesh mesh;
  {
    py::gil_scoped_release release;
    std::lock_guard<std::mutex> lock(preprocess_mutex());
    mesh = generate_shape(shape, shape_options, meshing);
  }
  return py::make_tuple(nodes_array(mesh.nodes), cells_array(mesh.tets));
}

/// `tetseg.preprocess.InputError`; never destroyed (outlives module teardown).
py::object& input_error_type() {
  static auto* type = new py::object();
  return *type;
}

}  // namespace
}  // namespace tetseg::python

PYBIND11_MODULE(preprocess, m) {
  using namespace tetseg::python;
  using namespace tetseg::preprocess;
  m.doc() =
      "tetseg.preprocess: build assets and charge densities (docs/python.md). Links CGAL "
      "(GPL-3.0-or-later); the runtime package `tetseg` does not import it. Options and "
      "defaults are those of `tetseg build` and `tetseg charge` (docs/cli.md), with '-' "
      "written '_'.";
  m.attr("__version__") = TETSEG_VERSION_STRING;

  input_error_type() = add_status_exception(
      m, "tetseg.preprocess", "InputError", PyExc_ValueError,
      "Bad input mesh: unreadable, malformed or invalid. Attributes: file, detail.");
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const InputError& e) {
      const std::string message = (e.file().empty() ? std::string() : e.file() + ": ") + e.what();
      const py::object& type = input_error_type();
      py::object error = type(message);
      error.attr("file") = e.file();
      error.attr("detail") = std::string(e.what());
      PyErr_SetObject(type.ptr(), error.ptr());
    }
  });

  const BuildOptions b;
  const MeshingOptions meshing;
  m.def("build", &build, py::arg("mesh"), py::kw_only(), py::arg("source") = py::none(),
        py::arg("clusters") = std::string(name_of(b.clusters)),
        py::arg("refine_visibility") = b.refinement.min_visibility,
        py::arg("refine_max_clusters") = b.refinement.max_clusters,
        py::arg("refine_gain") = b.refinement.gain_per_cut_edge,
        py::arg("refine_merge") = b.refinement.merge, py::arg("alpha") = b.segmentation.alpha,
        py::arg("beta_divisor") = b.segmentation.beta_divisor,
        py::arg("equalization") = std::string(name_of(b.segmentation.equalization)),
        py::arg("growth_bound") = b.segmentation.growth_bound,
        py::arg("grow_through_marked") = b.segmentation.grow_through_marked,
        py::arg("min_cluster_triangles") = b.segmentation.min_cluster_triangles,
        py::arg("detector") = std::string(name_of(b.segmentation.detector)),
        py::arg("min_visibility") = b.segmentation.min_visibility,
        py::arg("solver") = std::string(name_of(b.charge.solver)),
        py::arg("tolerance") = b.charge.tolerance, py::arg("cell_size") = meshing.cell_size,
        py::arg("facet_size") = meshing.facet_size,
        py::arg("facet_distance") = meshing.facet_distance, py::arg("optimize") = meshing.optimize,
        py::arg("threads") = meshing.threads,
        py::arg("repair") = std::string(name_of(meshing.repair)),
        py::arg("wrap_alpha") = meshing.wrap_alpha, py::arg("wrap_offset") = meshing.wrap_offset,
        py::arg("wrap_sheet_offset") = meshing.wrap_sheet_offset,
        py::arg("keep_largest_component") = meshing.keep_largest_component,
        py::arg("max_deviation") = meshing.max_deviation,
        py::arg("time_limit") = BuildJobOptions{}.time_limit,
        py::arg("rest_positions") = b.keep_rest_positions,
        py::arg("body") = std::string(name_of(b.body)), py::arg("detectors") = py::none(),
        py::arg("on_stage") = py::none(),
        "Returns (asset bytes, report dict). "
        "Runs the whole pipeline as `tetseg build` does. mesh: a tet mesh file (.mesh, "
        ".node/.ele, .msh), a closed surface file (.obj, .ply, .stl, .off, ...; tetrahedralised "
        "first with cell_size, facet_size, facet_distance, optimize, threads, repair, "
        "wrap_alpha, wrap_offset, wrap_sheet_offset, keep_largest_component, max_deviation), or a "
        "pair of arrays "
        "(nodes (N, 3), tets (M, 4)) or (points (N, 3), triangles (M, 3)). source: the name "
        "recorded in the asset's provenance and used in messages (default: the path, or "
        "'arrays'). Every other option is the `tetseg build` option of the same name "
        "(--no-optimize is optimize=False, --no-rest-positions is rest_positions=False). "
        "body='surface' builds a surface body from a surface (file or arrays) as it is: its "
        "vertices and triangles in their order, no tets; detectors: None (the body's own form: "
        "'weights' for a surface body), 'weights' or 'skin' (carried by the bones of the file's "
        "skin: a glTF or FBX file, not arrays). "
        "on_stage(name, seconds, summary) is called after each stage. The report dict is "
        "`tetseg build --report` (the same writer; no 'output') plus 'stages'. Load the bytes with "
        "tetseg.load_asset. Raises InputError for a bad mesh or a build past time_limit seconds "
        "(its detail names the stage), ValueError for a bad option.");

  const ChargeOptions c;
  m.def("charge", &charge, py::arg("mesh"), py::kw_only(), py::arg("source") = py::none(),
        py::arg("solver") = std::string(name_of(c.solver)), py::arg("tolerance") = c.tolerance,
        py::arg("max_iterations") = c.max_iterations, py::arg("theta") = c.fast_theta,
        py::arg("order") = c.fast_order, py::arg("relaxed_products") = c.relaxed_products,
        py::arg("equalize") = std::string(name_of(ChargeJobOptions{}.equalization)),
        py::arg("bins") = ChargeJobOptions{}.bins,
        "Returns a dict. "
        "Relative charge density of a tet mesh's boundary or of a closed surface, as "
        "`tetseg charge` computes it (docs/charge.md). mesh as for build. Returns density and "
        "equalized (per triangle), points and triangles (the surface they refer to), and the "
        "solver figures (solver, iterations, relaxed_products, residual, converged, tolerance, "
        "capacitance, total_area, equalization, assembly_seconds, solve_seconds). "
        "relaxed_products=False makes every fast-solver product exact to order and theta "
        "(`tetseg charge --exact-products`).");

  const ShapeOptions s;
  m.def("generate", &generate, py::arg("shape"), py::kw_only(), py::arg("size") = s.size,
        py::arg("radius") = s.radius,
        py::arg("axes") = std::array<double, 3>{s.axes[0], s.axes[1], s.axes[2]},
        py::arg("cell_size") = meshing.cell_size, py::arg("facet_size") = meshing.facet_size,
        py::arg("facet_distance") = meshing.facet_distance,
        py::arg("facet_angle") = meshing.facet_angle,
        py::arg("radius_edge_ratio") = meshing.cell_radius_edge_ratio,
        py::arg("optimize") = meshing.optimize, py::arg("threads") = meshing.threads,
        "Returns (nodes (N, 3) float64, tets (M, 4) uint32). "
        "Meshes a procedural shape as `tetseg generate` does: 'sphere', 'ellipsoid', "
        "'dumbbell' or 'pawn'. Deterministic with threads=1 (the default); threads > 1 meshes "
        "in parallel (oneTBB) and the mesh differs from run to run.");
}
