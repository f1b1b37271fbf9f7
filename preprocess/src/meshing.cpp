// Driving CGAL Mesh_3 on a surface: option checks, the default sizes, the vertex budget,
// sharp-edge protection, the time bound and the retries when the meshed boundary is not a
// closed 2-manifold. Which surface it meshes (fix, wrap, slab; --repair auto) is decided in
// tetrahedralize.cpp. No CGAL here: the Mesh_3 work is in mesh3_implicit.cpp and
// mesh3_polyhedral.cpp.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "components.hpp"
#include "mesh3_driver.hpp"
#include "meshing_internal.hpp"
#include "repair_internal.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "validate_internal.hpp"
#include "vec3_math.hpp"
#include "watchdog.hpp"

namespace tetseg::preprocess {
namespace {

constexpr double kSurfaceDiagonalDivisor = 40.0;
constexpr double kFacetDistanceRatio = 0.1;
/// Meshing sizes below diagonal / kMaxDiagonalPerSize are refused (10^5 facets along the
/// diagonal: hundreds of millions of tets, or refinement that never ends).
constexpr double kMaxDiagonalPerSize = 1e5;
/// Vertex budget of Mesh_3 on a surface: kBudgetFactor times the vertices of a mesh with the
/// criteria's sizes filling the bounding-box diagonal's cube, (D/cell)^3 + 6 (D/facet)^2, and
/// at least kMinBudget. Real meshes use under 2 % of it at default sizes (elephant 2.4k
/// vertices, cube_quad 11k of 589k). It stops runaway refinement; it cannot stop a loop that
/// inserts nothing (colored_tetra.ply, docs/benchmarks-history.md, "Protected sharp edges").
constexpr double kBudgetFactor = 8.0;
constexpr double kMinBudget = 200000.0;
/// Edges whose two triangles' normals differ by more than this (degrees; CGAL
/// detect_features' default) are sharp; they are protected before Mesh_3 refines the surface
/// when the input is coarse against the facet size: its median edge at least
/// kProtectEdgeFacets facet sizes (at 4, mpi.off ran over 180 s protected; a polyhedron whose flat
/// faces Mesh_3 refines, like the cube, the tetrahedra or the pyramid). Unprotected, Mesh_3's
/// manifold refinement can loop forever at such a corner (colored_tetra.ply); on finely tessellated
/// inputs (edges shorter than the facet size) the sharp edges are mostly tessellation noise, and
/// protecting them made dino and femur run over 180 s, hand fail (docs/benchmarks-history.md).
constexpr double kSharpEdgeDegrees = 60.0;
constexpr double kProtectEdgeFacets = 8.0;
/// Mesh_3 with protected sharp edges stops after this many seconds of its thread's CPU time
/// (the load of other processes does not move it; CGAL offers no count of its protection's
/// steps to bound instead) and the surface is
/// refused like one whose refinement reached the vertex budget: on corners much sharper than
/// the sizes (the needle tetrahedron (0,0,0), (1,0,0), (0,L,0), (0,0,1): L = 40 took 8 s, 80
/// 45 s, 160 over 5 min) CGAL's protection loops without inserting vertices, which the budget
/// cannot see. Coarse polyhedra that protection serves mesh in seconds (colored_tetra 1.6 s).
constexpr double kProtectedMeshingSeconds = 20.0;
/// Sharp edges meeting at a smaller angle (degrees) are not protected: the surface is refused
/// at once (auto then wraps it). The needle above: L = 40 (1.4 degrees) meshes in 8 s, L = 80
/// (0.72) took 45 s, L = 160 (0.36) over 5 minutes, L = 1000 not stopped by the bound above
/// for 100 s on a loaded machine (CGAL's protection polls its stop flag rarely there).
constexpr double kMinProtectedCornerDegrees = 1.0;
/// Likewise for a sharp edge's dihedral angle (flat slivers, thin blades): a tetrahedron of
/// height 1e-2 (1.9 degrees) ran into the 20 s bound.
constexpr double kMinProtectedDihedralDegrees = 5.0;
/// When no optimisation gives a valid boundary, meshing is retried with every size (facet,
/// cell, facet distance) times these factors in turn (the first is the asked size).
constexpr double kRetrySizeFactors[] = {1.0, 0.7, 0.5};
/// When the meshed boundary lies further than the asked distance from the surface it meshes
/// (--max-deviation), meshing is retried at most kMaxDeviationRetries times, each with the
/// facet distance times kDeviationRetryMargin x asked / measured distance (clamped to
/// [kMinRetryShrink, kMaxRetryShrink]) and the facet size times its square root (cell sizes
/// unchanged). Mesh_3's facet distance bounds the distance of its facets' centres from the
/// surface, not the Hausdorff distance: elephant deviates about twice its facet distance,
/// fandisk three times (docs/benchmarks.md).
constexpr int kMaxDeviationRetries = 2;
constexpr double kDeviationRetryMargin = 0.7;
constexpr double kMinRetryShrink = 0.25;
constexpr double kMaxRetryShrink = 0.7;
/// A retry protects the sharp edges at once when the input's sharp edges lie further than asked
/// from the mesh (Mesh_3 rounds them off unprotected: fandisk) and form at most this many
/// curves (connected sets of sharp edges): CAD parts (fandisk, cross 1, rotor 9, anchor 12).
/// Organic scans' sharp edges are mostly tessellation noise in many curves (triceratops 96,
/// femur 274, camel 77): their protected retries ran into the protection's time bound
/// (triceratops, femur) or helped (camel), so they are protected only after an unprotected
/// retry (keep_within_distance).
constexpr std::size_t kMaxProtectedCurves = 16;
/// Work bounds of the retries (deterministic, unlike time bounds: the same input gives the
/// same asset on a loaded machine). A retry is expected to make the first mesh's vertices
/// divided by its facet distance factor (surface vertices grow as the inverse square of the
/// facet size); it is not run when that passes kMaxRetryVertices (cheese: 26k vertices in 33 s
/// for its first mesh, its retries could not finish), each of its Mesh_3 runs stops after
/// kRetryVertexFactor times that, and all of them (the boundary retries: optimisation off,
/// smaller sizes) after kRetryRunsPerBudget times that again (refused as not converging: the
/// nearest mesh so far is kept). The time limit (--time-limit) stays the outer bound.
constexpr double kMaxRetryVertices = 40000.0;
constexpr double kRetryVertexFactor = 2.0;
constexpr std::size_t kRetryRunsPerBudget = 3;
/// Whether the deviation retries perturb slivers before exuding them. They do not: on a
/// retry's finer surface, perturbation took 7.5 of triceratops' 10 CPU seconds (exudation only:
/// 2.8 s, the same deviation); the boundary retries already accept exudation only.
constexpr bool kDeviationRetryPerturb = false;

}  // namespace

double detail::bounding_box_diagonal(const std::vector<Vec3>& points) {
  if (points.empty()) return 0.0;
  Vec3 lo = points.front();
  Vec3 hi = lo;
  for (const Vec3& p : points)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  return std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
}

namespace {

void require_positive(double value, const char* name) {
  if (!std::isfinite(value) || value <= 0.0)
    throw std::invalid_argument(std::string(name) + " must be a positive number");
}

void require_non_negative(double value, const char* name) {
  if (!std::isfinite(value) || value < 0.0)
    throw std::invalid_argument(std::string(name) + " must be zero or a positive number");
}

detail::Mesh3Criteria resolve(const MeshingOptions& o, double default_facet) {
  require_non_negative(o.cell_size, "cell size");
  require_non_negative(o.facet_size, "facet size");
  require_non_negative(o.facet_distance, "facet distance");
  if (!(o.facet_angle > 0.0 && o.facet_angle <= 30.0))
    throw std::invalid_argument("facet angle must be in (0, 30] degrees");
  if (!(o.cell_radius_edge_ratio >= 2.0 && std::isfinite(o.cell_radius_edge_ratio)))
    throw std::invalid_argument("cell radius-edge ratio must be at least 2");
  if (o.threads < 0) throw std::invalid_argument("threads must be zero or a positive number");
  if (o.threads != 1 && !meshing_threads_available())
    throw std::invalid_argument(
        "threads other than 1 need a build with oneTBB (Debian libtbb-dev); this one meshes "
        "sequentially only");
  detail::Mesh3Criteria c;
  c.threads = o.threads == 0 ? static_cast<int>(std::max(1u, std::thread::hardware_concurrency()))
                             : o.threads;
  c.facet_angle = o.facet_angle;
  c.cell_radius_edge_ratio = o.cell_radius_edge_ratio;
  c.optimize = o.optimize;
  c.facet_size = o.facet_size > 0 ? o.facet_size : (o.cell_size > 0 ? o.cell_size : default_facet);
  c.cell_size = o.cell_size > 0 ? o.cell_size : c.facet_size;
  c.facet_distance = o.facet_distance > 0 ? o.facet_distance : kFacetDistanceRatio * c.facet_size;
  return c;
}

}  // namespace

double default_facet_size(Shape shape, const ShapeOptions& o) {
  double h = 0.0;
  switch (shape) {
    case Shape::kSphere:
      h = 0.08 * o.radius;
      break;
    case Shape::kEllipsoid:
      h = 0.06 * std::max({o.axes[0], o.axes[1], o.axes[2]});
      break;
    case Shape::kDumbbell:
      h = 0.08;
      break;
    case Shape::kPawn:
      h = 0.043;
      break;
  }
  return h / o.size;
}

double default_facet_size_for_diagonal(double diagonal) {
  return diagonal / kSurfaceDiagonalDivisor;
}

TetMesh generate_shape(Shape shape, const ShapeOptions& shape_options,
                       const MeshingOptions& meshing) {
  require_positive(shape_options.radius, "radius");
  for (double a : shape_options.axes) require_positive(a, "ellipsoid axis");
  require_positive(shape_options.size, "size");
  if (shape_options.size > 64.0) throw std::invalid_argument("size must be at most 64");
  const detail::Mesh3Criteria criteria = resolve(meshing, default_facet_size(shape, shape_options));
  TetMesh mesh = detail::mesh_implicit_shape(shape, shape_options, criteria);
  if (mesh.tets.empty()) throw std::runtime_error("meshing produced no tetrahedra");
  return mesh;
}

namespace {

/// The sharp edges of `s` (two triangles whose unit normals differ by more than `degrees`: the
/// test of CGAL detect_sharp_edges; degenerate triangles ignored) and how sharp they meet.
struct SharpEdges {
  std::size_t count = 0;
  /// The smallest angle between two sharp edges at a common vertex, degrees (180 when none).
  double min_corner_degrees = 180.0;
  /// The largest angle between the normals of a sharp edge's two triangles, degrees: 180
  /// minus it is the edge's smallest (wedge or slit) dihedral angle.
  double max_normal_degrees = 0.0;
  /// The sharp edges, as pairs of vertex ids.
  std::vector<std::pair<std::uint32_t, std::uint32_t>> edges;
  /// The connected sets of sharp edges (sharing vertices): feature curves, or noise.
  std::size_t curves = 0;
};

/// How many connected sets the edges form (union-find over their vertex ids).
std::size_t count_edge_components(const std::vector<std::pair<std::uint32_t, std::uint32_t>>& edges,
                                  std::size_t vertex_count) {
  std::vector<std::uint32_t> parent(vertex_count);
  for (std::size_t v = 0; v < vertex_count; ++v) parent[v] = static_cast<std::uint32_t>(v);
  const auto root = [&](std::uint32_t v) {
    while (parent[v] != v) v = parent[v] = parent[parent[v]];
    return v;
  };
  std::size_t components = 0;
  std::vector<bool> touched(vertex_count, false);
  for (const auto& [a, b] : edges) {
    for (const std::uint32_t v : {a, b})
      if (!touched[v]) {
        touched[v] = true;
        ++components;
      }
    const std::uint32_t ra = root(a), rb = root(b);
    if (ra != rb) {
      parent[ra] = rb;
      --components;
    }
  }
  return components;
}

SharpEdges sharp_edges(const TriangleMesh& s, double degrees) {
  std::vector<Vec3> normal(s.triangles.size());
  for (std::size_t t = 0; t < s.triangles.size(); ++t) {
    const Vec3& a = s.vertices[s.triangles[t][0]];
    const Vec3 n = detail::cross(detail::sub(s.vertices[s.triangles[t][1]], a),
                                 detail::sub(s.vertices[s.triangles[t][2]], a));
    const double length = detail::norm(n);
    normal[t] = length > 0 ? Vec3{n[0] / length, n[1] / length, n[2] / length} : Vec3{0, 0, 0};
  }
  std::vector<std::pair<std::pair<std::uint32_t, std::uint32_t>, std::size_t>> edges;
  edges.reserve(3 * s.triangles.size());
  for (std::size_t t = 0; t < s.triangles.size(); ++t)
    for (int k = 0; k < 3; ++k) {
      const std::uint32_t a = s.triangles[t][k], b = s.triangles[t][(k + 1) % 3];
      edges.push_back({{std::min(a, b), std::max(a, b)}, t});
    }
  std::sort(edges.begin(), edges.end());
  const double min_cos = std::cos(degrees * detail::kPi / 180.0);
  SharpEdges out;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> sharp;  // (vertex, other end)
  for (std::size_t i = 1; i < edges.size(); ++i) {
    if (edges[i].first != edges[i - 1].first) continue;
    const Vec3& n = normal[edges[i].second];
    const Vec3& m = normal[edges[i - 1].second];
    if (detail::norm(n) > 0 && detail::norm(m) > 0 && detail::dot(n, m) < min_cos) {
      const double c = std::clamp(detail::dot(n, m), -1.0, 1.0);
      out.max_normal_degrees = std::max(out.max_normal_degrees, std::acos(c) * 180.0 / detail::kPi);
      const auto [a, b] = edges[i].first;
      out.edges.push_back({a, b});
      sharp.push_back({a, b});
      sharp.push_back({b, a});
    }
  }
  out.count = out.edges.size();
  out.curves = count_edge_components(out.edges, s.vertices.size());
  std::sort(sharp.begin(), sharp.end());
  sharp.erase(std::unique(sharp.begin(), sharp.end()), sharp.end());
  for (std::size_t i = 0; i < sharp.size();) {
    std::size_t j = i;
    while (j < sharp.size() && sharp[j].first == sharp[i].first) ++j;
    const Vec3& p = s.vertices[sharp[i].first];
    for (std::size_t a = i; a < j; ++a)
      for (std::size_t b = a + 1; b < j; ++b) {
        const Vec3 u = detail::sub(s.vertices[sharp[a].second], p);
        const Vec3 v = detail::sub(s.vertices[sharp[b].second], p);
        const double lengths = detail::norm(u) * detail::norm(v);
        if (!(lengths > 0)) continue;
        const double c = std::clamp(detail::dot(u, v) / lengths, -1.0, 1.0);
        out.min_corner_degrees =
            std::min(out.min_corner_degrees, std::acos(c) * 180.0 / detail::kPi);
      }
    i = j;
  }
  return out;
}

/// The median length of the triangles' edges (each edge counted once per triangle).
double median_edge_length(const TriangleMesh& s) {
  std::vector<double> lengths;
  lengths.reserve(3 * s.triangles.size());
  for (const Tri& t : s.triangles)
    for (int k = 0; k < 3; ++k)
      lengths.push_back(detail::norm(detail::sub(s.vertices[t[(k + 1) % 3]], s.vertices[t[k]])));
  if (lengths.empty()) return 0.0;
  const auto middle = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
  std::nth_element(lengths.begin(), middle, lengths.end());
  return *middle;
}

std::size_t vertex_budget(const detail::Mesh3Criteria& criteria, double diagonal) {
  const double per_cell = diagonal / criteria.cell_size;
  const double per_facet = diagonal / criteria.facet_size;
  const double estimate = per_cell * per_cell * per_cell + 6.0 * per_facet * per_facet;
  return static_cast<std::size_t>(std::min(std::max(kBudgetFactor * estimate, kMinBudget), 1e12));
}

/// Runs one CGAL Mesh_3 call; whatever CGAL throws becomes an InputError naming the file and
/// the stage.
/// `step` names it for the time limit and progress; the call is bounded by `bound_seconds`
/// when > 0, and with sharp-edge protection by kProtectedMeshingSeconds; past the bound it is
/// refused as not converging.
TetMesh run_mesh_3_guarded(const TriangleMesh& input, detail::Mesh3Criteria criteria,
                           const std::string& file, detail::Watchdog& watchdog,
                           const std::string& step, double bound_seconds) {
  const bool sharp = criteria.sharp_edge_angle > 0.0;
  if (sharp)
    bound_seconds = bound_seconds > 0.0 ? std::min(bound_seconds, kProtectedMeshingSeconds)
                                        : kProtectedMeshingSeconds;
  const bool bounded = bound_seconds > 0.0;
  if (bounded)
    watchdog.begin_bounded(step + (sharp ? ", sharp edges protected" : ""), bound_seconds);
  else
    watchdog.begin(step);
  struct EndBound {
    detail::Watchdog& watchdog;
    bool bounded;
    ~EndBound() {
      if (bounded) watchdog.end_bounded();
    }
  } end_bound{watchdog, bounded};
  criteria.stop = watchdog.stop_flag();
  criteria.seconds_left =
      bounded ? std::min(watchdog.seconds_left(), bound_seconds) : watchdog.seconds_left();
  // CGAL 5.5 writes dump-bug.mesh and dump-bug.binary.cgal to the working directory when a
  // Mesh_3 assertion fails (Refine_facets_3.h, "already inserted on surface"); those it made
  // here are removed, so that a failed run leaves no file.
  const char* const dumps[] = {"dump-bug.mesh", "dump-bug.binary.cgal"};
  bool dumped_before[2];
  for (int i = 0; i < 2; ++i) dumped_before[i] = std::filesystem::exists(dumps[i]);
  const auto remove_new_dumps = [&] {
    std::error_code ignored;
    for (int i = 0; i < 2; ++i)
      if (!dumped_before[i]) std::filesystem::remove(dumps[i], ignored);
  };
  try {
    return detail::mesh_polyhedral_surface(input, criteria);
  } catch (const InputError&) {
    remove_new_dumps();
    throw;
  } catch (const detail::MeshingStopped&) {
    remove_new_dumps();
    watchdog.check();  // the time limit: throws TimeLimitExceeded naming the step
    end_bound.bounded = false;
    if (!bounded || !watchdog.end_bounded()) throw;
    throw InputError(file, "tetrahedralize: CGAL Mesh_3 did not converge: it did not finish in " +
                               std::to_string(static_cast<int>(bound_seconds)) +
                               (sharp ? " s with the sharp edges protected (corners too sharp or "
                                        "parts too thin for its feature protection); try "
                                        "--repair wrap"
                                      : " s"));
  } catch (const detail::MeshingBudgetExceeded& e) {
    remove_new_dumps();
    throw InputError(file, std::string("tetrahedralize: CGAL Mesh_3 did not converge: ") +
                               e.what() +
                               " (sharp corners or needle-thin parts that its manifold "
                               "refinement cannot resolve); try --repair wrap");
  } catch (const std::bad_alloc&) {
    throw InputError(file,
                     "tetrahedralize: out of memory in CGAL Mesh_3 (is the facet size "
                     "much smaller than the surface?)");
  } catch (const std::exception& e) {
    remove_new_dumps();
    throw InputError(file, std::string("tetrahedralize: CGAL Mesh_3 failed: ") + e.what());
  }
}

/// The defect of the tets' boundary ("" when it is a valid closed 2-manifold): the checks of
/// validate_tet_mesh.
std::string boundary_defect(const TetMesh& mesh, const std::string& file) {
  try {
    extract_valid_surface(mesh, file);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

/// How a deviation retry changes the sizes mesh_closed_surface derives from the options.
struct RetrySizes {
  double facet_distance = 1.0;       ///< factor
  double facet_size = 1.0;           ///< factor (the cell size stays)
  bool protect_sharp_edges = false;  ///< whatever the input's edge lengths
  /// false: no sliver perturbation (exudation only, when optimising), kDeviationRetryPerturb.
  bool perturb = true;
  /// > 0: each Mesh_3 run of the call makes at most this many vertices, and the runs together
  /// (the boundary retries included) kRetryRunsPerBudget times that, each run's budget at most
  /// what the runs before it left (past it: refused as not converging); 0: each run has the
  /// budget of its sizes (vertex_budget).
  std::size_t run_vertices = 0;
};

/// Mesh_3 on a closed surface (pinch points allowed), checked, with the retries of
/// tetrahedralize; notes.optimization_used and notes.first_defect say which mesh was returned.
TetMesh mesh_closed_surface(const TriangleMesh& input, const MeshingOptions& meshing,
                            const std::string& file, TetrahedralizeNotes& notes,
                            detail::Watchdog& watchdog, double bound_seconds,
                            const RetrySizes& retry = {}) {
  const double diagonal = detail::bounding_box_diagonal(input.vertices);
  // Criteria are checked before CGAL sees them: every size finite and positive, and not so
  // small against the surface that refinement could never end (kMaxDiagonalPerSize).
  detail::Mesh3Criteria criteria = resolve(meshing, default_facet_size_for_diagonal(diagonal));
  if (!(diagonal > 0.0) || !std::isfinite(diagonal))
    throw InputError(file, "tetrahedralize: the surface has no extent");
  // A derived facet distance keeps Mesh_3's re-meshing within half of --max-deviation.
  if (meshing.facet_distance == 0.0)
    criteria.facet_distance =
        std::min(criteria.facet_distance, 0.5 * meshing.max_deviation * diagonal);
  criteria.facet_distance *= retry.facet_distance;
  criteria.facet_size *= retry.facet_size;
  for (const double size : {criteria.facet_size, criteria.cell_size, criteria.facet_distance})
    if (!(size * kMaxDiagonalPerSize >= diagonal))
      throw InputError(file, "tetrahedralize: a meshing size is below 1/" +
                                 std::to_string(static_cast<long>(kMaxDiagonalPerSize)) +
                                 " of the bounding-box diagonal (" + std::to_string(diagonal) +
                                 "); give larger --facet-size / --cell-size / --facet-distance");
  const double median_edge = median_edge_length(input);
  const SharpEdges sharp_features = sharp_edges(input, kSharpEdgeDegrees);
  const bool sharp = sharp_features.count > 0;
  // Mesh_3 refines with its manifold option, so the boundary of the refined tets is a closed
  // 2-manifold; sliver perturbation can break that (it moves vertices after refinement: on
  // rotor, homer, couplingdown and cheese it leaves non-manifold vertices or edges), and
  // exudation alone has not been seen to. Thin parts can also leave the cells in the complex
  // with a non-manifold edge or an enclosed void whatever the optimisation (femur.off). So the
  // boundary is checked, and meshing is retried with exudation only, then with no
  // optimisation, then the same at kRetrySizeFactors of every size; the first valid mesh is
  // returned.
  struct Attempt {
    const char* name;
    bool optimize;
    bool perturb;
  };
  std::vector<Attempt> attempts = {{"optimised", criteria.optimize, true}};
  if (criteria.optimize)
    attempts.insert(attempts.end(),
                    {{"exudation only", true, false}, {"no optimisation", false, false}});
  if (!retry.perturb && criteria.optimize) attempts.erase(attempts.begin());
  std::string first_defect;
  std::string defects;
  std::size_t vertices_made = 0;
  for (const double factor : kRetrySizeFactors) {
    detail::Mesh3Criteria sized = criteria;
    sized.facet_size *= factor;
    sized.cell_size *= factor;
    sized.facet_distance *= factor;
    sized.max_vertices = vertex_budget(sized, diagonal);
    if (sharp &&
        (retry.protect_sharp_edges || median_edge >= kProtectEdgeFacets * sized.facet_size)) {
      sized.sharp_edge_angle = kSharpEdgeDegrees;
      if (sharp_features.min_corner_degrees < kMinProtectedCornerDegrees)
        throw InputError(
            file, "tetrahedralize: CGAL Mesh_3 did not converge: sharp edges meet at " +
                      std::to_string(sharp_features.min_corner_degrees).substr(0, 6) +
                      " degrees, under the " +
                      std::to_string(kMinProtectedCornerDegrees).substr(0, 3) +
                      " its feature protection meshes in bounded time (a needle or spike); try "
                      "--repair wrap");
      const double dihedral = 180.0 - sharp_features.max_normal_degrees;
      if (dihedral < kMinProtectedDihedralDegrees)
        throw InputError(
            file,
            "tetrahedralize: CGAL Mesh_3 did not converge: a sharp edge has a dihedral "
            "angle of " +
                std::to_string(dihedral).substr(0, 6) + " degrees, under the " +
                std::to_string(kMinProtectedDihedralDegrees).substr(0, 3) +
                " its feature protection meshes in bounded time (a sliver or thin "
                "blade); try --repair wrap");
    }
    for (const Attempt& attempt : attempts) {
      detail::Mesh3Criteria tried = sized;
      tried.optimize = attempt.optimize;
      tried.perturb = attempt.perturb;
      if (retry.run_vertices > 0) {
        const std::size_t total = kRetryRunsPerBudget * retry.run_vertices;
        if (vertices_made >= total)
          throw InputError(file, "tetrahedralize: CGAL Mesh_3 did not converge within " +
                                     std::to_string(total) + " vertices");
        tried.max_vertices =
            std::min({tried.max_vertices, retry.run_vertices, total - vertices_made});
      }
      const TetMesh mesh =
          run_mesh_3_guarded(input, tried, file, watchdog,
                             std::string("CGAL Mesh_3 (") + attempt.name + ", sizes x" +
                                 std::to_string(factor).substr(0, 3) + ")",
                             bound_seconds);
      vertices_made += mesh.nodes.size();
      if (mesh.tets.empty())
        throw InputError(file,
                         "meshing produced no tetrahedra (is the surface closed and "
                         "larger than the facet size?)");
      const std::string defect = boundary_defect(mesh, file);
      if (defect.empty()) {
        if (!first_defect.empty()) {
          notes.optimization_used = attempt.name;
          if (factor != 1.0)
            notes.optimization_used += ", sizes x" + std::to_string(factor).substr(0, 3);
          notes.first_defect = first_defect;
        }
        return mesh;
      }
      if (first_defect.empty()) first_defect = defect;
      if (factor == 1.0)
        defects += std::string(defects.empty() ? "" : "; ") + attempt.name + ": " + defect;
    }
  }
  throw InputError(file, "tetrahedralize: the meshed boundary is not a closed 2-manifold (" +
                             defects +
                             "; also at 0.7 and 0.5 of the sizes); thin parts may "
                             "need a smaller --facet-size");
}

/// The larger of the two (approximate) Hausdorff distances between `surface` and the boundary
/// of `mesh`, absolute; -1 when not measurable.
double boundary_distance(const TriangleMesh& surface, const TetMesh& mesh) {
  const TriangleMesh boundary{mesh.nodes, extract_surface(mesh).triangles};
  const auto [there, back] = detail::hausdorff_distances(surface, boundary);
  return std::max(there, back);
}

/// Points along the sharp edges of `surface` (each edge's ends and its quarter points; at most
/// about kMaxSharpEdgeSamples points, every k-th edge beyond).
std::vector<Vec3> sharp_edge_samples(const TriangleMesh& surface, const SharpEdges& sharp) {
  constexpr std::size_t kMaxSharpEdgeSamples = 20000;
  constexpr int kPerEdge = 4;
  std::vector<Vec3> points;
  const std::size_t stride =
      std::max<std::size_t>(1, kPerEdge * sharp.edges.size() / kMaxSharpEdgeSamples + 1);
  for (std::size_t e = 0; e < sharp.edges.size(); e += stride) {
    const Vec3& a = surface.vertices[sharp.edges[e].first];
    const Vec3& b = surface.vertices[sharp.edges[e].second];
    for (int k = 0; k < kPerEdge; ++k) {
      const double t = static_cast<double>(k) / kPerEdge;
      points.push_back(
          {a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1]), a[2] + t * (b[2] - a[2])});
    }
  }
  return points;
}

/// The deviation retries (kMaxDeviationRetries): while the boundary of `mesh` lies further than
/// `max_distance` (absolute, > 0) from `surface`, meshing is repeated at smaller sizes, and the
/// nearest mesh is returned, with its notes; notes.deviation_retries counts the meshings
/// repeated.
/// Sharp edges lying further than `max_distance` from the mesh are protected at once when they
/// form at most kMaxProtectedCurves curves; else first unprotected, and protected at the same
/// sizes only when the unprotected retry leaves them that far and over `max_distance` (camel:
/// 0.011 -> 0.0039 protected; triceratops and femur meet it unprotected, whose protected
/// retries ran into their bound). A protected retry refused is followed by the same sizes
/// unprotected.
TetMesh keep_within_distance(const TriangleMesh& surface, TetMesh best, double max_distance,
                             const MeshingOptions& meshing, const std::string& file,
                             TetrahedralizeNotes& notes, detail::Watchdog& watchdog) {
  watchdog.begin("deviation of the meshed boundary");
  double best_distance = boundary_distance(surface, best);
  if (!(best_distance > max_distance)) return best;
  const TetrahedralizeNotes notes_before = notes;
  const SharpEdges sharp = sharp_edges(surface, kSharpEdgeDegrees);
  const std::vector<Vec3> sharp_samples = sharp_edge_samples(surface, sharp);
  const bool feature_curves = sharp.curves <= kMaxProtectedCurves;
  const auto sharp_edges_far = [&](const TetMesh& mesh) {
    if (sharp_samples.empty()) return false;
    const TriangleMesh boundary{mesh.nodes, extract_surface(mesh).triangles};
    return detail::max_distance_to_surface(sharp_samples, boundary) > max_distance;
  };
  const double first_vertices = static_cast<double>(best.nodes.size());
  RetrySizes sizes;  // those of `best`
  sizes.perturb = kDeviationRetryPerturb;
  std::string best_sizes;
  std::size_t retries = 0;
  bool repeat_flipped = false;  // the next retry: the last sizes, the protection switched
  bool flipped = false;         // the last retry was such a repeat
  bool protection_failed = false;
  RetrySizes tried_sizes;
  for (int retry = 1; retry <= kMaxDeviationRetries; ++retry) {
    if (repeat_flipped) {
      tried_sizes.protect_sharp_edges = !tried_sizes.protect_sharp_edges;
    } else {
      const double shrink = std::clamp(kDeviationRetryMargin * max_distance / best_distance,
                                       kMinRetryShrink, kMaxRetryShrink);
      tried_sizes = sizes;
      tried_sizes.facet_distance *= shrink;
      tried_sizes.facet_size *= std::sqrt(shrink);
      const double expected_vertices = first_vertices / tried_sizes.facet_distance;
      if (expected_vertices > kMaxRetryVertices) break;
      tried_sizes.run_vertices =
          static_cast<std::size_t>(std::ceil(kRetryVertexFactor * expected_vertices));
      tried_sizes.protect_sharp_edges =
          !protection_failed &&
          (sizes.protect_sharp_edges || (feature_curves && sharp_edges_far(best)));
    }
    // Near the time limit (the outer bound, wall time), a retry gets at most half of what is
    // left, so that it cannot make the build refused that has a mesh already.
    const double time_left = 0.5 * watchdog.seconds_left();
    if (!(time_left > 1.0)) break;
    flipped = repeat_flipped;
    repeat_flipped = false;
    TetrahedralizeNotes tried_notes = notes_before;
    TetMesh tried;
    ++retries;
    try {
      tried = mesh_closed_surface(surface, meshing, file, tried_notes, watchdog,
                                  time_left < 1e6 ? time_left : 0.0, tried_sizes);
    } catch (const TimeLimitExceeded&) {
      throw;
    } catch (const InputError&) {
      // Refused (over its vertex bound, the protection's time bound, or CGAL failed): the same
      // sizes with the protection switched, once; else the nearest mesh so far is kept.
      if (tried_sizes.protect_sharp_edges) protection_failed = true;
      repeat_flipped = !flipped && (tried_sizes.protect_sharp_edges ||
                                    (!protection_failed && sharp_edges_far(best)));
      if (!repeat_flipped) break;
      continue;
    }
    watchdog.begin("deviation of the meshed boundary");
    const double distance = boundary_distance(surface, tried);
    const bool nearer = distance >= 0.0 && distance < best_distance;
    if (nearer) {
      char text[120];
      std::snprintf(text, sizeof text, "facet distance x%.2g, facet size x%.2g%s%s",
                    tried_sizes.facet_distance, tried_sizes.facet_size,
                    tried_sizes.protect_sharp_edges ? ", sharp edges protected" : "",
                    !tried_sizes.perturb && meshing.optimize ? ", no sliver perturbation" : "");
      best_distance = distance;
      best_sizes = text;
      sizes = tried_sizes;
      notes = tried_notes;
      if (distance <= max_distance) {
        best = std::move(tried);
        break;
      }
    }
    repeat_flipped = !flipped && !tried_sizes.protect_sharp_edges && !protection_failed &&
                     sharp_edges_far(tried);
    if (nearer) best = std::move(tried);
    if (!nearer && !repeat_flipped) break;  // smaller sizes did not bring it nearer
  }
  notes.deviation_retries = retries;
  notes.deviation_retry_sizes = best_sizes;
  return best;
}

}  // namespace

TetMesh detail::validate_and_mesh(const TriangleMesh& source, const MeshingOptions& meshing,
                                  const std::string& file, TetrahedralizeNotes& notes,
                                  detail::Watchdog& watchdog, double bound_seconds,
                                  double max_distance) {
  watchdog.begin("surface validation");
  TriangleMesh split;
  detail::SurfaceCheck check;
  check.allow_pinched_vertices = true;
  check.allow_components = true;  // Mesh_3 meshes each closed component; the tets are checked
  try {
    detail::validate_closed_surface(source, file, check, &split);
  } catch (const InputError& e) {
    if (meshing.repair != MeshingOptions::Repair::kFix) throw;
    throw InputError(file, std::string(e.what()) +
                               ", left after --repair fix; --repair wrap makes a closed surface "
                               "of any input (docs/cli.md)");
  }
  detail::check_surface_not_nested(source, file);
  const TriangleMesh& meshed = split.triangles.empty() ? source : split;
  TetMesh mesh = mesh_closed_surface(meshed, meshing, file, notes, watchdog, bound_seconds);
  if (!(max_distance > 0.0)) return mesh;
  return keep_within_distance(meshed, std::move(mesh), max_distance, meshing, file, notes,
                              watchdog);
}

}  // namespace tetseg::preprocess
