#pragma once
/// \file
/// Elementary continuous collision tests between two primitives that move linearly over a
/// step t in [0,1]: x(t) = (1-t) x0 + t x1 (assumes linear trajectories).
///
/// Guarantees (docs/ccd.md): conservative in floating point. Every decision "no contact" is
/// proved with rigorous interval arithmetic (round-to-nearest with outward error bounds on
/// every operation; doubles first, double-double where doubles cannot decide), so a contact
/// that exact arithmetic finds is never missed, and the
/// reported time of impact is a lower bound of the true first contact time. "Contact" may be
/// reported for primitives that only come within the resolution of the bisection (false
/// positive); never the converse. Degenerate input (coplanar for the whole step, zero motion,
/// parallel edges, degenerate triangles) is handled by the same rule. Non-finite input is
/// reported as a contact (kContact, toi 0): the test never proves separation it cannot see.
///
/// Cost (docs/benchmarks.md): well-separated pairs exit after one interval (about 0.1-0.2 us);
/// real contacts, degenerate ones included (touching at an end or sliding in an axis-aligned
/// plane), are proven by positive certificates and float descents with rigorous error bounds
/// (docs/ccd.md), about 0.4-3 us; near-degenerate pairs are bounded by max_intervals.
/// Thread safety: every function is reentrant (no global state). No allocation, no
/// exceptions. The floating-point environment must be round-to-nearest (the default).

#include <array>
#include <cstddef>
#include <cstdint>

namespace tetseg {

using Vec3d = std::array<double, 3>;

struct CcdOptions {
  /// Minimum separation in length units, >= 0: a contact is reported when the primitives
  /// come within this distance (the test is conservative for the distance too; near
  /// triangle corners and edge ends it may report up to the prism/slab over-approximation
  /// described in docs/ccd.md). 0 = exact contact. Negative or NaN values are treated as 0.
  double min_separation = 0.0;
  /// Width of the time intervals at which the bisection stops and reports a contact it
  /// could not exclude, in step units (0,1]. Smaller = fewer false positives, more work.
  double time_tolerance = 1e-9;
  /// Maximum number of time intervals examined by one query; when exhausted, a contact is
  /// reported at the earliest unresolved time (conservative).
  std::uint32_t max_intervals = 2048;
};

enum class CcdOutcome : std::uint8_t {
  kNoContact = 0,
  kContact,         ///< possible contact in [toi, 1], none before toi; toi in [0,1]
  kContactAtStart,  ///< touching (within min_separation, up to rounding) at t = 0; toi = 0
};

struct CcdResult {
  CcdOutcome outcome = CcdOutcome::kNoContact;
  /// Lower bound on the first contact time, in [0,1]; valid on contact (1 otherwise).
  double toi = 1.0;
  /// Number of time intervals examined (work measure, for statistics).
  std::uint32_t intervals = 0;
  bool hit() const noexcept { return outcome != CcdOutcome::kNoContact; }
};

/// Vertex p against triangle (a,b,c); suffix 0 = start of step, 1 = end. Contact = p lies
/// in the closed triangle (or within min_separation of it) at some t in [0,1].
CcdResult vertex_face_ccd(const Vec3d& p0, const Vec3d& a0, const Vec3d& b0, const Vec3d& c0,
                          const Vec3d& p1, const Vec3d& a1, const Vec3d& b1, const Vec3d& c1,
                          const CcdOptions& options = {}) noexcept;

/// Edge (a,b) against edge (c,d). Contact = the closed segments intersect (or come within
/// min_separation) at some t in [0,1].
CcdResult edge_edge_ccd(const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0,
                        const Vec3d& a1, const Vec3d& b1, const Vec3d& c1, const Vec3d& d1,
                        const CcdOptions& options = {}) noexcept;

/// One query of a batch: the four points in the argument order of vertex_face_ccd (p, a, b, c)
/// or edge_edge_ccd (a, b, c, d), at the start (x0) and at the end (x1) of the step.
struct CcdQuery {
  Vec3d x0[4];
  Vec3d x1[4];
};

/// vertex_face_ccd on queries[0..count) into results[0..count): bitwise the results of the
/// calls one by one. With exact contact (min_separation 0) the first stage, the coplanarity
/// cubic of the whole step in doubles, is computed for two queries at a time (SIMD lanes);
/// the rest of each test runs as in vertex_face_ccd.
void vertex_face_ccd_batch(const CcdQuery* queries, std::size_t count, CcdResult* results,
                           const CcdOptions& options = {}) noexcept;

/// edge_edge_ccd on a batch, as vertex_face_ccd_batch.
void edge_edge_ccd_batch(const CcdQuery* queries, std::size_t count, CcdResult* results,
                         const CcdOptions& options = {}) noexcept;

/// Cheap conservative pre-filter for vertex_face_ccd (same arguments): false only when a
/// contact over the whole step is impossible (swept boxes disjoint, or the coplanarity cubic
/// provably of one sign on [0,1], with min_separation). true means "run the full test".
bool vertex_face_ccd_filter(const Vec3d& p0, const Vec3d& a0, const Vec3d& b0, const Vec3d& c0,
                            const Vec3d& p1, const Vec3d& a1, const Vec3d& b1, const Vec3d& c1,
                            const CcdOptions& options = {}) noexcept;

/// Cheap conservative pre-filter for edge_edge_ccd (same arguments and meaning).
bool edge_edge_ccd_filter(const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0,
                          const Vec3d& a1, const Vec3d& b1, const Vec3d& c1, const Vec3d& d1,
                          const CcdOptions& options = {}) noexcept;

}  // namespace tetseg
