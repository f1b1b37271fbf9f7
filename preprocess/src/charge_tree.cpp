// Treecode (FMM) operator of the charge solvers: the kernels (direct sums, M2L, Taylor
// recurrence, with AVX2 / AVX-512F variants chosen at run time) and TreecodeOperator. The
// cluster tree and the analytic near field it reads: charge_cluster_tree.cpp.

#include "charge_tree.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <numeric>
#if defined(__SSE2__)
#include <immintrin.h>
#endif
#if defined(__x86_64__) && defined(__GNUC__)
#define TETSEG_CHARGE_AVX2 1  // AVX2 + FMA (and AVX-512F) kernels, chosen at run time
#endif

namespace tetseg::preprocess::charge_detail {

namespace {

/// The widest FMM kernels apply() may use (set_fmm_vector_width).
std::atomic<int> g_vector_width{512};

}  // namespace

void set_fmm_vector_width(int bits) {
  g_vector_width.store(bits, std::memory_order_relaxed);
}

namespace {

/// sum over j in [begin, end) of q[j] / |t - p_j|, skipping p_j == t. `inv_scale2` (1 / R^2,
/// R of the order of the mesh size) keeps r^2 / R^2 inside single-precision range for the
/// SSE path: 1/r from the single-precision rsqrt estimate (relative error < 4e-4) refined by
/// two Newton steps in double, relative error below 1e-12, and no division or square root.
inline double direct_sum(double tx, double ty, double tz, const double* px, const double* py,
                         const double* pz, const double* q, std::uint32_t begin, std::uint32_t end,
                         double inv_scale2) {
  double sum = 0.0;
  std::uint32_t j = begin;
#if defined(__SSE2__)
  const __m128d vx = _mm_set1_pd(tx), vy = _mm_set1_pd(ty), vz = _mm_set1_pd(tz);
  const __m128d vs = _mm_set1_pd(inv_scale2), half = _mm_set1_pd(0.5),
                three_halves = _mm_set1_pd(1.5), zero = _mm_setzero_pd();
  __m128d acc = _mm_setzero_pd();
  auto pair = [&](std::uint32_t k) {
    const __m128d dx = _mm_sub_pd(vx, _mm_loadu_pd(px + k));
    const __m128d dy = _mm_sub_pd(vy, _mm_loadu_pd(py + k));
    const __m128d dz = _mm_sub_pd(vz, _mm_loadu_pd(pz + k));
    const __m128d r2 = _mm_mul_pd(
        _mm_add_pd(_mm_add_pd(_mm_mul_pd(dx, dx), _mm_mul_pd(dy, dy)), _mm_mul_pd(dz, dz)), vs);
    const __m128d live = _mm_cmpgt_pd(r2, zero);
    __m128d y = _mm_cvtps_pd(_mm_rsqrt_ps(_mm_cvtpd_ps(r2)));
    const __m128d hr2 = _mm_mul_pd(half, r2);
    y = _mm_mul_pd(y, _mm_sub_pd(three_halves, _mm_mul_pd(hr2, _mm_mul_pd(y, y))));
    y = _mm_mul_pd(y, _mm_sub_pd(three_halves, _mm_mul_pd(hr2, _mm_mul_pd(y, y))));
    y = _mm_and_pd(y, live);  // r2 == 0 (the target itself) gives inf/NaN: drop it
    acc = _mm_add_pd(acc, _mm_mul_pd(y, _mm_loadu_pd(q + k)));
  };
  for (; j + 2 <= end; j += 2) pair(j);
  double lanes[2];
  _mm_storeu_pd(lanes, acc);
  sum = (lanes[0] + lanes[1]) * std::sqrt(inv_scale2);
#else
  (void)inv_scale2;
#endif
  for (; j < end; ++j) {
    const double dx = tx - px[j], dy = ty - py[j], dz = tz - pz[j];
    const double r2 = dx * dx + dy * dy + dz * dz;
    if (r2 > 0.0) sum += q[j] / std::sqrt(r2);
  }
  return sum;
}

/// The multipole-to-local sums of one batch of kBatch = 4 source clusters: for each target
/// index a, L_a += (1 / a!) sum over a's terms e of sum_p deriv[c_e][p] * moments[b_e][p]
/// (deriv and moments interleaved: lane p of slot k at k * 4 + p). Terms are sorted by a.
void m2l_sums(std::size_t kc, const std::size_t* start, const std::uint16_t* tb,
              const std::uint16_t* tc, const double* dv, const double* mv, const double* inv_fact,
              double* local) {
  constexpr std::size_t kBatch = 4;
  std::size_t e = 0;
  for (std::size_t a = 0; a < kc; ++a) {
    const std::size_t end = start[a + 1];
#if defined(__SSE2__)
    // Two independent accumulator pairs (even and odd terms) for lanes 0-1 and 2-3.
    __m128d lo0 = _mm_setzero_pd(), hi0 = _mm_setzero_pd();
    __m128d lo1 = _mm_setzero_pd(), hi1 = _mm_setzero_pd();
    for (; e + 2 <= end; e += 2) {
      const double* d0 = dv + static_cast<std::size_t>(tc[e]) * kBatch;
      const double* m0 = mv + static_cast<std::size_t>(tb[e]) * kBatch;
      const double* d1 = dv + static_cast<std::size_t>(tc[e + 1]) * kBatch;
      const double* m1 = mv + static_cast<std::size_t>(tb[e + 1]) * kBatch;
      lo0 = _mm_add_pd(lo0, _mm_mul_pd(_mm_loadu_pd(d0), _mm_loadu_pd(m0)));
      hi0 = _mm_add_pd(hi0, _mm_mul_pd(_mm_loadu_pd(d0 + 2), _mm_loadu_pd(m0 + 2)));
      lo1 = _mm_add_pd(lo1, _mm_mul_pd(_mm_loadu_pd(d1), _mm_loadu_pd(m1)));
      hi1 = _mm_add_pd(hi1, _mm_mul_pd(_mm_loadu_pd(d1 + 2), _mm_loadu_pd(m1 + 2)));
    }
    if (e < end) {
      const double* d0 = dv + static_cast<std::size_t>(tc[e]) * kBatch;
      const double* m0 = mv + static_cast<std::size_t>(tb[e]) * kBatch;
      lo0 = _mm_add_pd(lo0, _mm_mul_pd(_mm_loadu_pd(d0), _mm_loadu_pd(m0)));
      hi0 = _mm_add_pd(hi0, _mm_mul_pd(_mm_loadu_pd(d0 + 2), _mm_loadu_pd(m0 + 2)));
      ++e;
    }
    const __m128d both = _mm_add_pd(_mm_add_pd(lo0, lo1), _mm_add_pd(hi0, hi1));
    double lanes[2];
    _mm_storeu_pd(lanes, both);
    local[a] += (lanes[0] + lanes[1]) * inv_fact[a];
#else
    double acc[kBatch] = {};
    for (; e < end; ++e) {
      const double* d = dv + static_cast<std::size_t>(tc[e]) * kBatch;
      const double* m = mv + static_cast<std::size_t>(tb[e]) * kBatch;
      for (std::size_t p = 0; p < kBatch; ++p) acc[p] += d[p] * m[p];
    }
    local[a] += ((acc[0] + acc[1]) + (acc[2] + acc[3])) * inv_fact[a];
#endif
  }
}

#if defined(TETSEG_CHARGE_AVX2)
/// m2l_sums with 256-bit fused multiply-adds (one per term), for CPUs that have them.
__attribute__((target("avx2,fma"))) void m2l_sums_avx2(std::size_t kc, const std::size_t* start,
                                                       const std::uint16_t* tb,
                                                       const std::uint16_t* tc, const double* dv,
                                                       const double* mv, const double* inv_fact,
                                                       double* local) {
  std::size_t e = 0;
  for (std::size_t a = 0; a < kc; ++a) {
    const std::size_t end = start[a + 1];
    __m256d acc0 = _mm256_setzero_pd(), acc1 = _mm256_setzero_pd();
    __m256d acc2 = _mm256_setzero_pd(), acc3 = _mm256_setzero_pd();
    for (; e + 4 <= end; e += 4) {
      acc0 = _mm256_fmadd_pd(_mm256_loadu_pd(dv + 4 * static_cast<std::size_t>(tc[e])),
                             _mm256_loadu_pd(mv + 4 * static_cast<std::size_t>(tb[e])), acc0);
      acc1 = _mm256_fmadd_pd(_mm256_loadu_pd(dv + 4 * static_cast<std::size_t>(tc[e + 1])),
                             _mm256_loadu_pd(mv + 4 * static_cast<std::size_t>(tb[e + 1])), acc1);
      acc2 = _mm256_fmadd_pd(_mm256_loadu_pd(dv + 4 * static_cast<std::size_t>(tc[e + 2])),
                             _mm256_loadu_pd(mv + 4 * static_cast<std::size_t>(tb[e + 2])), acc2);
      acc3 = _mm256_fmadd_pd(_mm256_loadu_pd(dv + 4 * static_cast<std::size_t>(tc[e + 3])),
                             _mm256_loadu_pd(mv + 4 * static_cast<std::size_t>(tb[e + 3])), acc3);
    }
    for (; e < end; ++e) {
      acc0 = _mm256_fmadd_pd(_mm256_loadu_pd(dv + 4 * static_cast<std::size_t>(tc[e])),
                             _mm256_loadu_pd(mv + 4 * static_cast<std::size_t>(tb[e])), acc0);
    }
    const __m256d sum = _mm256_add_pd(_mm256_add_pd(acc0, acc1), _mm256_add_pd(acc2, acc3));
    const __m128d half = _mm_add_pd(_mm256_castpd256_pd128(sum), _mm256_extractf128_pd(sum, 1));
    double lanes[2];
    _mm_storeu_pd(lanes, half);
    local[a] += (lanes[0] + lanes[1]) * inv_fact[a];
  }
}

/// acc + q / r for four sources (s) and the target (v): rsqrt estimate of r^2 * vs and two
/// Newton steps; lanes outside `used` take r^2 = 1 (their charge is 0), r^2 = 0 gives 0.
__attribute__((target("avx2,fma"), always_inline)) inline __m256d direct_step(
    __m256d vx, __m256d vy, __m256d vz, __m256d vs, __m256d sx, __m256d sy, __m256d sz, __m256d sq,
    __m256d used, __m256d acc) {
  const __m256d half = _mm256_set1_pd(0.5), three_halves = _mm256_set1_pd(1.5);
  const __m256d dx = _mm256_sub_pd(vx, sx);
  const __m256d dy = _mm256_sub_pd(vy, sy);
  const __m256d dz = _mm256_sub_pd(vz, sz);
  __m256d r2 =
      _mm256_mul_pd(_mm256_fmadd_pd(dz, dz, _mm256_fmadd_pd(dy, dy, _mm256_mul_pd(dx, dx))), vs);
  r2 = _mm256_blendv_pd(_mm256_set1_pd(1.0), r2, used);
  const __m256d live = _mm256_cmp_pd(r2, _mm256_setzero_pd(), _CMP_GT_OQ);
  __m256d y = _mm256_cvtps_pd(_mm_rsqrt_ps(_mm256_cvtpd_ps(r2)));
  const __m256d hr2 = _mm256_mul_pd(half, r2);
  y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hr2, _mm256_mul_pd(y, y), three_halves));
  y = _mm256_mul_pd(y, _mm256_fnmadd_pd(hr2, _mm256_mul_pd(y, y), three_halves));
  y = _mm256_and_pd(y, live);  // r2 == 0 (the target itself): drop it
  return _mm256_fmadd_pd(y, sq, acc);
}

/// The direct sums of one target over all its source leaves (node ids list[0, count)) with
/// 256-bit vectors: direct_sum's rsqrt estimate and two (fused) Newton steps, the same relative
/// error bound; one accumulator pair and one reduction per target, and each leaf's last one to
/// three sources in a masked step (unused lanes: r^2 = 1, charge 0), not scalar square roots.
__attribute__((target("avx2,fma"))) double direct_row_avx2(double tx, double ty, double tz,
                                                           const double* px, const double* py,
                                                           const double* pz, const double* q,
                                                           const Cluster* nodes,
                                                           const std::int32_t* list,
                                                           std::size_t count, double inv_scale2) {
  const __m256d vx = _mm256_set1_pd(tx), vy = _mm256_set1_pd(ty), vz = _mm256_set1_pd(tz);
  const __m256d vs = _mm256_set1_pd(inv_scale2);
  const __m256i lane = _mm256_setr_epi64x(0, 1, 2, 3);
  __m256d acc0 = _mm256_setzero_pd(), acc1 = _mm256_setzero_pd();
  const __m256d all = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
  for (std::size_t d = 0; d < count; ++d) {
    const Cluster& s = nodes[static_cast<std::size_t>(list[d])];
    std::uint32_t j = s.begin;
    for (; j + 8 <= s.end; j += 8) {
      acc0 = direct_step(vx, vy, vz, vs, _mm256_loadu_pd(px + j), _mm256_loadu_pd(py + j),
                         _mm256_loadu_pd(pz + j), _mm256_loadu_pd(q + j), all, acc0);
      acc1 = direct_step(vx, vy, vz, vs, _mm256_loadu_pd(px + j + 4), _mm256_loadu_pd(py + j + 4),
                         _mm256_loadu_pd(pz + j + 4), _mm256_loadu_pd(q + j + 4), all, acc1);
    }
    for (; j < s.end; j += 4) {
      const __m256i mask =
          _mm256_cmpgt_epi64(_mm256_set1_epi64x(static_cast<long long>(s.end - j)), lane);
      acc0 = direct_step(vx, vy, vz, vs, _mm256_maskload_pd(px + j, mask),
                         _mm256_maskload_pd(py + j, mask), _mm256_maskload_pd(pz + j, mask),
                         _mm256_maskload_pd(q + j, mask), _mm256_castsi256_pd(mask), acc0);
    }
  }
  const __m256d acc = _mm256_add_pd(acc0, acc1);
  const __m128d pair = _mm_add_pd(_mm256_castpd256_pd128(acc), _mm256_extractf128_pd(acc, 1));
  double lanes[2];
  _mm_storeu_pd(lanes, pair);
  return (lanes[0] + lanes[1]) * std::sqrt(inv_scale2);
}

/// direct_row_avx2 with 512-bit vectors (AVX-512F): eight sources per step, the 14-bit
/// rsqrt14 estimate in double and two Newton steps (relative error below 1e-15), masked tails.
__attribute__((target("avx512f"))) double direct_row_avx512(double tx, double ty, double tz,
                                                            const double* px, const double* py,
                                                            const double* pz, const double* q,
                                                            const Cluster* nodes,
                                                            const std::int32_t* list,
                                                            std::size_t count, double inv_scale2) {
  const __m512d vx = _mm512_set1_pd(tx), vy = _mm512_set1_pd(ty), vz = _mm512_set1_pd(tz);
  const __m512d vs = _mm512_set1_pd(inv_scale2), half = _mm512_set1_pd(0.5),
                three_halves = _mm512_set1_pd(1.5), zero = _mm512_setzero_pd();
  __m512d acc = _mm512_setzero_pd();
  for (std::size_t d = 0; d < count; ++d) {
    const Cluster& s = nodes[static_cast<std::size_t>(list[d])];
    for (std::uint32_t j = s.begin; j < s.end; j += 8) {
      const std::uint32_t left = s.end - j;
      const __mmask8 used = left >= 8 ? __mmask8(0xff) : __mmask8((1u << left) - 1u);
      const __m512d dx = _mm512_sub_pd(vx, _mm512_maskz_loadu_pd(used, px + j));
      const __m512d dy = _mm512_sub_pd(vy, _mm512_maskz_loadu_pd(used, py + j));
      const __m512d dz = _mm512_sub_pd(vz, _mm512_maskz_loadu_pd(used, pz + j));
      const __m512d r2 = _mm512_mul_pd(
          _mm512_fmadd_pd(dz, dz, _mm512_fmadd_pd(dy, dy, _mm512_mul_pd(dx, dx))), vs);
      const __mmask8 live = _mm512_mask_cmp_pd_mask(used, r2, zero, _CMP_GT_OQ);
      __m512d y = _mm512_maskz_rsqrt14_pd(0xff, r2);
      const __m512d hr2 = _mm512_mul_pd(half, r2);
      y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_halves));
      y = _mm512_mul_pd(y, _mm512_fnmadd_pd(hr2, _mm512_mul_pd(y, y), three_halves));
      acc = _mm512_mask3_fmadd_pd(y, _mm512_maskz_loadu_pd(live, q + j), acc, live);
    }
  }
  double lanes[8];
  _mm512_storeu_pd(lanes, acc);
  return (((lanes[0] + lanes[4]) + (lanes[2] + lanes[6])) +
          ((lanes[1] + lanes[5]) + (lanes[3] + lanes[7]))) *
         std::sqrt(inv_scale2);
}

bool cpu_has_avx2() {
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
bool cpu_has_avx512() {
  return __builtin_cpu_supports("avx512f");
}
#else
void m2l_sums_avx2(std::size_t kc, const std::size_t* start, const std::uint16_t* tb,
                   const std::uint16_t* tc, const double* dv, const double* mv,
                   const double* inv_fact, double* local) {
  m2l_sums(kc, start, tb, tc, dv, mv, inv_fact, local);
}
double direct_row_avx2(double, double, double, const double*, const double*, const double*,
                       const double*, const Cluster*, const std::int32_t*, std::size_t, double) {
  return 0.0;  // never called: cpu_has_avx2() is false
}
double direct_row_avx512(double, double, double, const double*, const double*, const double*,
                         const double*, const Cluster*, const std::int32_t*, std::size_t, double) {
  return 0.0;  // never called: cpu_has_avx512() is false
}
bool cpu_has_avx512() {
  return false;
}
bool cpu_has_avx2() {
  return false;
}
#endif

/// Four doubles, one per source cluster of an M2L batch (GCC vector extension: one 256-bit
/// register in the AVX2 clone, two 128-bit halves otherwise).
typedef double Doubles4 __attribute__((vector_size(32), aligned(8)));

/// The Taylor coefficients D_k of 1 / |R_p + w| for the four separations R_p = (rx, ry, rz)[p]
/// of a batch, interleaved (lane p of slot k at k * 4 + p): raw holds D_k ((kc + 1) * 4,
/// slot kc the zero predecessor), scaled receives k! D_k (kc * 4).
TETSEG_CHARGE_CLONES void taylor_batch(std::size_t kc, const TaylorRecurrence* recurrence,
                                       const double* rx, const double* ry, const double* rz,
                                       const double* inv_r2, const double* fact, double* raw,
                                       double* scaled) {
  // Explicit Doubles4 pointers throughout: a deduced type would drop the reduced alignment.
  Doubles4* const d = reinterpret_cast<Doubles4*>(raw);
  Doubles4* const out = reinterpret_cast<Doubles4*>(scaled);
  const Doubles4 vx = *reinterpret_cast<const Doubles4*>(rx);
  const Doubles4 vy = *reinterpret_cast<const Doubles4*>(ry);
  const Doubles4 vz = *reinterpret_cast<const Doubles4*>(rz);
  const Doubles4 vi = *reinterpret_cast<const Doubles4*>(inv_r2);
  Doubles4 d0 = vi;
  for (int p = 0; p < 4; ++p) d0[p] = std::sqrt(inv_r2[p]);
  d[0] = d0;
  d[kc] = Doubles4{0.0, 0.0, 0.0, 0.0};
  out[0] = d0 * fact[0];
  for (std::size_t k = 1; k < kc; ++k) {
    const TaylorRecurrence& rc = recurrence[k];
    const Doubles4 s1 = vx * d[rc.m1[0]] + vy * d[rc.m1[1]] + vz * d[rc.m1[2]];
    const Doubles4 s2 = d[rc.m2[0]] + d[rc.m2[1]] + d[rc.m2[2]];
    const Doubles4 v = (rc.alpha * s1 + rc.beta * s2) * vi;
    d[k] = v;
    out[k] = v * fact[k];
  }
}

}  // namespace

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

  m_x.resize(m_n);
  m_y.resize(m_n);
  m_z.resize(m_n);
  m_area.resize(m_n);
  for (std::size_t k = 0; k < m_n; ++k) {
    const std::uint32_t j = tree.order[k];
    m_x[k] = panels.centroid[j][0];
    m_y[k] = panels.centroid[j][1];
    m_z[k] = panels.centroid[j][2];
    m_area[k] = panels.area[j];
  }
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
  const double* px = m_x.data();
  const double* py = m_y.data();
  const double* pz = m_z.data();
  const double root_radius = nodes[0].radius > 0.0 ? nodes[0].radius : 1.0;
  const double inv_scale2 = 1.0 / (root_radius * root_radius);
  static const bool cpu_avx2 = cpu_has_avx2();
  static const bool cpu_avx512 = cpu_avx2 && cpu_has_avx512();
  const int width = g_vector_width.load(std::memory_order_relaxed);
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
          const double q = m_area[k] * x[order[k]];
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
