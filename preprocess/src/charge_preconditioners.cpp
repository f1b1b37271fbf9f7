// The preconditioners of the charge solver's GMRES (docs/charge.md, "Preconditioner"):
// block Jacobi over the leaves and the near-field Schwarz of each leaf with its neighbours.
// The two-level Schwarz built on the latter: charge_two_level.cpp.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "charge_solvers.hpp"

namespace tetseg::preprocess::charge_detail {

BlockJacobi::BlockJacobi(const PanelSet& panels, const ClusterTree& tree) : m_tree(tree) {
  const std::size_t leaves = tree.leaves.size();
  m_offset.resize(leaves + 1, 0);
  for (std::size_t l = 0; l < leaves; ++l) {
    const Cluster& c = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
    const std::size_t m = c.end - c.begin;
    m_offset[l + 1] = m_offset[l] + m * m;
  }
  m_inverse.resize(m_offset[leaves]);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(dynamic, 8)
#endif
  for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves); ++ll) {
    const std::size_t l = static_cast<std::size_t>(ll);
    const Cluster& c = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
    const Eigen::Index m = c.end - c.begin;
    Eigen::MatrixXd block(m, m);
    for (Eigen::Index a = 0; a < m; ++a) {
      for (Eigen::Index b = 0; b < m; ++b) {
        block(a, b) = matrix_entry(panels, tree.order[c.begin + static_cast<std::size_t>(a)],
                                   tree.order[c.begin + static_cast<std::size_t>(b)]);
      }
    }
    const Eigen::MatrixXd inv = block.partialPivLu().inverse();
    Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
        m_inverse.data() + m_offset[l], m, m) = inv;
  }
}

void BlockJacobi::apply(const double* in, double* out) const {
  const std::size_t leaves = m_tree.leaves.size();
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel for schedule(static)
#endif
  for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves); ++ll) {
    const std::size_t l = static_cast<std::size_t>(ll);
    const Cluster& c = m_tree.nodes[static_cast<std::size_t>(m_tree.leaves[l])];
    const std::size_t m = c.end - c.begin;
    const double* inv = m_inverse.data() + m_offset[l];
    for (std::size_t a = 0; a < m; ++a) {
      double s = 0.0;
      for (std::size_t b = 0; b < m; ++b) s += inv[a * m + b] * in[m_tree.order[c.begin + b]];
      out[m_tree.order[c.begin + a]] = s;
    }
  }
}

}  // namespace tetseg::preprocess::charge_detail

namespace tetseg::preprocess::charge_detail {

namespace {

/// Per-thread buffers of the Schwarz setup.
struct SchwarzScratch {
  std::vector<float> a, rows, upper, x, y, z, area;
  std::vector<std::uint32_t> perm, pivot;
  void resize(std::size_t s, std::size_t ld, std::size_t members) {
    a.resize(s * ld);
    rows.resize(members * ld);
    upper.resize(members * members);
    for (auto* v : {&x, &y, &z, &area}) v->resize(s);
    perm.resize(s);
    pivot.resize(s);
  }
};

/// One row of point_charge_matrix from column v on: four entries per SSE step, then scalar.
inline void point_charge_row_tail(std::size_t s, std::size_t v, float px, float py, float pz,
                                  const float* x, const float* y, const float* z, const float* area,
                                  float* row) {
#if defined(__SSE2__)
  const __m128 vx = _mm_set1_ps(px), vy = _mm_set1_ps(py), vz = _mm_set1_ps(pz);
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
  for (; v + 4 <= s; v += 4) {
    const __m128 dx = _mm_sub_ps(vx, _mm_loadu_ps(x + v));
    const __m128 dy = _mm_sub_ps(vy, _mm_loadu_ps(y + v));
    const __m128 dz = _mm_sub_ps(vz, _mm_loadu_ps(z + v));
    const __m128 r2 =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, dx), _mm_mul_ps(dy, dy)), _mm_mul_ps(dz, dz));
    const __m128 live = _mm_cmpgt_ps(r2, zero);
    const __m128 safe = _mm_or_ps(_mm_and_ps(live, r2), _mm_andnot_ps(live, one));
    const __m128 w = _mm_div_ps(_mm_loadu_ps(area + v), _mm_sqrt_ps(safe));
    _mm_storeu_ps(row + v, _mm_and_ps(live, w));
  }
#endif
  for (; v < s; ++v) {
    const float dx = px - x[v], dy = py - y[v], dz = pz - z[v];
    const float r2 = dx * dx + dy * dy + dz * dz;
    row[v] = r2 > 0.0f ? area[v] / std::sqrt(r2) : 0.0f;
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
/// Eight entries per step of one row (AVX, no FMA: the same correctly rounded operations per
/// entry as the SSE steps), from column 0; returns the first column left over.
__attribute__((target("avx2"))) std::size_t point_charge_row_avx2(std::size_t s, float px, float py,
                                                                  float pz, const float* x,
                                                                  const float* y, const float* z,
                                                                  const float* area, float* row) {
  const __m256 vx = _mm256_set1_ps(px), vy = _mm256_set1_ps(py), vz = _mm256_set1_ps(pz);
  const __m256 zero = _mm256_setzero_ps(), one = _mm256_set1_ps(1.0f);
  std::size_t v = 0;
  for (; v + 8 <= s; v += 8) {
    const __m256 dx = _mm256_sub_ps(vx, _mm256_loadu_ps(x + v));
    const __m256 dy = _mm256_sub_ps(vy, _mm256_loadu_ps(y + v));
    const __m256 dz = _mm256_sub_ps(vz, _mm256_loadu_ps(z + v));
    const __m256 r2 = _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(dx, dx), _mm256_mul_ps(dy, dy)),
                                    _mm256_mul_ps(dz, dz));
    const __m256 live = _mm256_cmp_ps(r2, zero, _CMP_GT_OQ);
    const __m256 safe = _mm256_blendv_ps(one, r2, live);
    const __m256 w = _mm256_div_ps(_mm256_loadu_ps(area + v), _mm256_sqrt_ps(safe));
    _mm256_storeu_ps(row + v, _mm256_and_ps(live, w));
  }
  return v;
}
#endif

/// a[u * ld + v] = area[v] / |p_u - p_v| (0 for u == v), single precision; columns s..ld-1
/// are set to 0. Exact square root and division (eight entries per AVX step where the CPU has
/// it, four per SSE step otherwise; the same values either way).
void point_charge_matrix(std::size_t s, std::size_t ld, const float* x, const float* y,
                         const float* z, const float* area, float* a) {
#if defined(__x86_64__) && defined(__GNUC__)
  static const bool avx2 = __builtin_cpu_supports("avx2");
#else
  constexpr bool avx2 = false;
#endif
  for (std::size_t u = 0; u < s; ++u) {
    float* row = a + u * ld;
    std::size_t v = 0;
#if defined(__x86_64__) && defined(__GNUC__)
    if (avx2) v = point_charge_row_avx2(s, x[u], y[u], z[u], x, y, z, area, row);
#endif
    point_charge_row_tail(s, v, x[u], y[u], z[u], x, y, z, area, row);
    std::fill(row + s, row + ld, 0.0f);
  }
}

/// Eight floats, loaded and stored without alignment (GCC vector extension: 256-bit
/// instructions in the AVX2 clone below, two 128-bit halves otherwise).
typedef float Floats8 __attribute__((vector_size(32), aligned(4)));
typedef std::int32_t Ints8 __attribute__((vector_size(32)));

/// dst[j] -= f * src[j] for keep <= j < end, in blocks of eight from keep rounded down to a
/// multiple of 8 (end is one): the lanes of the first block below `keep` keep their values.
inline void subtract_scaled(float* dst, const float* src, float f, std::size_t keep,
                            std::size_t end) {
  std::size_t j = keep & ~std::size_t{7};
  if (j < keep && j < end) {
    const Ints8 lane = {0, 1, 2, 3, 4, 5, 6, 7};
    Floats8* d = reinterpret_cast<Floats8*>(dst + j);
    const Floats8 v = *d - f * *reinterpret_cast<const Floats8*>(src + j);
    *d = lane + static_cast<std::int32_t>(j) >= static_cast<std::int32_t>(keep) ? v : *d;
    j += 8;
  }
  for (; j < end; j += 8) {
    Floats8* d = reinterpret_cast<Floats8*>(dst + j);
    *d -= f * *reinterpret_cast<const Floats8*>(src + j);
  }
}

/// dst[r][j] -= f[r] * src[j] for 0 <= j < end, four rows (blocks of eight; the lanes of the
/// last block at or above `end` keep their values).
inline void subtract_scaled_rows4(float* const* dst, const float* src, const float* f,
                                  std::size_t end) {
  std::size_t j = 0;
  for (; j + 8 <= end; j += 8) {
    const Floats8 v = *reinterpret_cast<const Floats8*>(src + j);
    *reinterpret_cast<Floats8*>(dst[0] + j) -= f[0] * v;
    *reinterpret_cast<Floats8*>(dst[1] + j) -= f[1] * v;
    *reinterpret_cast<Floats8*>(dst[2] + j) -= f[2] * v;
    *reinterpret_cast<Floats8*>(dst[3] + j) -= f[3] * v;
  }
  for (int q = 0; q < 4; ++q) {
    for (std::size_t e = j; e < end; ++e) dst[q][e] -= f[q] * src[e];
  }
}

/// Four rows at once: dst[r][j] -= sum over q < 4, in order, of dst[r][k0 + q] * u[q][j] for
/// keep <= j < end (blocks of eight as in subtract_scaled): four rank-1 updates of a panel in
/// one load and store of each row block.
inline void subtract_rank4(float* const* dst, const float* const* u, std::size_t k0,
                           std::size_t keep, std::size_t end) {
  float f[4][4];
  for (int r = 0; r < 4; ++r) {
    for (int q = 0; q < 4; ++q) f[r][q] = dst[r][k0 + static_cast<std::size_t>(q)];
  }
  std::size_t j = keep & ~std::size_t{7};
  if (j < keep && j < end) {
    for (int r = 0; r < 4; ++r) {
      for (int q = 0; q < 4; ++q) subtract_scaled(dst[r], u[q], f[r][q], keep, j + 8);
    }
    j += 8;
  }
  for (; j < end; j += 8) {
    const Floats8 u0 = *reinterpret_cast<const Floats8*>(u[0] + j);
    const Floats8 u1 = *reinterpret_cast<const Floats8*>(u[1] + j);
    const Floats8 u2 = *reinterpret_cast<const Floats8*>(u[2] + j);
    const Floats8 u3 = *reinterpret_cast<const Floats8*>(u[3] + j);
    for (int r = 0; r < 4; ++r) {
      Floats8* d = reinterpret_cast<Floats8*>(dst[r] + j);
      Floats8 v = *d;
      v -= f[r][0] * u0;
      v -= f[r][1] * u1;
      v -= f[r][2] * u2;
      v -= f[r][3] * u3;
      *d = v;
    }
  }
}

/// Rows s - m .. s - 1 of A^-1 for the dense s x s matrix A (row-major, stride ld, destroyed),
/// into rows (m x ld, row t = row s - m + t of A^-1); `upper` is scratch of m x m. LU with partial
/// pivoting, P A = L U, so A^-1 = U^-1 L^-1 P; the last m rows of the upper triangular U^-1 are
/// zero left of column s - m, so they need only the trailing m x m block of U and the last m rows
/// of L^-1: about s^3 / 3 + m s^2 / 2 multiply-adds, all row operations (vectorised). Returns false
/// if a pivot is zero or not finite.
TETSEG_CHARGE_CLONES bool inverse_rows_of_last(std::size_t s, std::size_t ld, std::size_t m,
                                               float* a, std::uint32_t* pivot, float* upper,
                                               float* rows) {
  // Right-looking LU in panels of up to four columns: the panel is factorised with its own
  // columns updated at once, then the panel's U rows and the trailing rows receive the panel's
  // (up to) four rank-1 updates in one pass over each row (the same operations in the same
  // order as one update per column, so the same result, with a quarter of the row loads and
  // stores). Row swaps move whole rows: a row's pending updates come from its own multipliers.
  constexpr std::size_t kPanel = 4;
  for (std::size_t k0 = 0; k0 < s; k0 += kPanel) {
    const std::size_t kb = std::min(kPanel, s - k0), k1 = k0 + kb;
    for (std::size_t k = k0; k < k1; ++k) {
      std::size_t p = k;
      float best = std::abs(a[k * ld + k]);
      for (std::size_t i = k + 1; i < s; ++i) {
        const float v = std::abs(a[i * ld + k]);
        if (v > best) {
          best = v;
          p = i;
        }
      }
      if (!(best > 0.0f) || !std::isfinite(best)) return false;
      pivot[k] = static_cast<std::uint32_t>(p);
      if (p != k) std::swap_ranges(a + k * ld, a + k * ld + s, a + p * ld);
      const float* rk = a + k * ld;
      const float inv = 1.0f / rk[k];
      for (std::size_t i = k + 1; i < s; ++i) {
        float* ri = a + i * ld;
        const float l = ri[k] * inv;
        ri[k] = l;
        for (std::size_t c = k + 1; c < k1; ++c) ri[c] -= l * rk[c];
      }
    }
    if (k1 >= s) break;
    const float* u[kPanel];
    for (std::size_t q = 0; q < kPanel; ++q) u[q] = a + (k0 + std::min(q, kb - 1)) * ld;
    // The panel's own U rows right of the panel (row k0 + t needs rows k0 .. k0 + t - 1).
    for (std::size_t t = 1; t < kb; ++t) {
      float* rt = a + (k0 + t) * ld;
      for (std::size_t q = 0; q < t; ++q) subtract_scaled(rt, u[q], rt[k0 + q], k1, ld);
    }
    std::size_t i = k1;
    if (kb == kPanel) {
      for (; i + 4 <= s; i += 4) {
        float* const ri[4] = {a + i * ld, a + (i + 1) * ld, a + (i + 2) * ld, a + (i + 3) * ld};
        subtract_rank4(ri, u, k0, k1, ld);
      }
    }
    for (; i < s; ++i) {
      float* ri = a + i * ld;
      for (std::size_t q = 0; q < kb; ++q) subtract_scaled(ri, u[q], ri[k0 + q], k1, ld);
    }
  }
  // Y = last m rows of L^-1: row t solves y L = e_{r+t} (L unit lower triangular), from the
  // right: y_k is final once the rows below k have been subtracted. L is copied with zeros on
  // and above the diagonal first, so that whole rows can be subtracted.
  const std::size_t r = s - m;
  for (std::size_t t = 0; t < m; ++t) {
    std::copy(a + (r + t) * ld + r, a + (r + t) * ld + s, upper + t * m);
  }
  for (std::size_t k = 0; k < s; ++k) {
    float* row = a + k * ld;
    std::fill(row + k, row + ld, 0.0f);
  }
  // Four rows at a time (independent chains, one load of each row of L): a row whose start
  // r + t lies below k has y[k] = 0 there, and subtracting 0 * L_k changes nothing.
  for (std::size_t t0 = 0; t0 < m; t0 += 4) {
    const std::size_t tb = std::min<std::size_t>(4, m - t0);
    float* y[4];
    for (std::size_t q = 0; q < 4; ++q) y[q] = rows + (t0 + std::min(q, tb - 1)) * ld;
    for (std::size_t q = 0; q < tb; ++q) {
      std::fill(y[q], y[q] + ld, 0.0f);
      y[q][r + t0 + q] = 1.0f;
    }
    for (std::size_t k = r + t0 + tb - 1; k > 0; --k) {
      const float* lk = a + k * ld;
      if (tb == 4) {
        const float f[4] = {y[0][k], y[1][k], y[2][k], y[3][k]};
        subtract_scaled_rows4(y, lk, f, k);
      } else {
        for (std::size_t q = 0; q < tb; ++q) subtract_scaled(y[q], lk, y[q][k], 0, k);
      }
    }
  }
  // X = U_mm^-1 Y (U_mm the trailing m x m block of U), back substitution by rows.
  for (std::size_t t = m; t-- > 0;) {
    float* x = rows + t * ld;
    const float* ut = upper + t * m;
    for (std::size_t v = t + 1; v < m; ++v) {
      const float f = ut[v];
      const float* xv = rows + v * ld;
      subtract_scaled(x, xv, f, 0, s);
    }
    const float inv = 1.0f / ut[t];
    for (std::size_t j = 0; j < s; ++j) x[j] *= inv;
  }
  // X P: the row swaps of the factorisation become column swaps, last first.
  for (std::size_t k = s; k-- > 0;) {
    if (pivot[k] == k) continue;
    for (std::size_t t = 0; t < m; ++t) std::swap(rows[t * ld + k], rows[t * ld + pivot[k]]);
  }
  return true;
}

}  // namespace

NearFieldSchwarz::NearFieldSchwarz(const PanelSet& panels, const ClusterTree& tree,
                                   const NearField& near, std::size_t max_set)
    : m_tree(tree) {
  const std::size_t n = panels.size();
  const std::size_t leaves = tree.leaves.size();
  // Pass 1: the extended set of every leaf: its members, then the near-field columns of its
  // members with the largest coupling score sum over members i of A_i A_j / |c_i - c_j|^3
  // (the decay of the inverse operator's kernel; docs/charge.md, "Preconditioner").
  std::vector<std::vector<std::uint32_t>> sets(leaves);
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
    // mark[j]: -1 for a member, 1 + its index in `extra` for a candidate, 0 otherwise.
    std::vector<std::int32_t> mark(n, 0);
    std::vector<std::pair<double, std::uint32_t>> extra;  // (-score, column)
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 8)
#endif
    for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves); ++ll) {
      const std::size_t l = static_cast<std::size_t>(ll);
      const Cluster& c = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
      auto& set = sets[l];
      for (std::uint32_t k = c.begin; k < c.end; ++k) {
        set.push_back(tree.order[k]);
        mark[tree.order[k]] = -1;
      }
      extra.clear();
      for (std::uint32_t k = c.begin; k < c.end; ++k) {
        const std::size_t i = tree.order[k];
        const Vec3& p = panels.centroid[i];
        for (std::size_t e = near.row_start[i]; e < near.row_start[i + 1]; ++e) {
          const std::uint32_t j = near.column[e];
          if (mark[j] < 0) continue;
          const Vec3& q = panels.centroid[j];
          const double dx = q[0] - p[0], dy = q[1] - p[1], dz = q[2] - p[2];
          const double r2 = dx * dx + dy * dy + dz * dz;
          // Coincident centroids (overlapping triangles) couple the most.
          const double score =
              r2 > 0.0 ? panels.area[i] * panels.area[j] / (r2 * std::sqrt(r2)) : HUGE_VAL;
          if (mark[j] == 0) {
            extra.push_back({-score, j});
            mark[j] = static_cast<std::int32_t>(extra.size());
          } else {
            extra[static_cast<std::size_t>(mark[j] - 1)].first -= score;
          }
        }
      }
      for (const std::uint32_t j : set) mark[j] = 0;
      for (const auto& e : extra) mark[e.second] = 0;
      const std::size_t room = max_set > set.size() ? max_set - set.size() : 0;
      if (extra.size() > room) {
        std::nth_element(extra.begin(), extra.begin() + static_cast<std::ptrdiff_t>(room),
                         extra.end());
        extra.resize(room);
      }
      std::sort(extra.begin(), extra.end());
      for (const auto& e : extra) set.push_back(e.second);
    }
  }
  m_set_start.assign(leaves + 1, 0);
  m_rows_start.assign(leaves + 1, 0);
  for (std::size_t l = 0; l < leaves; ++l) {
    const Cluster& c = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
    m_set_start[l + 1] = m_set_start[l] + sets[l].size();
    m_rows_start[l + 1] = m_rows_start[l] + sets[l].size() * (c.end - c.begin);
  }
  m_set.resize(m_set_start[leaves]);
  m_rows.resize(m_rows_start[leaves]);
  m_mean_set =
      static_cast<double>(m_set.size()) / static_cast<double>(std::max<std::size_t>(leaves, 1));
  // Pass 2: factorise M_SS and keep the members' rows of its inverse. Unknowns (and
  // equations) in the order [others, members], so that the members' rows of the inverse come
  // from the last rows of U^-1 (inverse_rows_of_last).
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
    std::vector<std::int32_t> pos(n, -1);
    SchwarzScratch scratch;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(dynamic, 4)
#endif
    for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves); ++ll) {
      const std::size_t l = static_cast<std::size_t>(ll);
      const Cluster& c = tree.nodes[static_cast<std::size_t>(tree.leaves[l])];
      const auto& set = sets[l];
      std::copy(set.begin(), set.end(),
                m_set.begin() + static_cast<std::ptrdiff_t>(m_set_start[l]));
      const std::size_t s = set.size();
      const std::size_t members = c.end - c.begin;
      const std::size_t others = s - members;
      const std::size_t ld = (s + 7) & ~std::size_t{7};
      // perm[u]: the set position of unknown (and equation) u.
      scratch.resize(s, ld, members);
      for (std::size_t u = 0; u < s; ++u) {
        scratch.perm[u] = static_cast<std::uint32_t>(u < others ? members + u : u - others);
      }
      // Point charges in single precision about the leaf centre (the preconditioner needs a
      // few digits), then the analytic near-field entries over them.
      for (std::size_t u = 0; u < s; ++u) {
        const std::size_t j = set[scratch.perm[u]];
        const Vec3& q = panels.centroid[j];
        scratch.x[u] = static_cast<float>(q[0] - c.center[0]);
        scratch.y[u] = static_cast<float>(q[1] - c.center[1]);
        scratch.z[u] = static_cast<float>(q[2] - c.center[2]);
        scratch.area[u] = static_cast<float>(panels.area[j]);
        pos[j] = static_cast<std::int32_t>(u);
      }
      point_charge_matrix(s, ld, scratch.x.data(), scratch.y.data(), scratch.z.data(),
                          scratch.area.data(), scratch.a.data());
      for (std::size_t u = 0; u < s; ++u) {
        const std::size_t i = set[scratch.perm[u]];
        float* row = scratch.a.data() + u * ld;
        for (std::size_t e = near.row_start[i]; e < near.row_start[i + 1]; ++e) {
          const std::int32_t b = pos[near.column[e]];
          if (b >= 0) row[b] = static_cast<float>(near.value[e]);
        }
      }
      for (const std::uint32_t j : set) pos[j] = -1;
      float* rows = m_rows.data() + m_rows_start[l];
      if (!inverse_rows_of_last(s, ld, members, scratch.a.data(), scratch.pivot.data(),
                                scratch.upper.data(), scratch.rows.data())) {
        // Singular block (not seen on valid input): this leaf falls back to Jacobi.
        std::fill(rows, rows + members * s, 0.0f);
        for (std::size_t a = 0; a < members; ++a) {
          rows[a * s + a] = static_cast<float>(1.0 / near.diagonal[set[a]]);
        }
        continue;
      }
      // Row t of the result belongs to unknown others + t, i.e. member t; its columns are
      // equations in perm order.
      for (std::size_t t = 0; t < members; ++t) {
        const float* from = scratch.rows.data() + t * ld;
        float* to = rows + t * s;
        for (std::size_t u = 0; u < s; ++u) to[scratch.perm[u]] = from[u];
      }
    }
  }
}

void NearFieldSchwarz::apply(const double* in, double* out) const {
  const std::size_t leaves = m_tree.leaves.size();
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp parallel
#endif
  {
    std::vector<double> gathered;
#if defined(TETSEG_HAVE_OPENMP)
#pragma omp for schedule(static)
#endif
    for (std::ptrdiff_t ll = 0; ll < static_cast<std::ptrdiff_t>(leaves); ++ll) {
      const std::size_t l = static_cast<std::size_t>(ll);
      const Cluster& c = m_tree.nodes[static_cast<std::size_t>(m_tree.leaves[l])];
      const std::size_t s = m_set_start[l + 1] - m_set_start[l];
      const std::uint32_t* set = m_set.data() + m_set_start[l];
      gathered.resize(s);
      for (std::size_t b = 0; b < s; ++b) gathered[b] = in[set[b]];
      const float* rows = m_rows.data() + m_rows_start[l];
      for (std::size_t a = 0; a < c.end - c.begin; ++a) {
        const float* row = rows + a * s;
        double s0 = 0.0, s1 = 0.0;
        std::size_t b = 0;
        for (; b + 2 <= s; b += 2) {
          s0 += row[b] * gathered[b];
          s1 += row[b + 1] * gathered[b + 1];
        }
        if (b < s) s0 += row[b] * gathered[b];
        out[set[a]] = s0 + s1;
      }
    }
  }
}

}  // namespace tetseg::preprocess::charge_detail
