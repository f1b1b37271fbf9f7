// Treecode (FMM) operator of the charge solvers (TreecodeOperator). Its kernels (direct sums,
// M2L, Taylor recurrence): charge_fmm_kernels.cpp; the cluster tree and the analytic near
// field it reads: charge_cluster_tree.cpp.

#include "charge_tree.hpp"

#include "charge_fmm_kernels.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace tetseg::preprocess::charge_detail {

TreecodeOperator::TreecodeOperator(const PanelSet& panels, const ClusterTree& tree,
                                   const NearField& near, double theta, int order)
    : m_n(panels.size()), m_order(std::clamp(order, 0, 16)), m_tree(tree), m_near(near) {
  // Multi-index tables.
  const int p = m_order;
  std::vector<int> lookup(static_cast<std::size_t>((p + 1) * (p + 1) * (p + 1)), -1);
  auto at = [&](int a, int b, int c) -> int {
    if (a < 0 || b < 0 || c < 0 || a + b + c > p) return -1;
    return lookup[static_cast<std::size_t>((a * (p + 1) + b) * (p + 1) + c)];
  };
  for (int total = 0; total <= p; ++total) {
    for (int a = total; a >= 0; --a) {
      for (int b = total - a; b >= 0; --b) {
        const int c = total - a - b;
        lookup[static_cast<std::size_t>((a * (p + 1) + b) * (p + 1) + c)] =
            static_cast<int>(m_index.size());
        m_index.push_back({a, b, c});
      }
    }
  }
  for (const auto& k : m_index) {
    std::array<int, 3> m1{-1, -1, -1}, m2{-1, -1, -1};
    for (int i = 0; i < 3; ++i) {
      std::array<int, 3> q = k;
      q[i] -= 1;
      m1[i] = at(q[0], q[1], q[2]);
      q[i] -= 1;
      m2[i] = at(q[0], q[1], q[2]);
    }
    m_minus1.push_back(m1);
    m_minus2.push_back(m2);
  }
  m_recurrence.resize(m_index.size());
  for (std::size_t k = 1; k < m_index.size(); ++k) {
    const int o = m_index[k][0] + m_index[k][1] + m_index[k][2];
    TaylorRecurrence& rc = m_recurrence[k];
    for (std::size_t i = 0; i < 3; ++i) {
      rc.m1[i] = m_minus1[k][i] >= 0 ? static_cast<std::uint32_t>(m_minus1[k][i])
                                     : static_cast<std::uint32_t>(m_index.size());
      rc.m2[i] = m_minus2[k][i] >= 0 ? static_cast<std::uint32_t>(m_minus2[k][i])
                                     : static_cast<std::uint32_t>(m_index.size());
    }
    rc.alpha = -(2.0 * o - 1.0) / o;
    rc.beta = -(o - 1.0) / o;
  }
  m_mono_from.assign(m_index.size(), 0);
  m_mono_axis.assign(m_index.size(), 0);
  for (std::size_t k = 1; k < m_index.size(); ++k) {
    const auto& m1 = m_minus1[k];
    const int i = m1[0] >= 0 ? 0 : (m1[1] >= 0 ? 1 : 2);
    m_mono_axis[k] = static_cast<std::uint8_t>(i);
    m_mono_from[k] = static_cast<std::uint32_t>(m1[static_cast<std::size_t>(i)]);
  }
  auto binom = [](int a, int b) {
    double r = 1.0;
    for (int i = 1; i <= b; ++i) r = r * (a - b + i) / i;
    return r;
  };
  const int kc = static_cast<int>(m_index.size());
  for (int ni = 0; ni < kc; ++ni) {
    for (int mi = 0; mi < kc; ++mi) {
      const auto& n = m_index[static_cast<std::size_t>(ni)];
      const auto& m = m_index[static_cast<std::size_t>(mi)];
      // M2L: 1/|R + u - s| = sum_k D_k(R) (u - s)^k, D_k the Taylor coefficients.
      const int sum = at(n[0] + m[0], n[1] + m[1], n[2] + m[2]);
      if (sum >= 0) {
        double coef = ((m[0] + m[1] + m[2]) % 2) ? -1.0 : 1.0;
        for (int i = 0; i < 3; ++i) coef *= binom(n[i] + m[i], n[i]);
        m_m2l.push_back({ni, mi, sum, coef});
      }
      // Shifts: (s + d)^n = sum_{m <= n} C(n, m) d^(n - m) s^m.
      const int diff = at(n[0] - m[0], n[1] - m[1], n[2] - m[2]);
      if (diff >= 0) {
        double coef = 1.0;
        for (int i = 0; i < 3; ++i) coef *= binom(n[i], m[i]);
        m_m2m.push_back({ni, mi, diff, coef});  // M_n(parent) from M_m(child)
        m_l2l.push_back({mi, ni, diff, coef});  // L_m(child) from L_n(parent)
      }
    }
  }

  m_m2l_start.assign(static_cast<std::size_t>(kc) + 1, 0);
  for (const Term& t : m_m2l) ++m_m2l_start[static_cast<std::size_t>(t.a) + 1];
  for (std::size_t a = 0; a < static_cast<std::size_t>(kc); ++a) {
    m_m2l_start[a + 1] += m_m2l_start[a];
  }
  for (const Term& t : m_m2l) {
    m_m2l_b.push_back(static_cast<std::uint16_t>(t.b));
    m_m2l_c.push_back(static_cast<std::uint16_t>(t.c));
  }
  for (const auto& k : m_index) {
    double f = 1.0;
    for (int i = 0; i < 3; ++i) {
      for (int q = 2; q <= k[static_cast<std::size_t>(i)]; ++q) f *= q;
    }
    m_fact.push_back(f);
    m_inv_fact.push_back(1.0 / f);
    m_moment_scale.push_back(((k[0] + k[1] + k[2]) % 2 ? -1.0 : 1.0) / f);
  }

  m_sources = in_tree_order(panels, tree);
  const std::size_t node_count = tree.nodes.size();
  // Shift terms grouped by their target index a (M2M already is), with start offsets.
  std::stable_sort(m_l2l.begin(), m_l2l.end(),
                   [](const Term& u, const Term& v) { return u.a < v.a; });
  for (auto [terms, start] : {std::pair{&m_m2m, &m_m2m_start}, std::pair{&m_l2l, &m_l2l_start}}) {
    start->assign(static_cast<std::size_t>(kc) + 1, 0);
    for (const Term& t : *terms) ++(*start)[static_cast<std::size_t>(t.a) + 1];
    for (std::size_t a = 0; a < static_cast<std::size_t>(kc); ++a) (*start)[a + 1] += (*start)[a];
  }
  m_parent.assign(node_count, -1);
  for (std::size_t id = 0; id < node_count; ++id) {
    const Cluster& c = tree.nodes[id];
    if (c.left >= 0) {
      m_parent[static_cast<std::size_t>(c.left)] = static_cast<std::int32_t>(id);
      m_parent[static_cast<std::size_t>(c.right)] = static_cast<std::int32_t>(id);
    }
  }
  // The upward and downward passes run over kSubtrees subtrees in parallel (each in post-order
  // in one thread) and over the few nodes above them in one thread: two barriers per pass at
  // any tree size (they went level by level before; at 5k every level was below the parallel
  // threshold, so the whole pass ran in one thread).
  {
    constexpr std::size_t kSubtrees = 32;
    std::vector<std::int32_t> cut = {0};
    m_top_nodes.clear();
    while (cut.size() < kSubtrees) {
      std::vector<std::int32_t> next;
      bool split = false;
      for (const std::int32_t id : cut) {
        const Cluster& c = tree.nodes[static_cast<std::size_t>(id)];
        if (c.left >= 0) {
          next.push_back(c.left);
          next.push_back(c.right);
          m_top_nodes.push_back(id);
          split = true;
        } else {
          next.push_back(id);
        }
      }
      if (!split) break;
      cut.swap(next);
    }
    // m_top_nodes is parents first; the upward pass walks it backwards.
    m_subtree_start.assign(1, 0);
    m_subtree_nodes.clear();
    std::vector<std::pair<std::int32_t, bool>> stack;
    for (const std::int32_t root : cut) {
      stack.assign(1, {root, false});
      while (!stack.empty()) {
        const auto [id, expanded] = stack.back();
        stack.pop_back();
        const Cluster& c = tree.nodes[static_cast<std::size_t>(id)];
        if (expanded || c.left < 0) {
          m_subtree_nodes.push_back(id);
        } else {
          stack.push_back({id, true});
          stack.push_back({c.right, false});
          stack.push_back({c.left, false});
        }
      }
      m_subtree_start.push_back(m_subtree_nodes.size());
    }
  }
  m_leaf_of_node.assign(node_count, -1);
  for (std::size_t l = 0; l < tree.leaves.size(); ++l) {
    m_leaf_of_node[static_cast<std::size_t>(tree.leaves[l])] = static_cast<std::int32_t>(l);
  }

  // Dual-tree traversal: admissible pairs become M2L, leaf pairs direct sums, otherwise the
  // larger cluster (or the one that is not a leaf) is split. A depth-first walk with an
  // explicit stack, in two phases with the same lists as one serial walk: one thread walks
  // until the stack holds kWalks pairs; then the pairs left on the stack are walked to the
  // end in parallel, each into its own record, and the records are read top of the stack
  // first (the order in which the serial walk would have finished them).
  using NodePair = std::pair<std::int32_t, std::int32_t>;
  struct Walk {
    std::vector<NodePair> far, direct;  // (target node, source node), in walk order
  };
  auto step = [&](std::vector<NodePair>& stack, Walk& out) {
    const auto [ti, si] = stack.back();
    stack.pop_back();
    const Cluster& t = tree.nodes[static_cast<std::size_t>(ti)];
    const Cluster& s = tree.nodes[static_cast<std::size_t>(si)];
    const double dx = s.center[0] - t.center[0];
    const double dy = s.center[1] - t.center[1];
    const double dz = s.center[2] - t.center[2];
    const double dist = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (ti != si && t.radius + s.radius < theta * dist) {
      out.far.push_back({ti, si});
      return;
    }
    const bool t_leaf = t.left < 0, s_leaf = s.left < 0;
    if (t_leaf && s_leaf) {
      out.direct.push_back({ti, si});
    } else if (s_leaf || (!t_leaf && t.radius >= s.radius)) {
      stack.push_back({t.right, si});
      stack.push_back({t.left, si});
    } else {
      stack.push_back({ti, s.right});
      stack.push_back({ti, s.left});
    }
  };
  constexpr std::size_t kWalks = 64;
  std::vector<NodePair> stack = {{0, 0}};
  std::vector<Walk> walks(1);
  while (!stack.empty() && stack.size() < kWalks) step(stack, walks[0]);
  const std::size_t parallel_walks = stack.size();
  walks.resize(1 + parallel_walks);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(dynamic, 1)
#endif
  for (std::ptrdiff_t ww = 0; ww < static_cast<std::ptrdiff_t>(parallel_walks); ++ww) {
    const std::size_t w = static_cast<std::size_t>(ww);
    std::vector<NodePair> own = {stack[parallel_walks - 1 - w]};
    while (!own.empty()) step(own, walks[1 + w]);
  }
  // Per-target lists (CSR), each in walk order.
  m_far_start.assign(node_count + 1, 0);
  std::vector<std::vector<std::int32_t>> direct(tree.leaves.size());
  for (const Walk& w : walks) {
    for (const auto& [ti, si] : w.far) ++m_far_start[static_cast<std::size_t>(ti) + 1];
  }
  for (std::size_t id = 0; id < node_count; ++id) m_far_start[id + 1] += m_far_start[id];
  m_far.resize(m_far_start[node_count]);
  {
    std::vector<std::size_t> fill(m_far_start.begin(), m_far_start.end() - 1);
    for (const Walk& w : walks) {
      for (const auto& [ti, si] : w.far) m_far[fill[static_cast<std::size_t>(ti)]++] = si;
      for (const auto& [ti, si] : w.direct) {
        direct[static_cast<std::size_t>(m_leaf_of_node[static_cast<std::size_t>(ti)])].push_back(
            si);
      }
    }
  }
  m_direct_start.assign(tree.leaves.size() + 1, 0);
  double direct_work = 0.0;
  for (std::size_t l = 0; l < tree.leaves.size(); ++l) {
    const Cluster& t = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
    std::sort(direct[l].begin(), direct[l].end());
    m_direct_start[l + 1] = m_direct_start[l] + direct[l].size();
    m_direct.insert(m_direct.end(), direct[l].begin(), direct[l].end());
    for (const std::int32_t id : direct[l]) {
      const Cluster& s = tree.nodes[static_cast<std::size_t>(id)];
      direct_work += static_cast<double>(t.end - t.begin) * (s.end - s.begin);
    }
  }
  m_direct_per_target = direct_work / static_cast<double>(m_n);
  // Every product writes these before reading them: no zero-fill here (its page faults
  // then fall in the first product, on both threads).
  m_charge.resize(m_n);
  m_moments.resize(node_count * m_index.size());
  m_local.resize(node_count * m_index.size());
  m_scaled.resize(node_count * m_index.size());
}

void TreecodeOperator::apply(const double* x, double* y) const {
  const auto& order = m_tree.order;
  const auto& nodes = m_tree.nodes;
  const auto& leaves = m_tree.leaves;
  const std::size_t kc = m_index.size();
  const std::ptrdiff_t node_count = static_cast<std::ptrdiff_t>(nodes.size());
  double* charge = m_charge.data();
  const double* px = m_sources.x.data();
  const double* py = m_sources.y.data();
  const double* pz = m_sources.z.data();
  const double root_radius = nodes[0].radius > 0.0 ? nodes[0].radius : 1.0;
  const double inv_scale2 = 1.0 / (root_radius * root_radius);
  static const bool cpu_avx2 = cpu_has_avx2();
  static const bool cpu_avx512 = cpu_avx2 && cpu_has_avx512();
  const int width = fmm_vector_width();
  const bool avx2 = cpu_avx2 && width >= 256;
  const bool avx512 = cpu_avx512 && width >= 512;
  // Monomials w^k for |k| <= order, graded order, from k - e_i.
  auto monomials = [&](double wx, double wy, double wz, double* out) {
    out[0] = 1.0;
    const double w[3] = {wx, wy, wz};
    for (std::size_t k = 1; k < kc; ++k) out[k] = out[m_mono_from[k]] * w[m_mono_axis[k]];
  };
  // to[a] += sum over a's terms of coef * d^c * from[b], one register sum per a.
  auto shift = [&](const std::vector<Term>& terms, const std::vector<std::size_t>& start,
                   const double* d_mono, const double* from, double* to) {
    for (std::size_t a = 0; a < kc; ++a) {
      double acc0 = 0.0, acc1 = 0.0;  // two chains: the sums are latency-bound
      std::size_t e = start[a];
      for (; e + 2 <= start[a + 1]; e += 2) {
        const Term& t0 = terms[e];
        const Term& t1 = terms[e + 1];
        acc0 += t0.coef * d_mono[t0.c] * from[t0.b];
        acc1 += t1.coef * d_mono[t1.c] * from[t1.b];
      }
      if (e < start[a + 1]) acc0 += terms[e].coef * d_mono[terms[e].c] * from[terms[e].b];
      to[a] += acc0 + acc1;
    }
  };
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
    constexpr std::size_t kBatch = 4;
    std::vector<double> mono(kc), raw((kc + 1) * kBatch), deriv(kc * kBatch), moments(kc * kBatch),
        pot, zeros(kc, 0.0);
    // Upward pass: leaf moments from the members, parents from their children.
    auto upward = [&](std::size_t id) {
      const Cluster& c = nodes[id];
      double* mom = m_moments.data() + id * kc;
      std::fill(mom, mom + kc, 0.0);
      if (c.left < 0) {
        for (std::uint32_t k = c.begin; k < c.end; ++k) {
          monomials(px[k] - c.center[0], py[k] - c.center[1], pz[k] - c.center[2], mono.data());
          const double q = m_sources.area[k] * x[order[k]];
          charge[k] = q;
          for (std::size_t e = 0; e < kc; ++e) mom[e] += q * mono[e];
        }
        return;
      }
      for (const std::int32_t child : {c.left, c.right}) {
        const Cluster& ch = nodes[static_cast<std::size_t>(child)];
        monomials(ch.center[0] - c.center[0], ch.center[1] - c.center[1],
                  ch.center[2] - c.center[2], mono.data());
        shift(m_m2m, m_m2m_start, mono.data(),
              m_moments.data() + static_cast<std::size_t>(child) * kc, mom);
      }
    };
    auto downward = [&](std::size_t id) {
      const Cluster& c = nodes[id];
      const Cluster& pc = nodes[static_cast<std::size_t>(m_parent[id])];
      monomials(c.center[0] - pc.center[0], c.center[1] - pc.center[1], c.center[2] - pc.center[2],
                mono.data());
      shift(m_l2l, m_l2l_start, mono.data(),
            m_local.data() + static_cast<std::size_t>(m_parent[id]) * kc, m_local.data() + id * kc);
    };
    const std::ptrdiff_t subtrees = static_cast<std::ptrdiff_t>(m_subtree_start.size()) - 1;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 1)
#endif
    for (std::ptrdiff_t t = 0; t < subtrees; ++t) {
      for (std::size_t at = m_subtree_start[static_cast<std::size_t>(t)];
           at < m_subtree_start[static_cast<std::size_t>(t) + 1]; ++at) {
        upward(static_cast<std::size_t>(m_subtree_nodes[at]));
      }
    }
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp single
#endif
    for (std::size_t at = m_top_nodes.size(); at-- > 0;) {
      upward(static_cast<std::size_t>(m_top_nodes[at]));
    }
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(static)
#endif
    for (std::ptrdiff_t e = 0; e < static_cast<std::ptrdiff_t>(m_scaled.size()); ++e) {
      const std::size_t u = static_cast<std::size_t>(e);
      m_scaled[u] = m_moments[u] * m_moment_scale[u % kc];
    }
    // Multipole-to-local for every target cluster.
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 8)
#endif
    for (std::ptrdiff_t ti = 0; ti < node_count; ++ti) {
      const Cluster& target = nodes[static_cast<std::size_t>(ti)];
      double* local = m_local.data() + static_cast<std::size_t>(ti) * kc;
      std::fill(local, local + kc, 0.0);
      // Source clusters in batches of kBatch, interleaved so that the recurrence and the
      // term sums run kBatch independent chains (lane p of deriv[k * kBatch + p]); missing
      // lanes of the last batch repeat a real source with zero moments.
      const std::size_t first = m_far_start[static_cast<std::size_t>(ti)];
      const std::size_t stop = m_far_start[static_cast<std::size_t>(ti) + 1];
      for (std::size_t f = first; f < stop; f += kBatch) {
        double rx[kBatch], ry[kBatch], rz[kBatch], inv_r2[kBatch];
        const double* mom[kBatch];
        for (std::size_t p = 0; p < kBatch; ++p) {
          const bool real = f + p < stop;
          const std::int32_t sid = m_far[real ? f + p : f];
          const Cluster& s = nodes[static_cast<std::size_t>(sid)];
          rx[p] = target.center[0] - s.center[0];
          ry[p] = target.center[1] - s.center[1];
          rz[p] = target.center[2] - s.center[2];
          inv_r2[p] = 1.0 / (rx[p] * rx[p] + ry[p] * ry[p] + rz[p] * rz[p]);
          mom[p] = real ? m_scaled.data() + static_cast<std::size_t>(sid) * kc : zeros.data();
        }
        // Taylor coefficients of 1 / |R + w| in w (Duan & Krasny recurrence), times k!.
        taylor_batch(kc, m_recurrence.data(), rx, ry, rz, inv_r2, m_fact.data(), raw.data(),
                     deriv.data());
        // The batch's moments interleaved like deriv (lane p of slot b), so that every term is
        // one product of two contiguous kBatch-vectors.
        for (std::size_t b = 0; b < kc; ++b) {
          for (std::size_t p = 0; p < kBatch; ++p) moments[b * kBatch + p] = mom[p][b];
        }
        if (avx2) {
          m2l_sums_avx2(kc, m_m2l_start.data(), m_m2l_b.data(), m_m2l_c.data(), deriv.data(),
                        moments.data(), m_inv_fact.data(), local);
        } else {
          m2l_sums(kc, m_m2l_start.data(), m_m2l_b.data(), m_m2l_c.data(), deriv.data(),
                   moments.data(), m_inv_fact.data(), local);
        }
      }
    }
    // Downward pass: parents before children, the nodes above the subtrees in one thread.
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp single
#endif
    for (const std::int32_t id : m_top_nodes) {
      if (id != 0) downward(static_cast<std::size_t>(id));
    }
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 1)
#endif
    for (std::ptrdiff_t t = 0; t < subtrees; ++t) {
      for (std::size_t at = m_subtree_start[static_cast<std::size_t>(t) + 1];
           at-- > m_subtree_start[static_cast<std::size_t>(t)];) {
        const std::int32_t id = m_subtree_nodes[at];
        if (id != 0) downward(static_cast<std::size_t>(id));
      }
    }
    // Leaves: evaluate the local expansion and the direct sums.
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 4)
#endif
    for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves.size()); ++ll) {
      const std::size_t l = static_cast<std::size_t>(ll);
      const std::size_t id = static_cast<std::size_t>(leaves[l]);
      const Cluster& target = nodes[id];
      const double* local = m_local.data() + id * kc;
      pot.assign(target.end - target.begin, 0.0);
      for (std::uint32_t k = target.begin; k < target.end; ++k) {
        monomials(px[k] - target.center[0], py[k] - target.center[1], pz[k] - target.center[2],
                  mono.data());
        double s0 = 0.0, s1 = 0.0, s2 = 0.0, s3 = 0.0;  // four chains
        std::size_t e = 0;
        for (; e + 4 <= kc; e += 4) {
          s0 += local[e] * mono[e];
          s1 += local[e + 1] * mono[e + 1];
          s2 += local[e + 2] * mono[e + 2];
          s3 += local[e + 3] * mono[e + 3];
        }
        for (; e < kc; ++e) s0 += local[e] * mono[e];
        pot[k - target.begin] = (s0 + s1) + (s2 + s3);
      }
      if (avx2) {
        const std::int32_t* list = m_direct.data() + m_direct_start[l];
        const std::size_t count = m_direct_start[l + 1] - m_direct_start[l];
        for (std::uint32_t k = target.begin; k < target.end; ++k) {
          pot[k - target.begin] += (avx512 ? direct_row_avx512 : direct_row_avx2)(
              px[k], py[k], pz[k], px, py, pz, charge, nodes.data(), list, count, inv_scale2);
        }
      } else {
        for (std::size_t d = m_direct_start[l]; d < m_direct_start[l + 1]; ++d) {
          const Cluster& s = nodes[static_cast<std::size_t>(m_direct[d])];
          for (std::uint32_t k = target.begin; k < target.end; ++k) {
            pot[k - target.begin] +=
                direct_sum(px[k], py[k], pz[k], px, py, pz, charge, s.begin, s.end, inv_scale2);
          }
        }
      }
      // Exact near field of each target: analytic minus the point charge counted above.
      for (std::uint32_t k = target.begin; k < target.end; ++k) {
        const std::size_t i = order[k];
        const std::size_t end = m_near.row_start[i + 1];
        double c0 = 0.0, c1 = 0.0, c2 = 0.0, c3 = 0.0;  // four chains
        std::size_t e = m_near.row_start[i];
        for (; e + 4 <= end; e += 4) {
          c0 += m_near.correction[e] * x[m_near.column[e]];
          c1 += m_near.correction[e + 1] * x[m_near.column[e + 1]];
          c2 += m_near.correction[e + 2] * x[m_near.column[e + 2]];
          c3 += m_near.correction[e + 3] * x[m_near.column[e + 3]];
        }
        for (; e < end; ++e) c0 += m_near.correction[e] * x[m_near.column[e]];
        y[i] = pot[k - target.begin] + ((c0 + c1) + (c2 + c3));
      }
    }
  }
}

}  // namespace tetseg::preprocess::charge_detail
