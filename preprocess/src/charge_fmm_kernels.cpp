// The FMM kernels of the charge solver (charge_fmm_kernels.hpp): direct sums, M2L sums and
// the Taylor recurrence, with AVX2 / AVX-512F variants chosen at run time. Their user:
// TreecodeOperator (charge_tree.cpp).

#include "charge_fmm_kernels.hpp"

#include <atomic>
#include <cmath>
#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace tetseg::preprocess::charge_detail {

namespace {

/// The widest FMM kernels apply() may use (set_fmm_vector_width).
std::atomic<int> g_vector_width{512};

}  // namespace

void set_fmm_vector_width(int bits) {
  g_vector_width.store(bits, std::memory_order_relaxed);
}

int fmm_vector_width() {
  return g_vector_width.load(std::memory_order_relaxed);
}

/// sum over j in [begin, end) of q[j] / |t - p_j|, skipping p_j == t. `inv_scale2` (1 / R^2,
/// R of the order of the mesh size) keeps r^2 / R^2 inside single-precision range for the
/// SSE path: 1/r from the single-precision rsqrt estimate (relative error < 4e-4) refined by
/// two Newton steps in double, relative error below 1e-12, and no division or square root.
double direct_sum(double tx, double ty, double tz, const double* px, const double* py,
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

namespace {

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

}  // namespace

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

double direct_leaves(double tx, double ty, double tz, const double* px, const double* py,
                     const double* pz, const double* q, const Cluster* nodes,
                     const std::int32_t* list, std::size_t count, double inv_scale2) {
  static const bool cpu_avx2 = cpu_has_avx2();
  static const bool cpu_avx512 = cpu_avx2 && cpu_has_avx512();
  const int width = fmm_vector_width();
  if (cpu_avx512 && width >= 512) {
    return direct_row_avx512(tx, ty, tz, px, py, pz, q, nodes, list, count, inv_scale2);
  }
  if (cpu_avx2 && width >= 256) {
    return direct_row_avx2(tx, ty, tz, px, py, pz, q, nodes, list, count, inv_scale2);
  }
  double sum = 0.0;
  for (std::size_t d = 0; d < count; ++d) {
    const Cluster& s = nodes[static_cast<std::size_t>(list[d])];
    sum += direct_sum(tx, ty, tz, px, py, pz, q, s.begin, s.end, inv_scale2);
  }
  return sum;
}

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

}  // namespace tetseg::preprocess::charge_detail
