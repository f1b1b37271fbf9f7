// Elementary continuous collision tests: vertex-face and edge-edge, linear trajectories.
//
// Method (docs/ccd.md): bisection in time only. On a time interval T every vector used
// (differences of moving points) is affine in t, so every quantity below is a multilinear form
// of such vectors, i.e. a polynomial in t whose Bernstein coefficients on T are averages of
// the form evaluated at the interval ends. Those coefficients are enclosed with rigorous
// interval arithmetic (ccd_interval.hpp); by the convex-hull property they bound the
// polynomial on T. T is excluded when one necessary condition of contact provably fails on
// all of T: swept boxes disjoint, the coplanarity cubic of one sign, the point (the other
// edge) strictly on the outer side of one edge plane, or (exact contact only) an inside
// condition plus a multiple of the coplanarity cubic negative on T (where the cubic vanishes
// the inside condition is then negative). Unexcluded intervals are split, left first, down to
// options.time_tolerance; a leaf that doubles cannot exclude is examined again in
// double-double arithmetic (and, once that was needed, every interval doubles cannot
// exclude); the first leaf still unexcluded is reported with toi = its start, so every time
// before toi was proved contact-free. Below an interval where every inside condition is
// proven positive only the coplanarity cubic can decide, so its sub-intervals test the cubic
// alone, subdivided from that interval's coefficients (exact contact) or recomputed.
// Exact contact also proves contacts (docs/ccd.md, "Exact contacts at the speed of float"):
// certificates at an end of the step in an axis-aligned plane (ccd_plane.hpp), on intervals
// (inside proven and the cubic changing sign; in a plane, the inside conditions), then a jump
// to the crossing or descents in floating point with rigorous error bounds (ccd_bernstein.hpp);
// a crossing of the cubic goes straight to its root's leaf (ccd_certificates.hpp). The forms
// and their exclusion tests are in ccd_forms.hpp (their products two SIMD lanes at a time,
// bitwise the scalar interval arithmetic); this file holds the two tests, the bisection and the
// batches.

#include <algorithm>
#include <cmath>
#include <type_traits>

#include "ccd_bernstein.hpp"
#include "ccd_certificates.hpp"
#include "ccd_forms.hpp"
#include "ccd_interval.hpp"
#include "ccd_plane.hpp"
#include "orientation_terms.hpp"
#include "tetseg/runtime/ccd.hpp"

namespace tetseg {
namespace {

using namespace ccd_detail;

constexpr int kStackSize = 64;

constexpr double kMinTolerance = 0x1p-50;

bool all_finite(const Vec3d* const* points, int count) noexcept {
  for (int i = 0; i < count; ++i)
    for (double x : *points[i])
      if (!std::isfinite(x)) return false;
  return true;
}

/// How much of a test to run on an interval. kFilter: boxes and the coplanarity cubic (the
/// cheap pre-filter). kFull: every exclusion test. kCoplanarOnly: boxes and the coplanarity
/// cubic, for an interval inside one where every inside condition was proven positive (the
/// point strictly inside the edge planes, the closest-point parameters of both edges strictly
/// inside (0,1)): there the other tests cannot exclude anything (their conditions are proven
/// false), and contact happens exactly where the cubic vanishes. Any subset of the tests is
/// sound (each is a necessary condition of contact); this one only drops useless work.
/// kOpenCondition (exact contact, four points in one plane): below an interval certified with
/// one inside condition open, that condition alone decides (subdivided, never recomputed).
/// kCubicFirst (exact contact): below an interval where the coplanarity cubic changes sign,
/// the subdivided cubic excludes sub-intervals, and a sub-interval it cannot exclude is given
/// the full check only once the cubic no longer changes sign on it or it is a leaf (the
/// crossing is isolated first; the inside conditions are then tested once, near it).
/// kLeaf (exact contact): the leaf holding the only root of the coplanarity cubic on an
/// interval (root_leaf): kFull, unless a coarser enclosure of the inside conditions over the
/// whole leaf decides it first (LeafConditions).
enum class Depth { kFilter, kFull, kCoplanarOnly, kOpenCondition, kCubicFirst, kLeaf };

/// The four points of a query at the ends of the time interval [ta, tb]: x[i][0] at ta,
/// x[i][1] at tb.
template <class I>
void positions_at(const Vec3d* const x0[4], const Vec3d* const x1[4], double ta, double tb,
                  Vec<I> (&x)[4][2]) noexcept {
  for (int i = 0; i < 4; ++i) {
    x[i][0] = position<I>(*x0[i], *x1[i], ta);
    x[i][1] = ta == tb ? x[i][0] : position<I>(*x0[i], *x1[i], tb);
  }
}

/// Vertex p against triangle abc. Points: 0 = p, 1 = a, 2 = b, 3 = c.
struct VertexFaceTest {
  const Vec3d* x0[4];
  const Vec3d* x1[4];
  Separation sep;
  /// The axis orthogonal to a plane the four points stay in for the whole step, or -1.
  int plane_axis = axis_plane(x0, x1);

  /// `leaf` > 0 (exact contact, doubles): a crossing of the coplanarity cubic goes to its
  /// root's leaf of that width (crossing_leaf) before the inside conditions are computed.
  template <class I>
  IntervalOutcome check(double ta, double tb, Depth depth, Sums<I, 3>* coplanarity = nullptr,
                        Sums<I, 4>* open_condition = nullptr, double leaf = 0.0) const noexcept {
    Vec<I> x[4][2];
    positions_at<I>(x0, x1, ta, tb, x);
    if (boxes_disjoint<I>(x, 1, x + 1, 3, sep)) return {true, false};

    const Slot<I> u = difference(x[2], x[1]);  // b - a
    const Slot<I> v = difference(x[3], x[1]);  // c - a
    const Slot<I> w = difference(x[0], x[1]);  // p - a
    const double n2 = sep.zero() ? 0.0 : cross_norm2_upper(u, v);
    const CrossSums<I> n = cross_sums(u, v);
    const Sums<I, 3> f = trilinear(n, w);
    if (coplanarity != nullptr) *coplanarity = f;
    if (away_from_zero(f, sep, n2)) return {true, false};
    if (depth != Depth::kFull) return {false, depth == Depth::kCoplanarOnly};
    if constexpr (std::is_same_v<I, Iv>) {
      if (leaf > 0.0) {
        const IntervalOutcome jump = crossing_leaf(f, ta, tb, leaf);
        if (jump.to_leaf) return jump;
      }
    }

    const Slot<I> cb = difference(x[3], x[2]);
    const Slot<I> pb = difference(x[0], x[2]);
    const Slot<I> ac = difference(x[1], x[3]);
    const Slot<I> pc = difference(x[0], x[3]);

    // In an axis-aligned plane for the whole step (exact contact): p is in the closed
    // triangle only if no two of its 2D orientations against the edges have strictly
    // opposite signs (inside a proper triangle they share the triangle's sign; on a
    // degenerate one, a segment or a point, they all vanish). This also excludes the times
    // when the triangle degenerates, where the edge-plane conditions below all vanish.
    if (plane_axis >= 0 && sep.zero() &&
        opposite_signs(cross2(u, w, plane_axis), cross2(cb, pb, plane_axis),
                       cross2(ac, pc, plane_axis)))
      return {true, false};

    // Edge planes (through an edge, perpendicular to the triangle): inside needs
    // n . ((b-a) x (p-a)) >= 0 and the two others.
    const Sums<I, 4> e_ab = quadrilinear(n, cross_sums(u, w));
    if (outside(e_ab, f, sep, sep.zero() ? 0.0 : mul_up(n2, norm2_upper(u)))) return {true, false};
    const Sums<I, 4> e_bc = quadrilinear(n, cross_sums(cb, pb));
    if (outside(e_bc, f, sep, sep.zero() ? 0.0 : mul_up(n2, norm2_upper(cb)))) return {true, false};
    const Sums<I, 4> e_ca = quadrilinear(n, cross_sums(ac, pc));
    if (outside(e_ca, f, sep, sep.zero() ? 0.0 : mul_up(n2, norm2_upper(ac)))) return {true, false};
    const bool inside = positive(e_ab) && positive(e_bc) && positive(e_ca);
    if (!sep.zero()) return {false, inside};
    const Sums<I, 4>* const conditions[3] = {&e_ab, &e_bc, &e_ca};
    return certify<I, 3>(f, conditions, plane_axis >= 0, inside, open_condition);
  }

  /// Contact at t = 0 (at_end false) or t = 1 (true) when the four points are then in one
  /// axis-aligned plane (ccd_plane.hpp); unknown otherwise.
  PlaneContact contact_at(bool at_end) const noexcept {
    const Vec3d* const* x = at_end ? x1 : x0;
    const int axis = shared_axis(x);
    return axis < 0 ? PlaneContact::kUnknown : vertex_triangle_2d(*x[0], *x[1], *x[2], *x[3], axis);
  }

  /// A crossing's leaf [ta, tb] decided from one enclosure of each edge-plane condition over
  /// it, in turn (LeafConditions): n . ((b-a) x (p-a)), n . ((c-b) x (p-b)), n . ((a-c) x (p-c))
  /// with n = (b-a) x (c-a). Not tried in an axis plane (they vanish with the triangle's area).
  LeafOutcome leaf(double ta, double tb) const noexcept {
    if (plane_axis >= 0) return LeafOutcome::kUndecided;
    const Iv t = hull(exact(ta), exact(tb));
    // The differences, cross and dot products two at a time (bitwise the scalar ones).
    auto d2 = [&](int i, int j, int k, int l, IvVec& a, IvVec& b) {
      difference_over2(*x0[i], *x1[i], *x0[j], *x1[j], *x0[k], *x1[k], *x0[l], *x1[l], t, a, b);
    };
    IvVec u, v, p1, cb, p2, ac, n, w;
    d2(2, 1, 3, 1, u, v);
    d2(0, 1, 3, 2, p1, cb);
    cross2(u, v, u, p1, n, w);
    LeafConditions c;
    if (c.apart(dot(n, w))) return LeafOutcome::kApart;
    d2(0, 2, 1, 3, p2, ac);
    IvVec w_bc, w_ca;
    cross2(cb, p2, ac, difference_over(*x0[0], *x1[0], *x0[3], *x1[3], t), w_bc, w_ca);
    Iv e_bc, e_ca;
    dot2(n, w_bc, n, w_ca, e_bc, e_ca);
    if (c.apart(e_bc) || c.apart(e_ca)) return LeafOutcome::kApart;
    return c.outcome();
  }

  /// The points of the coplanarity cubic on [0, 1] in doubles (orientation_detail::cubic's o,
  /// a, b, c at both ends): det[p-a, b-a, c-a] = det[b-a, c-a, p-a].
  void step_cubic_points(const double* (&q)[8]) const noexcept {
    constexpr int kOrder[4] = {1, 0, 2, 3};
    for (int j = 0; j < 4; ++j) {
      q[j] = x0[kOrder[j]]->data();
      q[4 + j] = x1[kOrder[j]]->data();
    }
  }
};

/// Edge ab against edge cd. Points: 0 = a, 1 = b, 2 = c, 3 = d.
struct EdgeEdgeTest {
  const Vec3d* x0[4];
  const Vec3d* x1[4];
  Separation sep;
  /// The axis orthogonal to a plane the four points stay in for the whole step, or -1.
  int plane_axis = axis_plane(x0, x1);

  /// `leaf` > 0 (exact contact, doubles): a crossing of the coplanarity cubic goes to its
  /// root's leaf of that width (crossing_leaf) before the inside conditions are computed.
  template <class I>
  IntervalOutcome check(double ta, double tb, Depth depth, Sums<I, 3>* coplanarity = nullptr,
                        Sums<I, 4>* open_condition = nullptr, double leaf = 0.0) const noexcept {
    Vec<I> x[4][2];
    positions_at<I>(x0, x1, ta, tb, x);
    if (boxes_disjoint<I>(x, 2, x + 2, 2, sep)) return {true, false};

    const Slot<I> ba = difference(x[1], x[0]);
    const Slot<I> dc = difference(x[3], x[2]);
    const Slot<I> ca = difference(x[2], x[0]);
    const double n2 = sep.zero() ? 0.0 : cross_norm2_upper(ba, dc);
    const CrossSums<I> n = cross_sums(ba, dc);
    const Sums<I, 3> f = trilinear(n, ca);
    if (coplanarity != nullptr) *coplanarity = f;
    if (away_from_zero(f, sep, n2)) return {true, false};
    if (depth != Depth::kFull) return {false, depth == Depth::kCoplanarOnly};
    if constexpr (std::is_same_v<I, Iv>) {
      if (leaf > 0.0) {
        const IntervalOutcome jump = crossing_leaf(f, ta, tb, leaf);
        if (jump.to_leaf) return jump;
      }
    }

    // Planes through one edge containing the common normal n = (b-a) x (d-c): the other edge
    // strictly beyond one of them (by delta) cannot touch. With N = |n|^2:
    // h1 = ((c-a) x (d-c)).n, h2 = ((b-c) x (d-c)).n, h1 + h2 = N (closest point on ab at
    // u = h1/N in [0,1]); h3 = ((c-a) x (b-a)).n, h4 = ((b-a) x (d-a)).n, h3 + h4 = N.
    const double dc2 = sep.zero() ? 0.0 : mul_up(n2, norm2_upper(dc));
    const CrossSums<I> left1 = cross_sums(ca, dc);
    const Sums<I, 4> h1 = quadrilinear(left1, n);
    if (outside(h1, f, sep, dc2)) return {true, false};
    const Slot<I> bc = difference(x[1], x[2]);
    const CrossSums<I> left2 = cross_sums(bc, dc);
    const Sums<I, 4> h2 = quadrilinear(left2, n);
    if (outside(h2, f, sep, dc2)) return {true, false};
    const double ba2 = sep.zero() ? 0.0 : mul_up(n2, norm2_upper(ba));
    const CrossSums<I> left3 = cross_sums(ca, ba);
    const Sums<I, 4> h3 = quadrilinear(left3, n);
    if (outside(h3, f, sep, ba2)) return {true, false};
    const Slot<I> da = difference(x[3], x[0]);
    const CrossSums<I> left4 = cross_sums(ba, da);
    const Sums<I, 4> h4 = quadrilinear(left4, n);
    if (outside(h4, f, sep, ba2)) return {true, false};

    // Planes containing one edge and turned towards an endpoint of the other (decide parallel
    // and coplanar edges, where n vanishes): m = (b-a) x ((b-a) x (c-a)) puts c at
    // (c-a).m = -|(b-a) x (c-a)|^2 <= 0; if d is strictly on that side too,
    // (d-a).m = ((d-a) x (b-a)).((b-a) x (c-a)) < 0, the plane separates the edges. With a
    // separation: c's distance to line ab, |(b-a) x (c-a)| / |b-a|, and d's, |(d-a).m| / |m|,
    // must both exceed delta. Same with the roles of the edges swapped.
    // (d-a) x (b-a) = left4 negated and (b-a) x (c-a) = left3 negated; (b-c) x (d-c) = left2
    // and (d-c) x (a-c) = left1.
    const Slot<I> ac = difference(x[0], x[2]);
    if (separated_by_edge_plane(left4, left3, ba, ca) ||
        separated_by_edge_plane(left2, left1, dc, ac))
      return {true, false};

    // Both closest-point parameters strictly inside (0,1) on all of T (then |n| > 0): the
    // edges touch exactly where the coplanarity cubic vanishes.
    const bool inside = positive(h1) && positive(h2) && positive(h3) && positive(h4);
    // End caps (decide parallel edges): both points of one edge beyond the plane through an
    // endpoint of the other, perpendicular to it. None can hold where `inside` is proven: then
    // the point q of segment cd closest to line ab (v = h3 / N in (0,1)) projects onto ab at
    // u = h1 / N in (0,1), (q - a).(b - a) = u |b - a|^2, while the cap at a (b) puts c and d,
    // so q, strictly before a (beyond b); the same for the caps at c and d. So they are only
    // evaluated when `inside` is not proven (the outcome is the same, with less work).
    if (!inside) {
      const Slot<I> ab = difference(x[0], x[1]);
      const Slot<I> cd = difference(x[2], x[3]);
      const double ab2 = sep.zero() ? 0.0 : norm2_upper(ab);
      const double cd2 = sep.zero() ? 0.0 : norm2_upper(cd);
      const Slot<I> bd = difference(x[1], x[3]);
      // cap at a: (c-a).(a-b) > delta |a-b| and (d-a).(a-b) > delta |a-b|.
      if (above_delta(bilinear(ca, ab), sep, ab2) && above_delta(bilinear(da, ab), sep, ab2))
        return {true, false};
      // cap at b: (c-b).(b-a), (d-b).(b-a), i.e. (b-c).(a-b), (b-d).(a-b).
      if (above_delta(bilinear(bc, ab), sep, ab2) && above_delta(bilinear(bd, ab), sep, ab2))
        return {true, false};
      // cap at c: (a-c).(c-d), (b-c).(c-d).
      if (above_delta(bilinear(ac, cd), sep, cd2) && above_delta(bilinear(bc, cd), sep, cd2))
        return {true, false};
      // cap at d: (a-d).(d-c), (b-d).(d-c), i.e. (d-a).(c-d), (d-b).(c-d).
      if (above_delta(bilinear(da, cd), sep, cd2) &&
          above_delta(bilinear(difference(x[3], x[1]), cd), sep, cd2))
        return {true, false};
    }
    if (!sep.zero()) return {false, inside};
    const Sums<I, 4>* const conditions[4] = {&h1, &h2, &h3, &h4};
    return certify<I, 4>(f, conditions, plane_axis >= 0, inside, open_condition);
  }

  /// Plane through the edge with direction e (from point o), normal e x (e x (near - o)):
  /// true when far - o and near - o are both strictly (by delta) on the near side.
  /// far_e = (far - o) x e and e_near = e x (near - o), or both negated.
  template <class I>
  bool separated_by_edge_plane(const CrossSums<I>& far_e, const CrossSums<I>& e_near,
                               const Slot<I>& e, const Slot<I>& near_o) const noexcept {
    if (sep.zero()) return quadrilinear_negative(far_e, e_near);
    const Sums<I, 4> far_side = quadrilinear(far_e, e_near);
    const Range far_range = value_range(far_side);
    if (!(far_range.hi < 0.0)) return false;
    const double e2 = norm2_upper(e);
    const Range near2 = value_range(quadrilinear(e_near, e_near));  // |e x (near-o)|^2
    if (!(near2.lo > 0.0) || !(mul_down(near2.lo, 1.0) > mul_up(sep.delta2, e2))) return false;
    return mul_down(far_range.hi, far_range.hi) >
           mul_up(sep.delta2, mul_up(e2, cross_norm2_upper(e, near_o)));
  }

  /// Contact at t = 0 (at_end false) or t = 1 (true) when the four points are then in one
  /// axis-aligned plane (ccd_plane.hpp); unknown otherwise.
  PlaneContact contact_at(bool at_end) const noexcept {
    const Vec3d* const* x = at_end ? x1 : x0;
    const int axis = shared_axis(x);
    return axis < 0 ? PlaneContact::kUnknown : segments_2d(*x[0], *x[1], *x[2], *x[3], axis);
  }

  /// A crossing's leaf [ta, tb] decided from one enclosure of each of h1..h4 (check) over it
  /// in turn (LeafConditions): ((c-a) x (d-c)).n, ((b-c) x (d-c)).n, ((c-a) x (b-a)).n,
  /// ((b-a) x (d-a)).n with n = (b-a) x (d-c). Not tried in an axis plane (n vanishes there).
  LeafOutcome leaf(double ta, double tb) const noexcept {
    if (plane_axis >= 0) return LeafOutcome::kUndecided;
    const Iv t = hull(exact(ta), exact(tb));
    // The differences, cross and dot products two at a time (bitwise the scalar ones).
    auto d2 = [&](int i, int j, int k, int l, IvVec& a, IvVec& b) {
      difference_over2(*x0[i], *x1[i], *x0[j], *x1[j], *x0[k], *x1[k], *x0[l], *x1[l], t, a, b);
    };
    IvVec ba, dc, ca, bc, n, w1;
    d2(1, 0, 3, 2, ba, dc);
    d2(2, 0, 1, 2, ca, bc);
    cross2(ba, dc, ca, dc, n, w1);
    LeafConditions c;
    if (c.apart(dot(w1, n))) return LeafOutcome::kApart;
    IvVec w2, w3;
    cross2(bc, dc, ca, ba, w2, w3);
    Iv h2, h3;
    dot2(w2, n, w3, n, h2, h3);
    if (c.apart(h2) || c.apart(h3) ||
        c.apart(dot(cross(ba, difference_over(*x0[3], *x1[3], *x0[0], *x1[0], t)), n)))
      return LeafOutcome::kApart;
    return c.outcome();
  }

  /// The points of the coplanarity cubic on [0, 1] in doubles (orientation_detail::cubic's o,
  /// a, b, c at both ends): det[b-a, d-a, c-a] = det[b-a, d-c, c-a].
  void step_cubic_points(const double* (&q)[8]) const noexcept {
    constexpr int kOrder[4] = {0, 1, 3, 2};
    for (int j = 0; j < 4; ++j) {
      q[j] = x0[kOrder[j]]->data();
      q[4 + j] = x1[kOrder[j]]->data();
    }
  }
};

double clamp_tolerance(double tol) noexcept {
  if (!(tol > kMinTolerance)) return kMinTolerance;  // also NaN
  return min_nan(tol, 1.0);
}

struct Item {
  double ta, tb;
  /// kFull, or kCoplanarOnly inside an interval with the inside proven. Exact contact only:
  /// then `poly` holds the coplanarity cubic's coefficients on [ta, tb], subdivided from the
  /// interval where the inside was proven, and the test is its sign (no recomputation); or,
  /// kOpenCondition, the open inside condition of an interval certified in the plane
  /// (contact exactly where it is >= 0); or, kCubicFirst, and kFull below an interval checked
  /// (exact contact), the coplanarity cubic subdivided from it, which excludes the interval
  /// when of one sign (degree 0: none).
  Depth depth;
  FloatBernstein poly;
};

/// The coplanarity cubic of the whole step in doubles (orientation_detail::cubic of the test's
/// step_cubic_points).
template <class Test>
BernsteinCubic step_cubic_terms(const Test& test) noexcept {
  const double* q[8];
  test.step_cubic_points(q);
  return orientation_detail::cubic(q[0], q[1], q[2], q[3], q[4], q[5], q[6], q[7]);
}

/// The test; `step_terms`, when given, is step_cubic_terms(test) computed by the caller (a
/// batch, two cubics at a time): bitwise the same result.
template <class Test>
CcdResult run_bisection(const Test& test, const CcdOptions& options,
                        const BernsteinCubic* step_terms = nullptr) noexcept {
  CcdResult result;
  if (!all_finite(test.x0, 4) || !all_finite(test.x1, 4)) {
    result.outcome = CcdOutcome::kContact;
    result.toi = 0.0;
    return result;
  }
  const bool exact_contact = test.sep.zero();
  // The start t = 0 is tested once the whole step could not be excluded: a step excluded as
  // a whole has no contact at t = 0 either, and most queries end there.
  bool start_tested = false;
  const double tol = clamp_tolerance(options.time_tolerance);
  const std::uint32_t max_intervals = std::max<std::uint32_t>(options.max_intervals, 1);
  Item stack[kStackSize];
  int top = 0;
  stack[top++] = {0.0, 1.0, Depth::kFull, {}};
  // Once a leaf has needed double-double to be excluded, the query is near-degenerate (the
  // primitives graze within rounding of doubles): from then on double-double is tried on
  // every interval doubles cannot exclude, before splitting it.
  bool near_degenerate = false;
  // A contact certainly exists in an interval examined so far (exact contact only). Every
  // interval examined later starts before that contact (everything before an examined
  // interval was proved contact-free), so the first leaf doubles cannot exclude is reported
  // as it is: the double-double stage would only move toi later, never decide the hit.
  bool certified = false;
  auto report = [&](CcdOutcome outcome, double toi) {
    result.outcome = outcome;
    result.toi = toi;
    return result;
  };
  // Plane certificates (exact contact): when the four points start (end) in one axis-aligned
  // plane, contact there is a 2D question (ccd_plane.hpp), and the coplanarity cubic vanishes
  // there. Touching at t = 0 is kContactAtStart at once. Otherwise, if the cubic has no other
  // root in [0, 1] (f = (1 - t) g or t g, g of one sign), contact can only happen at that end:
  // touching at t = 1 is the first contact, reported at the start of the bisection's last
  // leaf (what the bisection reports when the rest of the step is excluded); apart, there is
  // none. Only the boxes and the cubic are computed.
  const PlaneContact at_start = exact_contact ? test.contact_at(false) : PlaneContact::kUnknown;
  if (at_start == PlaneContact::kTouching) {
    result.intervals = 1;
    return report(CcdOutcome::kContactAtStart, 0.0);
  }
  const PlaneContact at_end = exact_contact ? test.contact_at(true) : PlaneContact::kUnknown;
  if (at_start != PlaneContact::kUnknown || at_end != PlaneContact::kUnknown) {
    Sums<Iv, 3> f{};
    result.intervals = 1;
    if (test.template check<Iv>(0.0, 1.0, Depth::kFilter, &f).excluded) return result;
    if (at_end != PlaneContact::kUnknown && nonzero_before_end(f))
      return at_end == PlaneContact::kTouching ? report(CcdOutcome::kContact, last_leaf_start(tol))
                                               : result;
    if (at_start == PlaneContact::kApart && nonzero_after_start(f)) return result;
  }
  const bool contact_at_end = at_end == PlaneContact::kTouching;
  // The whole step in plain doubles first (exact contact): the coplanarity cubic with a
  // rigorous error bound (step_cubic). Of one sign (on [0, 1] or on every piece of a few
  // halvings), there is no contact; changing sign with its only root in one leaf (root_leaf),
  // that leaf is all there is to check, as the interval check of [0, 1] would decide
  // (crossing_leaf) at a fraction of its cost. Otherwise, proven nonzero at t = 0 (no contact
  // there), its halves are examined as below an interval where the cubic changes sign
  // (kCubicFirst: excluded by its sign, or straight to a root's leaf, or checked in full). Only
  // when even that fails does the interval check of [0, 1] run as before.
  if (exact_contact) {
    const FloatBernstein cubic =
        step_cubic(step_terms != nullptr ? *step_terms : step_cubic_terms(test));
    if (proven_positive(cubic) || proven_negative(cubic) || one_signed_by_halving(cubic, 3)) {
      result.intervals = 1;
      return result;
    }
    double lo = 0.0, hi = 0.0;
    if (proven_sign_change(cubic) && root_leaf(cubic, 0.0, 1.0, leaf_width(1.0, tol), lo, hi)) {
      result.intervals = 1;  // [0, 1]: the cubic is nonzero at t = 0, no contact there
      start_tested = true;
      certified = contact_at_end;
      top = 0;
      stack[top++] = {lo, hi, Depth::kLeaf, {}};
    } else if (std::fabs(cubic.c[0]) > cubic.err) {
      result.intervals = 1;
      start_tested = true;
      certified = contact_at_end;
      top = 0;
      FloatBernstein left{}, right{};
      split_half(cubic, left, right);
      stack[top++] = {0.5, 1.0, Depth::kCubicFirst, right};
      stack[top++] = {0.0, 0.5, Depth::kCubicFirst, left};
    }
  }
  while (top > 0) {
    const Item item = stack[--top];
    ++result.intervals;
    const double tm = 0.5 * item.ta + 0.5 * item.tb;
    const bool leaf = item.tb - item.ta <= tol || result.intervals >= max_intervals ||
                      top + 2 > kStackSize || !(tm > item.ta && tm < item.tb);
    Sums<Iv, 3> f{};
    Sums<Iv, 4> open{};
    IntervalOutcome outcome{};
    bool checked = false;  // outcome from the interval check on [ta, tb]
    LeafOutcome leaf_decision = LeafOutcome::kUndecided;
    // The check this interval gets when it is not decided by a subdivided polynomial alone,
    // and the one the double-double stage repeats.
    const Depth depth = item.depth == Depth::kCoplanarOnly ? Depth::kCoplanarOnly : Depth::kFull;
    if (item.depth == Depth::kOpenCondition) {  // certified parent: contact where poly >= 0
      outcome.excluded = proven_negative(item.poly);
      outcome.certified = outcome.open_condition = true;
      outcome.contact_at_start = start_positive(item.poly);
    } else if (exact_contact && item.depth == Depth::kCoplanarOnly) {  // contact where poly = 0
      outcome.excluded = proven_positive(item.poly) || proven_negative(item.poly);
      outcome.inside = true;
      outcome.certified = proven_sign_change(item.poly);
    } else if ((item.depth == Depth::kCubicFirst || item.poly.degree == 3) &&
               (proven_positive(item.poly) || proven_negative(item.poly))) {
      outcome.excluded = true;
    } else if (item.depth == Depth::kCubicFirst && !leaf && proven_sign_change(item.poly)) {
      // The leaf holding the cubic's only root, checked in full as the bisection would
      // (everything else in [ta, tb] is proven contact-free); else one halving.
      double lo = 0.0, hi = 0.0;
      if (root_leaf(item.poly, item.ta, item.tb, leaf_width(item.tb - item.ta, tol), lo, hi)) {
        ++result.intervals;  // the rest of [ta, tb], excluded
        stack[top++] = {lo, hi, Depth::kLeaf, {}};
        continue;
      }
      FloatBernstein left{}, right{};
      split_half(item.poly, left, right);
      stack[top++] = {tm, item.tb, Depth::kCubicFirst, right};
      stack[top++] = {item.ta, tm, Depth::kCubicFirst, left};
      continue;
    } else if (item.depth == Depth::kLeaf &&
               (leaf_decision = test.leaf(item.ta, item.tb)) != LeafOutcome::kUndecided) {
      // The coplanarity cubic has a root in the leaf (root_leaf proved it of opposite signs
      // before and after): with the inside proven there, that root is a contact, and
      // everything before the leaf is contact-free.
      if (leaf_decision == LeafOutcome::kContact) return report(CcdOutcome::kContact, item.ta);
      outcome.excluded = true;
    } else {
      // The whole step first (exact contact): a crossing goes straight to its root's leaf.
      const double jump_width = exact_contact && !start_tested ? leaf_width(1.0, tol) : 0.0;
      outcome = test.template check<Iv>(item.ta, item.tb, depth, &f, &open, jump_width);
      checked = true;
    }
    if (outcome.to_leaf) {
      // The cubic is proven nonzero at t = 0 (it changes sign on [0, 1]): no contact there.
      start_tested = true;
      certified = contact_at_end;
      stack[top++] = {outcome.leaf_lo, outcome.leaf_hi, Depth::kLeaf, {}};
      continue;
    }
    if (outcome.excluded) continue;
    if (near_degenerate && !certified && test.template check<Dd>(item.ta, item.tb, depth).excluded)
      continue;
    if (!start_tested) {  // item is [0, 1] and f its coplanarity cubic
      start_tested = true;
      ++result.intervals;
      if (outcome.contact_at_start) return report(CcdOutcome::kContactAtStart, 0.0);
      // Exact contact at t = 0 needs the coplanarity cubic to vanish there; its first sum is
      // its value at t = 0: proven nonzero, the start has no contact (the start check would
      // exclude it on the cubic too).
      const bool start_excluded = exact_contact && (lower(f.s[0]) > 0.0 || upper(f.s[0]) < 0.0);
      if (!start_excluded && !test.template check<Iv>(0.0, 0.0, Depth::kFull).excluded &&
          !(exact_contact && test.template check<Dd>(0.0, 0.0, Depth::kFull).excluded))
        return report(CcdOutcome::kContactAtStart, 0.0);
      certified = contact_at_end;  // a contact at t = 1, after every interval examined
    }
    // The start of the interval is a contact and everything before it is contact-free.
    if (outcome.contact_at_start)
      return report(item.ta == 0.0 ? CcdOutcome::kContactAtStart : CcdOutcome::kContact, item.ta);
    certified = certified || outcome.certified;
    // A certified crossing jumps to its time of impact: of the coplanarity cubic below a
    // proven inside, or of the open inside condition in a plane (contact where it is >= 0;
    // it starts negative here, else contact_at_start) when it changes sign on the interval.
    if (exact_contact && outcome.certified && (outcome.inside || outcome.open_condition)) {
      const FloatBernstein p = !checked                 ? item.poly
                               : outcome.open_condition ? float_bernstein(open)
                                                        : float_bernstein(f);
      if (outcome.inside || proven_sign_change(p)) {
        const double toi = certified_crossing_time(p, item.ta, item.tb, tol);
        if (toi >= 0.0) return report(CcdOutcome::kContact, toi);
      }
    }
    if (leaf) {
      if (exact_contact && !near_degenerate && !certified && result.intervals < max_intervals &&
          test.template check<Dd>(item.ta, item.tb, depth).excluded) {
        near_degenerate = true;
        continue;
      }
      return report(CcdOutcome::kContact, item.ta);
    }
    // Children, exact contact: the open condition of an interval certified in the plane, the
    // coplanarity cubic below an interval with the inside proven or where it changes sign,
    // subdivided; else (and with a minimum separation) the check again.
    Depth child = Depth::kFull;
    FloatBernstein left{}, right{};
    if (outcome.open_condition) {
      child = Depth::kOpenCondition;
      split_half(checked ? float_bernstein(open) : item.poly, left, right);
    } else if (outcome.inside) {
      child = Depth::kCoplanarOnly;
      if (exact_contact) split_half(checked ? float_bernstein(f) : item.poly, left, right);
    } else if (exact_contact && checked) {  // the cubic, subdivided, as a pre-filter
      child = sign_change(f) ? Depth::kCubicFirst : Depth::kFull;
      split_half(float_bernstein(f), left, right);
    }
    stack[top++] = {tm, item.tb, child, right};
    stack[top++] = {item.ta, tm, child, left};
  }
  return result;
}

/// The cheap interval filter over the whole step: false only when contact is excluded.
/// Non-finite input may hit.
template <typename Test>
bool filter_may_hit(const Test& test) noexcept {
  if (!all_finite(test.x0, 4) || !all_finite(test.x1, 4)) return true;
  return !test.template check<Iv>(0.0, 1.0, Depth::kFilter).excluded;
}

template <class Test>
Test test_of(const CcdQuery& q, const CcdOptions& options) noexcept {
  return Test{{&q.x0[0], &q.x0[1], &q.x0[2], &q.x0[3]},
              {&q.x1[0], &q.x1[1], &q.x1[2], &q.x1[3]},
              Separation(options.min_separation)};
}

/// run_bisection on each query; with exact contact the whole step's coplanarity cubics are
/// computed two queries at a time (orientation_detail::cubic2, bitwise the scalar cubic), the
/// rest of each test as one query (the cubic's stages decide most non-contacts at once).
template <class Test>
void run_batch(const CcdQuery* queries, std::size_t count, CcdResult* results,
               const CcdOptions& options) noexcept {
  std::size_t i = 0;
  if (Separation(options.min_separation).zero()) {
    for (; i + 2 <= count; i += 2) {
      const Test tests[2] = {test_of<Test>(queries[i], options),
                             test_of<Test>(queries[i + 1], options)};
      const double* points[2][8];
      tests[0].step_cubic_points(points[0]);
      tests[1].step_cubic_points(points[1]);
      BernsteinCubic terms[2];
      orientation_detail::cubic2(points, terms);
      results[i] = run_bisection(tests[0], options, &terms[0]);
      results[i + 1] = run_bisection(tests[1], options, &terms[1]);
    }
  }
  for (; i < count; ++i) results[i] = run_bisection(test_of<Test>(queries[i], options), options);
}

}  // namespace

void vertex_face_ccd_batch(const CcdQuery* queries, std::size_t count, CcdResult* results,
                           const CcdOptions& options) noexcept {
  run_batch<VertexFaceTest>(queries, count, results, options);
}

void edge_edge_ccd_batch(const CcdQuery* queries, std::size_t count, CcdResult* results,
                         const CcdOptions& options) noexcept {
  run_batch<EdgeEdgeTest>(queries, count, results, options);
}

CcdResult vertex_face_ccd(const Vec3d& p0, const Vec3d& a0, const Vec3d& b0, const Vec3d& c0,
                          const Vec3d& p1, const Vec3d& a1, const Vec3d& b1, const Vec3d& c1,
                          const CcdOptions& options) noexcept {
  const VertexFaceTest test{
      {&p0, &a0, &b0, &c0}, {&p1, &a1, &b1, &c1}, Separation(options.min_separation)};
  return run_bisection(test, options);
}

CcdResult edge_edge_ccd(const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0,
                        const Vec3d& a1, const Vec3d& b1, const Vec3d& c1, const Vec3d& d1,
                        const CcdOptions& options) noexcept {
  const EdgeEdgeTest test{
      {&a0, &b0, &c0, &d0}, {&a1, &b1, &c1, &d1}, Separation(options.min_separation)};
  return run_bisection(test, options);
}

bool vertex_face_ccd_filter(const Vec3d& p0, const Vec3d& a0, const Vec3d& b0, const Vec3d& c0,
                            const Vec3d& p1, const Vec3d& a1, const Vec3d& b1, const Vec3d& c1,
                            const CcdOptions& options) noexcept {
  const VertexFaceTest test{
      {&p0, &a0, &b0, &c0}, {&p1, &a1, &b1, &c1}, Separation(options.min_separation)};
  return filter_may_hit(test);
}

bool edge_edge_ccd_filter(const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0,
                          const Vec3d& a1, const Vec3d& b1, const Vec3d& c1, const Vec3d& d1,
                          const CcdOptions& options) noexcept {
  const EdgeEdgeTest test{
      {&a0, &b0, &c0, &d0}, {&a1, &b1, &c1, &d1}, Separation(options.min_separation)};
  return filter_may_hit(test);
}

}  // namespace tetseg
