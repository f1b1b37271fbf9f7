// Meshing options, size rules and entry points. No CGAL here: the Mesh_3 work is in
// mesh3_implicit.cpp and mesh3_polyhedral.cpp.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "components.hpp"
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
/// Mesh_3 with protected sharp edges stops after this many seconds and the surface is
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
/// The smallest --wrap-alpha and --wrap-offset, as fractions of the diagonal.
constexpr double kMinWrapFraction = 1e-4;

double bounding_box_diagonal(const std::vector<Vec3>& points) {
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
};

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
  const double min_cos = std::cos(degrees * M_PI / 180.0);
  SharpEdges out;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> sharp;  // (vertex, other end)
  for (std::size_t i = 1; i < edges.size(); ++i) {
    if (edges[i].first != edges[i - 1].first) continue;
    const Vec3& n = normal[edges[i].second];
    const Vec3& m = normal[edges[i - 1].second];
    if (detail::norm(n) > 0 && detail::norm(m) > 0 && detail::dot(n, m) < min_cos) {
      const double c = std::clamp(detail::dot(n, m), -1.0, 1.0);
      out.max_normal_degrees = std::max(out.max_normal_degrees, std::acos(c) * 180.0 / M_PI);
      const auto [a, b] = edges[i].first;
      sharp.push_back({a, b});
      sharp.push_back({b, a});
    }
  }
  out.count = sharp.size() / 2;
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
        out.min_corner_degrees = std::min(out.min_corner_degrees, std::acos(c) * 180.0 / M_PI);
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

/// Mesh_3 on a closed surface (pinch points allowed), checked, with the retries of
/// tetrahedralize; notes.optimization_used and notes.first_defect say which mesh was returned.
TetMesh mesh_closed_surface(const TriangleMesh& input, const MeshingOptions& meshing,
                            const std::string& file, TetrahedralizeNotes& notes,
                            detail::Watchdog& watchdog, double bound_seconds) {
  const double diagonal = bounding_box_diagonal(input.vertices);
  // Criteria are checked before CGAL sees them: every size finite and positive, and not so
  // small against the surface that refinement could never end (kMaxDiagonalPerSize).
  detail::Mesh3Criteria criteria = resolve(meshing, default_facet_size_for_diagonal(diagonal));
  if (!(diagonal > 0.0) || !std::isfinite(diagonal))
    throw InputError(file, "tetrahedralize: the surface has no extent");
  // A derived facet distance keeps Mesh_3's re-meshing within half of --max-deviation.
  if (meshing.facet_distance == 0.0)
    criteria.facet_distance =
        std::min(criteria.facet_distance, 0.5 * meshing.max_deviation * diagonal);
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
  std::string first_defect;
  std::string defects;
  for (const double factor : kRetrySizeFactors) {
    detail::Mesh3Criteria sized = criteria;
    sized.facet_size *= factor;
    sized.cell_size *= factor;
    sized.facet_distance *= factor;
    sized.max_vertices = vertex_budget(sized, diagonal);
    if (sharp && median_edge >= kProtectEdgeFacets * sized.facet_size) {
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
      const TetMesh mesh =
          run_mesh_3_guarded(input, tried, file, watchdog,
                             std::string("CGAL Mesh_3 (") + attempt.name + ", sizes x" +
                                 std::to_string(factor).substr(0, 3) + ")",
                             bound_seconds);
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

}  // namespace

namespace {

/// Area and enclosed volume (divergence theorem; for a closed, outward surface) of `s`.
std::pair<double, double> area_and_volume(const TriangleMesh& s) {
  double area = 0.0, volume = 0.0;
  for (const Tri& t : s.triangles) {
    const Vec3& a = s.vertices[t[0]];
    const Vec3 n =
        detail::cross(detail::sub(s.vertices[t[1]], a), detail::sub(s.vertices[t[2]], a));
    area += 0.5 * detail::norm(n);
    volume += detail::dot(a, n) / 6.0;
  }
  return {area, volume};
}

/// A wrap is a thin shell where it went through a hole wider than alpha and wrapped both
/// sides of the input: there it is about 2 x offset thick, and Mesh_3 cannot fill it (it fails,
/// or on cube-ouvert.off does not end). Two tests, either one makes a wrap thin:
/// - its volume is below kThinShell x offset x area (a wrap that is a thin shell all over has
///   a volume of about offset x area; a solid's is far more);
/// - at least kThinShare of kThinProbes vertices (every k-th) are on a thin part: the point
///   kThinProbeDepth x offset inside along the vertex normal is outside the wrap (generalised
///   winding number below 1/2). On libcgal-demo (docs/benchmarks-history.md, "Real meshes") the
///   wraps of closed solids have shares 0-0.09; cube-ouvert's partly entered wrap (alpha
///   0.16), which the volume test lets through, 0.61. Wraps of open surfaces that Mesh_3 did
///   mesh reach 0.66, so no threshold is exact: three of them now take one more doubling.
constexpr double kThinShell = 4.0;
constexpr double kThinShare = 0.55;
constexpr double kThinProbeDepth = 3.0;
constexpr std::size_t kThinProbes = 512;
constexpr double kPi = 3.14159265358979323846;
/// With --repair wrap, alpha is doubled at most this many times (see tetrahedralize).
constexpr int kMaxAlphaDoublings = 6;
/// A wrap bridges the gaps and holes narrower than alpha, so its distance from the input grows
/// with alpha (libcgal-demo, docs/benchmarks-history.md: about 0.01-0.04 of the diagonal at
/// alpha 0.02, 0.05-0.08 at 0.08, 0.22-0.32 at 0.32). Alpha is doubled past
/// kAlphaPerDeviation x --max-deviation (or --wrap-alpha when larger) only when the slab
/// (mesh_sheet_slab, within about --wrap-sheet-offset of the input) does not mesh.
constexpr double kAlphaPerDeviation = 2.0;
/// That slab's Mesh_3 runs are bounded (seconds; past it, the doublings): slabs mesh in 1-20 s
/// on libcgal-demo, but b9_mesh.off's ran over 300 s.
constexpr double kSlabMeshingSeconds = 20.0;

/// The share of the probed vertices of `wrap` (closed, outward) that lie on a thin part (see
/// kThinShare). O(kThinProbes x triangles).
double thin_share(const TriangleMesh& wrap, double offset) {
  std::vector<Vec3> normal(wrap.vertices.size(), Vec3{0.0, 0.0, 0.0});
  for (const Tri& t : wrap.triangles) {
    const Vec3& a = wrap.vertices[t[0]];
    const Vec3 n =
        detail::cross(detail::sub(wrap.vertices[t[1]], a), detail::sub(wrap.vertices[t[2]], a));
    for (const std::uint32_t v : t)
      for (int k = 0; k < 3; ++k) normal[v][k] += n[k];
  }
  const std::size_t stride = std::max<std::size_t>(1, wrap.vertices.size() / kThinProbes);
  std::size_t probed = 0, thin = 0;
  for (std::size_t v = 0; v < wrap.vertices.size(); v += stride) {
    const double length = detail::norm(normal[v]);
    if (!(length > 0.0)) continue;
    Vec3 probe;
    for (int k = 0; k < 3; ++k)
      probe[k] = wrap.vertices[v][k] - kThinProbeDepth * offset * normal[v][k] / length;
    double angle = 0.0;
    for (const Tri& t : wrap.triangles)
      angle +=
          detail::solid_angle(probe, wrap.vertices[t[0]], wrap.vertices[t[1]], wrap.vertices[t[2]]);
    ++probed;
    if (angle < 2.0 * kPi) ++thin;  // winding number below 1/2: outside
  }
  return probed == 0 ? 1.0 : static_cast<double>(thin) / static_cast<double>(probed);
}

bool is_thin_shell(const TriangleMesh& wrap, double offset) {
  const auto [area, volume] = area_and_volume(wrap);
  return volume < kThinShell * offset * area || thin_share(wrap, offset) >= kThinShare;
}

/// The alpha wrap of `surface` (`--repair wrap`) with alpha `alpha` and offset `offset`, both
/// fractions of the bounding-box diagonal `diagonal`.
TriangleMesh wrapped_surface(const TriangleMesh& surface, double alpha, double offset,
                             double diagonal, const std::string& file, detail::Watchdog& watchdog) {
  watchdog.begin("CGAL alpha wrap (alpha " + std::to_string(alpha) + ", offset " +
                 std::to_string(offset) + ")");
  try {
    return detail::alpha_wrap(surface, alpha * diagonal, offset * diagonal);
  } catch (const std::bad_alloc&) {
    throw InputError(file,
                     "tetrahedralize: out of memory in CGAL alpha wrapping (is --wrap-alpha "
                     "much smaller than the surface?)");
  } catch (const std::exception& e) {
    throw InputError(file, std::string("tetrahedralize: CGAL alpha wrapping failed: ") + e.what());
  }
}

/// Validation (pinch points accepted: the domain only needs inside/outside queries, and the
/// output is validated strictly) and Mesh_3 of a surface; after --repair fix, what is left is
/// named with a pointer to wrap.
TetMesh validate_and_mesh(const TriangleMesh& source, const MeshingOptions& meshing,
                          const std::string& file, TetrahedralizeNotes& notes,
                          detail::Watchdog& watchdog, double bound_seconds = 0.0) {
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
  return mesh_closed_surface(split.triangles.empty() ? source : split, meshing, file, notes,
                             watchdog, bound_seconds);
}

/// The repair kind of mesh_sheet_slab (the count: the slab's thickness, 1e-4 of the diagonal).
constexpr const char* kSlabRepair =
    "surface wrapped as a slab this many ten thousandths of the diagonal thick";

/// An input that encloses no volume (its wrap is a thin shell even with alpha = the diagonal:
/// a flat or open sheet), or one whose wrap went through its holes (wrap_and_mesh), is wrapped
/// again, with --wrap-alpha and the larger offset
/// --wrap-sheet-offset, into a closed slab about 2 x that offset thick, and meshed.
TetMesh mesh_sheet_slab(const TriangleMesh& surface, const MeshingOptions& meshing, double diagonal,
                        const std::string& file, TetrahedralizeNotes& notes,
                        detail::Watchdog& watchdog, double bound_seconds = 0.0) {
  const TriangleMesh slab = wrapped_surface(surface, meshing.wrap_alpha, meshing.wrap_sheet_offset,
                                            diagonal, file, watchdog);
  TetMesh mesh;
  try {
    mesh = validate_and_mesh(slab, meshing, file, notes, watchdog, bound_seconds);
  } catch (const TimeLimitExceeded&) {
    throw;
  } catch (const InputError& e) {
    throw InputError(file, std::string(e.what()) +
                               " (meshing the slab wrapped around an input that encloses no "
                               "volume, --wrap-sheet-offset " +
                               std::to_string(meshing.wrap_sheet_offset) + ")");
  }
  notes.repairs = {
      {"surface replaced by an alpha wrap of this many triangles", slab.triangles.size()},
      {kSlabRepair, static_cast<std::size_t>(std::lround(2.0 * meshing.wrap_sheet_offset * 1e4))}};
  return mesh;
}

/// --repair wrap: wraps and meshes; while the wrap is a thin shell (is_thin_shell) or does not
/// mesh (thin parts), alpha is doubled (at most kMaxAlphaDoublings times, up to the whole
/// diagonal), without running Mesh_3 on thin wraps (slow on them). A thin wrap whose next alpha
/// would pass kAlphaPerDeviation x --max-deviation is first replaced by the slab
/// (mesh_sheet_slab: the surface stays within about --wrap-sheet-offset); the doublings go on
/// only when the slab does not mesh. A wrap still thin at the end means that the input encloses
/// no volume: mesh_sheet_slab.
TetMesh wrap_and_mesh(const TriangleMesh& surface, const MeshingOptions& meshing,
                      const std::string& file, TetrahedralizeNotes& notes,
                      detail::Watchdog& watchdog) {
  const auto check_fraction = [](double value, const char* what) {
    if (!(value >= kMinWrapFraction && value <= 1.0))
      throw std::invalid_argument(std::string(what) +
                                  " must be in [1e-4, 1] (a fraction of the diagonal)");
  };
  check_fraction(meshing.wrap_alpha, "wrap alpha");
  check_fraction(meshing.wrap_offset, "wrap offset");
  check_fraction(meshing.wrap_sheet_offset, "wrap sheet offset");
  if (surface.triangles.empty()) throw InputError(file, "tetrahedralize: surface has no triangles");
  const double diagonal = bounding_box_diagonal(surface.vertices);
  if (!(diagonal > 0.0) || !std::isfinite(diagonal))
    throw InputError(file, "tetrahedralize: the surface has no extent");
  double alpha = meshing.wrap_alpha;
  // The wrap lies `offset` outside the input: at most a quarter of --max-deviation.
  const double offset = std::min(meshing.wrap_offset, 0.25 * meshing.max_deviation);
  const double max_alpha_within_deviation =
      std::max(meshing.wrap_alpha, kAlphaPerDeviation * meshing.max_deviation);
  bool slab_tried = false;
  for (std::size_t doublings = 0;; ++doublings) {
    const bool last = doublings == kMaxAlphaDoublings || alpha >= 1.0;
    const TriangleMesh wrap = wrapped_surface(surface, alpha, offset, diagonal, file, watchdog);
    const bool thin = is_thin_shell(wrap, offset * diagonal);
    if (last && thin) return mesh_sheet_slab(surface, meshing, diagonal, file, notes, watchdog);
    if (!thin) {
      try {
        TetMesh mesh = validate_and_mesh(wrap, meshing, file, notes, watchdog);
        notes.repairs = {
            {"surface replaced by an alpha wrap of this many triangles", wrap.triangles.size()}};
        if (doublings > 0)
          notes.repairs.push_back(
              {"alpha doublings as the wrap was a thin shell or did not mesh", doublings});
        return mesh;
      } catch (const TimeLimitExceeded&) {
        throw;
      } catch (const InputError& e) {
        if (last)
          throw InputError(file, std::string(e.what()) + " (meshing the alpha wrap, alpha " +
                                     std::to_string(alpha) + " of the diagonal)");
      }
    }
    // The wrap went through holes, wrapped a sheet or did not mesh: a larger alpha would
    // bridge more and move the surface further than --max-deviation, so the slab around the
    // input is tried first.
    if (!slab_tried && 2.0 * alpha > max_alpha_within_deviation) {
      slab_tried = true;
      try {
        return mesh_sheet_slab(surface, meshing, diagonal, file, notes, watchdog,
                               kSlabMeshingSeconds);
      } catch (const TimeLimitExceeded&) {
        throw;
      } catch (const InputError&) {
        // Back to the doublings; only what the slab's meshing wrote is dropped.
        TetrahedralizeNotes kept;
        kept.repair_used = notes.repair_used;
        kept.fallback_reason = notes.fallback_reason;
        notes = kept;
      }
    }
    alpha = std::min(2.0 * alpha, 1.0);
  }
}

}  // namespace

std::string deviation_summary(const TetrahedralizeNotes& notes) {
  if (notes.hausdorff_input_to_mesh < 0.0) return "deviation not measured";
  char text[160];
  std::snprintf(text, sizeof text,
                "deviation %.2g / %.2g of the diagonal (input to mesh / mesh to input)",
                notes.hausdorff_input_to_mesh, notes.hausdorff_mesh_to_input);
  return text;
}

namespace {

/// tetrahedralize in the surface's own coordinates (below).
TetMesh tetrahedralize_in_place(const TriangleMesh& surface, const MeshingOptions& meshing,
                                const std::string& file, TetrahedralizeNotes* notes);

/// Where a surface is meshed: far from the origin against its size, or very large or small,
/// it is moved to the origin and scaled by a power of two to a diagonal in [1, 2) (Mesh_3's
/// constructions lose precision there: a tetrahedron of side 1e11 at 1e12 sent its exuder into
/// exact arithmetic for minutes); other surfaces are meshed where they are (`moved` false).
struct MeshingFrame {
  bool moved = false;
  Vec3 centre{0.0, 0.0, 0.0};
  double scale = 1.0;  ///< a power of two
};

MeshingFrame meshing_frame(const TriangleMesh& s) {
  MeshingFrame frame;
  if (s.vertices.empty()) return frame;
  Vec3 lo = s.vertices.front(), hi = lo;
  for (const Vec3& p : s.vertices)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], p[k]);
      hi[k] = std::max(hi[k], p[k]);
    }
  const double diagonal = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
  if (!(diagonal > 0.0) || !std::isfinite(diagonal)) return frame;
  double far = 0.0;
  for (int k = 0; k < 3; ++k) far = std::max(far, std::fabs(0.5 * (lo[k] + hi[k])));
  frame.moved = diagonal < 1e-3 || diagonal > 1e6 || far > 1e3 * diagonal;
  if (!frame.moved) return frame;
  for (int k = 0; k < 3; ++k) frame.centre[k] = 0.5 * (lo[k] + hi[k]);
  frame.scale = std::ldexp(1.0, -std::ilogb(diagonal));
  return frame;
}

}  // namespace

TetMesh tetrahedralize(const TriangleMesh& surface, const MeshingOptions& meshing,
                       const std::string& file, TetrahedralizeNotes* notes) {
  const MeshingFrame frame = meshing_frame(surface);
  if (!frame.moved) return tetrahedralize_in_place(surface, meshing, file, notes);
  TriangleMesh moved = surface;
  for (Vec3& p : moved.vertices)
    for (int k = 0; k < 3; ++k) p[k] = (p[k] - frame.centre[k]) * frame.scale;
  MeshingOptions scaled = meshing;
  for (double* size : {&scaled.cell_size, &scaled.facet_size, &scaled.facet_distance})
    *size *= frame.scale;
  TetrahedralizeNotes local_notes;
  TetrahedralizeNotes& out_notes = notes != nullptr ? *notes : local_notes;
  TetMesh mesh = tetrahedralize_in_place(moved, scaled, file, &out_notes);
  for (Vec3& p : mesh.nodes)
    for (int k = 0; k < 3; ++k) p[k] = p[k] / frame.scale + frame.centre[k];
  out_notes.diagonal /= frame.scale;  // the relative distances do not change
  return mesh;
}

namespace {

/// How far the surface moved (repairs, wrap and Mesh_3's re-meshing of the boundary): the
/// distances between the input and the boundary of the tets, whatever the repair, into `notes`.
void measure_deviation(const TriangleMesh& surface, const TetMesh& mesh,
                       const MeshingOptions& meshing, double diagonal, TetrahedralizeNotes& notes) {
  const Surface boundary = extract_surface(mesh);
  const TriangleMesh meshed{mesh.nodes, boundary.triangles};
  const auto [there, back] = detail::hausdorff_distances(surface, meshed);
  if (there >= 0.0 && diagonal > 0.0) {
    notes.hausdorff_input_to_mesh = there / diagonal;
    notes.hausdorff_mesh_to_input = back / diagonal;
    notes.diagonal = diagonal;
    notes.deviation_excess =
        std::max(0.0, std::max(there, back) / diagonal - meshing.max_deviation);
  }
}

/// Hole patches making at least this share of a fixed surface's area close an open surface
/// (a mask, a box without its lid) rather than mend a defect: --repair auto then checks them
/// against --max-deviation (fix_or_wrap). libcgal-demo, about: the 7 holes of pig.off make 4 %,
/// the base of head.off 8 %, open_cube.off's missing face 17 %, nefertiti.off's open back 43 %.
constexpr double kOpenPatchShare = 0.15;

/// The larger of the two notes' distances (relative); infinite when not measured.
double larger_deviation(const TetrahedralizeNotes& notes) {
  if (notes.hausdorff_input_to_mesh < 0.0) return std::numeric_limits<double>::infinity();
  return std::max(notes.hausdorff_input_to_mesh, notes.hausdorff_mesh_to_input);
}

/// --repair fix's repairs of `surface` (detail::repair_soup; the repairs into `notes`).
TriangleMesh fixed_surface(const TriangleMesh& surface, const MeshingOptions& meshing,
                           const std::string& file, TetrahedralizeNotes& notes,
                           detail::Watchdog& watchdog, double* patch_area = nullptr) {
  watchdog.begin("repair");
  TriangleMesh fixed = surface;
  notes.repairs = detail::repair_soup(fixed, meshing.keep_largest_component, patch_area);
  if (fixed.triangles.empty())
    throw InputError(file, "tetrahedralize: no triangle is left after repair");
  return fixed;
}

/// --repair auto: fix, and the wrap when what fix leaves cannot be meshed (any refusal of the
/// surface or of Mesh_3 but the time limit, which is the user's bound on the whole), or when
/// fix closed an open surface across: hole patches of at least kOpenPatchShare of the area
/// lying further than --max-deviation from the input (the wrap keeps nearer, as a slab if need
/// be). In that last case the fixed surface is meshed after all when the wrap fails or
/// deviates more.
TetMesh fix_or_wrap(const TriangleMesh& surface, const MeshingOptions& meshing, double diagonal,
                    const std::string& file, TetrahedralizeNotes& notes,
                    detail::Watchdog& watchdog) {
  using Repair = MeshingOptions::Repair;
  notes.repair_used = Repair::kFix;
  TriangleMesh fixed;
  double fix_deviation = 0.0;  // how far fix's hole patches are from the input, relative
  double patch_share = 0.0;
  std::string fix_error;
  try {
    double patch_area = 0.0;
    fixed = fixed_surface(surface, meshing, file, notes, watchdog, &patch_area);
    patch_share = patch_area / area_and_volume(fixed).first;
    if (patch_share >= kOpenPatchShare && diagonal > 0.0) {
      watchdog.begin("deviation of the hole patches");
      const auto [there, back] = detail::hausdorff_distances(surface, fixed);
      fix_deviation = std::max(there, back) / diagonal;
    }
    if (fix_deviation <= meshing.max_deviation)
      return validate_and_mesh(fixed, meshing, file, notes, watchdog);
  } catch (const TimeLimitExceeded&) {
    throw;
  } catch (const InputError& e) {
    fix_error = e.what();
  }
  const bool fixed_too_far = fix_error.empty();  // else fix's result could not be meshed
  const TetrahedralizeNotes fix_notes = notes;
  notes = TetrahedralizeNotes{};
  notes.repair_used = Repair::kWrap;
  if (fixed_too_far) {
    char reason[200];
    std::snprintf(reason, sizeof reason,
                  "tetrahedralize: the holes filled by fix (%.0f %% of the area) lie %.2g of "
                  "the diagonal from the input, over --max-deviation %.2g",
                  100.0 * patch_share, fix_deviation, meshing.max_deviation);
    notes.fallback_reason = reason;
  } else {
    notes.fallback_reason = fix_error;
  }
  TetMesh wrapped;
  try {
    wrapped = wrap_and_mesh(surface, meshing, file, notes, watchdog);
    if (!fixed_too_far) return wrapped;
    watchdog.begin("deviation measurement");
    measure_deviation(surface, wrapped, meshing, diagonal, notes);
    if (larger_deviation(notes) <= fix_deviation) return wrapped;
  } catch (const TimeLimitExceeded&) {
    throw;
  } catch (const InputError& wrap_error) {
    if (!fixed_too_far)
      throw InputError(file, std::string(wrap_error.what()) +
                                 " (--repair auto: the wrap, after fix left: " + fix_error + ")");
  }
  // The wrap failed or moved the surface further than fix did: fix's surface after all, unless
  // it does not mesh and the wrap did.
  const TetrahedralizeNotes wrap_notes = notes;
  notes = fix_notes;
  try {
    return validate_and_mesh(fixed, meshing, file, notes, watchdog);
  } catch (const TimeLimitExceeded&) {
    throw;
  } catch (const InputError&) {
    if (wrapped.tets.empty()) throw;
    notes = wrap_notes;
    return wrapped;
  }
}

TetMesh tetrahedralize_in_place(const TriangleMesh& surface, const MeshingOptions& meshing,
                                const std::string& file, TetrahedralizeNotes* notes) {
  TetrahedralizeNotes local_notes;
  TetrahedralizeNotes& out_notes = notes != nullptr ? *notes : local_notes;
  if (!(meshing.time_limit >= 0.0))
    throw std::invalid_argument("time limit must be zero (none) or a positive number of seconds");
  if (!(meshing.max_deviation >= 1e-4 && meshing.max_deviation <= 1.0))
    throw std::invalid_argument("max deviation must be in [1e-4, 1] (a fraction of the diagonal)");
  detail::Watchdog watchdog(meshing.time_limit, meshing.progress, file);
  using Repair = MeshingOptions::Repair;
  const double diagonal = bounding_box_diagonal(surface.vertices);
  TetMesh mesh;
  out_notes.repair_used = meshing.repair;
  if (meshing.repair == Repair::kFix) {
    mesh = validate_and_mesh(fixed_surface(surface, meshing, file, out_notes, watchdog), meshing,
                             file, out_notes, watchdog);
  } else if (meshing.repair == Repair::kWrap) {
    mesh = wrap_and_mesh(surface, meshing, file, out_notes, watchdog);
  } else if (meshing.repair == Repair::kAuto) {
    mesh = fix_or_wrap(surface, meshing, diagonal, file, out_notes, watchdog);
  } else {
    mesh = validate_and_mesh(surface, meshing, file, out_notes, watchdog);
  }
  watchdog.begin("deviation measurement");
  measure_deviation(surface, mesh, meshing, diagonal, out_notes);
  watchdog.check();
  return mesh;
}

}  // namespace

}  // namespace tetseg::preprocess
