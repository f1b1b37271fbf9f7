// The FMM product of the fast solver against the exact O(N^2) product of the same collocation
// matrix (point-charge far field plus analytic near field), at two FMM orders and at scales
// far from 1 (docs/charge.md, "fast").

#include <algorithm>
#include <catch2/catch.hpp>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "../../preprocess/src/charge_fmm_kernels.hpp"
#include "../../preprocess/src/charge_potential.hpp"
#include "../../preprocess/src/charge_solvers.hpp"
#include "../../preprocess/src/charge_tree.hpp"
#include "tetseg/preprocess/charge.hpp"
#include "tetseg/testing/charge_shapes.hpp"
#include "tetseg/testing/test_data.hpp"

using namespace tetseg::preprocess::charge_detail;

namespace {

/// Relative 2-norm and max pointwise relative error of the FMM product against the dense
/// one, for a positive smoothly varying charge vector.
std::pair<double, double> fmm_error(const tetseg::preprocess::TriangleMesh& m, double theta,
                                    int order) {
  const PanelSet panels = make_panels(m.vertices, m.triangles, "");
  const std::size_t n = panels.size();
  const ClusterTree tree = build_cluster_tree(panels, 32);
  const NearField near = build_near_field(panels, tree);
  const std::vector<double> dense = assemble_dense(panels, near);
  std::vector<double> x(n), exact(n), fast(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = 1.0 + 0.3 * std::sin(0.37 * static_cast<double>(i));
  dense_apply(dense, n, x.data(), exact.data());
  const TreecodeOperator op(panels, tree, near, theta, order);
  op.apply(x.data(), fast.data());
  double num = 0.0, den = 0.0, worst = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    num += (fast[i] - exact[i]) * (fast[i] - exact[i]);
    den += exact[i] * exact[i];
    worst = std::max(worst, std::abs(fast[i] / exact[i] - 1.0));
  }
  return {std::sqrt(num / den), worst};
}

tetseg::preprocess::TriangleMesh scaled(tetseg::preprocess::TriangleMesh m, double s) {
  for (auto& p : m.vertices) p = {p[0] * s, p[1] * s, p[2] * s};
  return m;
}

/// The relative residual of a computed charge against the exact collocation matrix of its
/// mesh (O(N^2) product): y = density * C / total area against b = 1.
double residual_against_exact(const tetseg::preprocess::TriangleMesh& m,
                              const tetseg::preprocess::ChargeResult& r) {
  const PanelSet panels = make_panels(m.vertices, m.triangles, "");
  const ClusterTree tree = build_cluster_tree(panels, 32);
  const NearField near = build_near_field(panels, tree);
  std::vector<double> y(r.density.size()), b(r.density.size(), 1.0);
  for (std::size_t j = 0; j < y.size(); ++j) y[j] = r.density[j] * r.capacitance / r.total_area;
  return exact_residual(panels, near, b, y);
}

/// A nonsymmetric, diagonally weighted 60 x 60 system for the GMRES tests, with its product,
/// Jacobi preconditioner and true relative residual.
struct DenseSystem {
  static constexpr std::size_t n = 60;
  std::vector<double> a = std::vector<double>(n * n), b = std::vector<double>(n);
  DenseSystem() {
    for (std::size_t i = 0; i < n; ++i) {
      b[i] = 1.0 + 0.5 * std::cos(0.7 * static_cast<double>(i));
      for (std::size_t j = 0; j < n; ++j) {
        a[i * n + j] = (i == j ? 4.0 + 0.1 * static_cast<double>(i % 7) : 0.0) +
                       std::sin(1.3 * static_cast<double>(i) + 0.7 * static_cast<double>(j)) /
                           (1.0 + std::abs(static_cast<double>(i) - static_cast<double>(j)));
      }
    }
  }
  void apply(const double* x, double* y) const { dense_apply(a, n, x, y); }
  void jacobi(const double* x, double* y) const {
    for (std::size_t i = 0; i < n; ++i) y[i] = x[i] / a[i * n + i];
  }
  double true_residual(const std::vector<double>& x) const {
    std::vector<double> ax(n);
    apply(x.data(), ax.data());
    double rr = 0.0, bb = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      rr += (b[i] - ax[i]) * (b[i] - ax[i]);
      bb += b[i] * b[i];
    }
    return std::sqrt(rr / bb);
  }
};

}  // namespace

TEST_CASE("The FMM product matches the exact product of the collocation matrix", "[charge]") {
  const auto m = tetseg::test::ellipsoid(11, 1.0, 0.6, 0.3);  // 2420 triangles
  REQUIRE(m.triangles.size() == 2420);
  SECTION("Order 6 at theta 0.5 is accurate to a few 1e-6 (2-norm).") {
    const auto e = fmm_error(m, 0.5, 6);
    CHECK(e.first < 1e-5);
    CHECK(e.second < 1e-4);
  }
  SECTION("Order 8 is more accurate than order 6, and order 2 much less.") {
    const auto e6 = fmm_error(m, 0.5, 6);
    const auto e8 = fmm_error(m, 0.5, 8);
    const auto e2 = fmm_error(m, 0.5, 2);
    CHECK(e8.first < 0.6 * e6.first);
    CHECK(e2.first > 10.0 * e6.first);
  }
  SECTION("The error does not depend on the length unit (1e-20 and 1e20 scales).") {
    const auto e = fmm_error(m, 0.5, 6);
    for (const double s : {1e-20, 1e20}) {
      const auto es = fmm_error(scaled(m, s), 0.5, 6);
      CHECK(std::abs(es.first - e.first) < 1e-2 * e.first);
      CHECK(std::abs(es.second - e.second) < 1e-2 * e.second);
    }
  }
}

TEST_CASE("The FMM's 512-, 256- and 128-bit kernels give the same product", "[charge]") {
  // The direct leaf sums and the M2L sums have a kernel per width, chosen by the CPU; capping
  // the width runs the narrower ones here too. The widths the CPU lacks fall back to the next
  // narrower, so on such a CPU two of the three products come from the same kernel.
  const auto m = tetseg::test::pawn(0.05);  // 2920 triangles, thin neck and a flat base
  const PanelSet panels = make_panels(m.vertices, m.triangles, "");
  const std::size_t n = panels.size();
  const ClusterTree tree = build_cluster_tree(panels, 32);
  const NearField near = build_near_field(panels, tree);
  const std::vector<double> dense = assemble_dense(panels, near);
  std::vector<double> x(n), exact(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = 1.0 + 0.3 * std::sin(0.37 * static_cast<double>(i));
  dense_apply(dense, n, x.data(), exact.data());
  const TreecodeOperator op(panels, tree, near, 0.4, 6);
  std::vector<std::vector<double>> products;
  for (const int bits : {512, 256, 128}) {
    set_fmm_vector_width(bits);
    products.emplace_back(n);
    op.apply(x.data(), products.back().data());
  }
  set_fmm_vector_width(512);
  for (const auto& fast : products) {
    double num = 0.0, den = 0.0, apart = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      num += (fast[i] - exact[i]) * (fast[i] - exact[i]);
      den += exact[i] * exact[i];
      apart = std::max(apart, std::abs(fast[i] / products[0][i] - 1.0));
    }
    CAPTURE(std::sqrt(num / den), apart);
    CHECK(std::sqrt(num / den) < 1e-5);  // the FMM's own error at order 6
    CHECK(apart < 1e-11);                // the kernels' 1 / r agree to about 1e-15
  }
}

TEST_CASE("Below 10k triangles the automatic fast solve is within 1e-6 of the exact matrix",
          "[charge]") {
  // The residual GMRES reports is against the FMM operator; the automatic order (7 below
  // 10k) keeps the residual against the exact matrix within the automatic tolerance.
  using namespace tetseg::preprocess;
  const auto m = tetseg::test::pawn(0.05);  // 2920 triangles
  ChargeOptions o;
  o.solver = ChargeSolver::kFast;
  const ChargeResult r = compute_charge(m.vertices, m.triangles, o);
  REQUIRE(r.converged);
  REQUIRE(r.tolerance == 1e-6);
  const double exact = residual_against_exact(m, r);
  CAPTURE(m.triangles.size(), r.iterations, r.residual, exact);
  CHECK(exact <= 1e-6);
  // The exact residual of the direct solution is at rounding level.
  o.solver = ChargeSolver::kDirect;
  const ChargeResult d = compute_charge(m.vertices, m.triangles, o);
  CHECK(residual_against_exact(m, d) < 1e-12);
}

TEST_CASE("GMRES reports the true residual of the solution it returns", "[charge]") {
  // At exit the residual comes from the Arnoldi relation instead of a product; it must agree
  // with ||b - A x|| / ||b|| recomputed here, from a zero and from a nonzero start, with and
  // without restarts. A: nonsymmetric, diagonally weighted, 60 x 60.
  const DenseSystem system;
  const std::size_t n = DenseSystem::n;
  const ApplyFn apply = [&](const double* x, double* y) { system.apply(x, y); };
  const ApplyFn jacobi = [&](const double* x, double* y) { system.jacobi(x, y); };
  for (const int restart : {80, 4}) {
    for (const double start : {0.0, 0.3}) {
      std::vector<double> x(n, start);
      const GmresOutcome g =
          solve_gmres(n, apply, jacobi, system.b, x, 1e-9, 200, restart, nullptr);
      const double truth = system.true_residual(x);
      CAPTURE(restart, start, g.iterations, g.residual, truth);
      REQUIRE(g.converged);
      CHECK(truth <= 1e-9);
      CHECK(std::abs(g.residual - truth) <= 1e-13);
    }
  }
}

TEST_CASE("Relaxed GMRES products keep the true residual within the relaxed budget", "[charge]") {
  // Inexact Krylov: a product with relative error delta taken where the residual is r moves
  // the true residual by about delta * r, so solve_gmres may use a cheaper product once
  // delta * (sum of those r) <= kRelaxedBudget * tolerance. Here the relaxed product is the
  // exact one with every component scaled by 1 + delta * s_i (|s_i| <= 1), so it keeps its
  // promise ||relaxed(x) - A x|| <= delta ||A x||; the true residual is recomputed.
  const DenseSystem system;
  const std::size_t n = DenseSystem::n;
  const std::vector<double>& b = system.b;
  int exact_products = 0, relaxed_calls = 0;
  const ApplyFn apply = [&](const double* x, double* y) {
    ++exact_products;
    system.apply(x, y);
  };
  const ApplyFn jacobi = [&](const double* x, double* y) { system.jacobi(x, y); };
  const double tolerance = 1e-9;
  for (const double delta : {1e-2, 1e-4}) {
    RelaxedProduct relaxed;
    relaxed.relative_error = delta;
    relaxed.apply = [&](const double* x, double* y) {
      ++relaxed_calls;
      system.apply(x, y);
      for (std::size_t i = 0; i < n; ++i) y[i] *= 1.0 + delta * std::sin(2.1 * i + 0.4);
    };
    exact_products = relaxed_calls = 0;
    std::vector<double> x(n, 0.0);
    const GmresOutcome g =
        solve_gmres(n, apply, jacobi, b, x, tolerance, 200, 80, nullptr, relaxed);
    const double truth = system.true_residual(x);
    // One product per iteration, of one kind or the other (no restart, zero start).
    CHECK(exact_products + relaxed_calls == g.iterations);
    std::vector<double> x_exact(n, 0.0);
    const GmresOutcome e = solve_gmres(n, apply, jacobi, b, x_exact, tolerance, 200, 80, nullptr);
    CAPTURE(delta, g.iterations, g.relaxed_products, e.iterations, g.residual, truth);
    REQUIRE(g.converged);
    CHECK(g.relaxed_products == relaxed_calls);
    CHECK(g.relaxed_products > 0);
    CHECK(g.relaxed_products < g.iterations);  // the first steps are exact
    CHECK(truth <= (1.0 + kRelaxedBudget) * tolerance);
    // The relaxed steps are those after the residual fell below budget * tolerance / delta.
    CHECK(g.iterations <= e.iterations + 1);
  }
  // A product claimed no better than 100 % is never used: the budget is spent at once.
  RelaxedProduct useless;
  useless.relative_error = 1.0;
  useless.apply = [&](const double*, double* y) { std::fill(y, y + n, 0.0); };
  std::vector<double> x(n, 0.0);
  const GmresOutcome g = solve_gmres(n, apply, jacobi, b, x, tolerance, 200, 80, nullptr, useless);
  CHECK(g.converged);
  CHECK(g.relaxed_products == 0);
  CHECK(system.true_residual(x) <= tolerance);
}

TEST_CASE("Relaxed products leave real meshes' charge within the tolerance", "[charge][cgal]") {
  // The automatic fast solve below 10k relaxes its last products (order 4, theta 0.5). Its
  // residual against the exact collocation matrix stays within the 1e-6 tolerance, and its
  // density is as close to a solve at 1e-10 as that of the solve whose every product is at the
  // automatic order, within 1e-4 of the mean density (measured: 7e-5 against 3e-5 on the
  // elephant, 2.1e-3 against 2.2e-3 on the femur, 1.75e-3 against 1.74e-3 on the dino).
  using namespace tetseg::preprocess;
  for (const char* name : {"elephant", "femur", "dino"}) {
    const std::string path = std::string(TETSEG_CGAL_MESH_DIR) + "/" + name + ".off";
    if (!tetseg::test::have_test_data(path, "libcgal-demo mesh")) return;
    const auto m = tetseg::test::read_off(path);
    ChargeOptions o;
    o.solver = ChargeSolver::kFast;
    const ChargeResult r = compute_charge(m.vertices, m.triangles, o, path);
    o.relaxed_products = false;
    const ChargeResult full = compute_charge(m.vertices, m.triangles, o, path);
    o.tolerance = 1e-10;
    const ChargeResult tight = compute_charge(m.vertices, m.triangles, o, path);
    const double exact = residual_against_exact(m, r);
    // Densities are relative to their area-weighted mean, 1.
    double relaxed_error = 0.0, full_error = 0.0;
    for (std::size_t j = 0; j < r.density.size(); ++j) {
      relaxed_error = std::max(relaxed_error, std::abs(r.density[j] - tight.density[j]));
      full_error = std::max(full_error, std::abs(full.density[j] - tight.density[j]));
    }
    CAPTURE(name, r.iterations, r.relaxed_products, full.iterations, exact, relaxed_error,
            full_error);
    REQUIRE(r.converged);
    CHECK(r.relaxed_products > 0);
    CHECK(full.relaxed_products == 0);
    CHECK(exact <= r.tolerance);
    CHECK(relaxed_error <= full_error + 1e-4);
  }
}

TEST_CASE("The relaxed FMM keeps within the error compute_charge assumes for it",
          "[charge][cgal]") {
  // solve_gmres trusts the relaxed product's promise (kRelaxedError); compute_charge's promise
  // for the order-4 / theta-0.5 FMM rests on its error against the automatic operators on
  // rough vectors like GMRES's (measured at most 4.8e-4 on those up to 327k triangles). A
  // random-sign vector is as rough: 3.1e-4 on the elephant (5558, against order 6 at theta
  // 0.4) and 4.2e-4 subdivided once (22,232, against order 8 at theta 0.45).
  using namespace tetseg::preprocess;
  const std::string path = std::string(TETSEG_CGAL_MESH_DIR) + "/elephant.off";
  if (!tetseg::test::have_test_data(path, "libcgal-demo mesh")) return;
  auto m = tetseg::test::read_off(path);
  for (const auto& [theta, order] : {std::pair{0.4, 6}, std::pair{0.45, 8}}) {
    const PanelSet panels = make_panels(m.vertices, m.triangles, "");
    const std::size_t n = panels.size();
    const ClusterTree tree = build_cluster_tree(panels, 32);
    const NearField near = build_near_field(panels, tree);
    const TreecodeOperator full(panels, tree, near, theta, order);
    const TreecodeOperator relaxed(panels, tree, near, kRelaxedTheta, kRelaxedOrder);
    std::vector<double> x(n), exact(n), cheap(n);
    std::uint64_t state = 12345;
    for (double& v : x) {
      state = state * 6364136223846793005ull + 1442695040888963407ull;
      v = (state >> 63) != 0 ? 1.0 : -1.0;
    }
    full.apply(x.data(), exact.data());
    relaxed.apply(x.data(), cheap.data());
    double num = 0.0, den = 0.0;
    for (std::size_t i = 0; i < n; ++i) {
      num += (exact[i] - cheap[i]) * (exact[i] - cheap[i]);
      den += exact[i] * exact[i];
    }
    const double error = std::sqrt(num / den);
    CAPTURE(n, theta, order, error);
    CHECK(error <= kRelaxedError);
    m = tetseg::test::subdivide(m);
  }
}
