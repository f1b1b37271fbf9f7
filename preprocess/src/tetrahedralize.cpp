// tetrahedralize: which surface Mesh_3 gets and how far the result moved. --repair fix
// (repair.cpp's soup repairs), wrap (the CGAL alpha wrap, alpha doublings, the slab around a
// sheet), auto (fix, else the wrap, with the reason; hole patches checked against
// --max-deviation), the meshing frame of far or huge surfaces, and the deviation measured
// after every build. Driving Mesh_3 itself is in meshing.cpp (mesh3_driver.hpp).

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "mesh3_driver.hpp"
#include "repair_internal.hpp"
#include "tetseg/preprocess/surface.hpp"
#include "vec3_math.hpp"
#include "watchdog.hpp"

namespace tetseg::preprocess {
namespace {

/// The smallest --wrap-alpha and --wrap-offset, as fractions of the diagonal.
constexpr double kMinWrapFraction = 1e-4;

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
/// With --repair wrap, alpha is doubled at most this many times (see tetrahedralize).
constexpr int kMaxAlphaDoublings = 6;
/// A wrap bridges the gaps and holes narrower than alpha, so its distance from the input grows
/// with alpha (libcgal-demo, docs/benchmarks-history.md: about 0.01-0.04 of the diagonal at
/// alpha 0.02, 0.05-0.08 at 0.08, 0.22-0.32 at 0.32). Alpha is doubled past
/// kAlphaPerDeviation x --max-deviation (or --wrap-alpha when larger) only when the slab
/// (mesh_sheet_slab, within about --wrap-sheet-offset of the input) does not mesh.
constexpr double kAlphaPerDeviation = 2.0;
/// That slab's Mesh_3 runs are each bounded (CPU seconds of the meshing thread,
/// Watchdog::begin_bounded; past it, the doublings): slabs mesh in 1-20 s on libcgal-demo, but
/// b9_mesh.off's ran over 300 s.
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
    if (angle < 2.0 * detail::kPi) ++thin;  // winding number below 1/2: outside
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

/// The slab's alpha is at most this many times --wrap-sheet-offset (and at most --wrap-alpha):
/// where the slab bridges a concave part of the input, its surface lies up to about alpha
/// further out than the offset (libcgal-demo, the default offset 0.01: open_cube.off and
/// patch-01.off 0.022-0.023 from their input at alpha 0.02, 0.016 at 0.01; docs/benchmarks.md).
constexpr double kSlabAlphaPerOffset = 1.0;

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
  const TriangleMesh slab = wrapped_surface(
      surface, std::min(meshing.wrap_alpha, kSlabAlphaPerOffset * meshing.wrap_sheet_offset),
      meshing.wrap_sheet_offset, diagonal, file, watchdog);
  TetMesh mesh;
  try {
    // Retries only when the slab's offset leaves room within --max-deviation.
    mesh =
        detail::validate_and_mesh(slab, meshing, file, notes, watchdog, bound_seconds,
                                  (meshing.max_deviation - meshing.wrap_sheet_offset) * diagonal);
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
  const double diagonal = detail::bounding_box_diagonal(surface.vertices);
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
        // Mesh_3 may move the surface what --max-deviation leaves beside the wrap's own distance
        // from the input; when the wrap alone takes it all (the inner parts of a
        // self-intersecting input, concave parts it bridges), no retry can help: none then.
        watchdog.begin("deviation of the wrap");
        const auto [there, back] = detail::hausdorff_distances(surface, wrap);
        const double wrap_distance = std::max(there, back);
        const double allowed = meshing.max_deviation * diagonal - wrap_distance;
        TetMesh mesh =
            detail::validate_and_mesh(wrap, meshing, file, notes, watchdog, 0.0,
                                      wrap_distance >= 0.0 ? std::max(allowed, 0.0) : 0.0);
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
/// A figure measured before for the same two surfaces (the deviation retries' check when fix
/// changed nothing, auto's check of a wrap) is not measured again: hausdorff_distances keeps it.
void measure_deviation(const TriangleMesh& surface, const TetMesh& mesh,
                       const MeshingOptions& meshing, double diagonal, TetrahedralizeNotes& notes) {
  const TriangleMesh meshed{mesh.nodes, extract_surface(mesh).triangles};
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
  notes.repairs = detail::repair_soup(fixed, meshing.keep_largest_component, patch_area,
                                      detail::kMaxRemovalPatches, watchdog.stop_flag());
  watchdog.check();  // a removal stopped by --time-limit: refused as such
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
      return detail::validate_and_mesh(fixed, meshing, file, notes, watchdog, 0.0,
                                       meshing.max_deviation * diagonal);
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
    return detail::validate_and_mesh(fixed, meshing, file, notes, watchdog, 0.0,
                                     meshing.max_deviation * diagonal);
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
  const double diagonal = detail::bounding_box_diagonal(surface.vertices);
  TetMesh mesh;
  out_notes.repair_used = meshing.repair;
  if (meshing.repair == Repair::kFix) {
    mesh = detail::validate_and_mesh(fixed_surface(surface, meshing, file, out_notes, watchdog),
                                     meshing, file, out_notes, watchdog, 0.0,
                                     meshing.max_deviation * diagonal);
  } else if (meshing.repair == Repair::kWrap) {
    mesh = wrap_and_mesh(surface, meshing, file, out_notes, watchdog);
  } else if (meshing.repair == Repair::kAuto) {
    mesh = fix_or_wrap(surface, meshing, diagonal, file, out_notes, watchdog);
  } else {
    mesh = detail::validate_and_mesh(surface, meshing, file, out_notes, watchdog, 0.0,
                                     meshing.max_deviation * diagonal);
  }
  watchdog.begin("deviation measurement");
  measure_deviation(surface, mesh, meshing, diagonal, out_notes);
  watchdog.check();
  return mesh;
}

}  // namespace

}  // namespace tetseg::preprocess