#pragma once
// The FMM kernels of the charge solver (internal; definitions and their error bounds in
// charge_fmm_kernels.cpp). Points and charges are in tree order; `inv_scale2` is 1 / R^2 with
// R of the order of the mesh size, and 1 / r comes from a reciprocal square root estimate of
// r^2 / R^2 refined by Newton steps (relative error below 1e-12).

#include <cstddef>
#include <cstdint>

#include "charge_tree.hpp"

#if defined(__x86_64__) && defined(__GNUC__)
#define TETSEG_CHARGE_AVX2 1  // AVX2 + FMA (and AVX-512F) kernels, chosen at run time
#endif

namespace tetseg::preprocess::charge_detail {

/// Caps the vector width of the FMM kernels: 512 (AVX-512F, the default where the CPU has it),
/// 256 (AVX2 and FMA) or anything lower (SSE2). For tests and benchmarks of the narrower
/// kernels; the CPU's features still bound it. Not to be changed during a product.
void set_fmm_vector_width(int bits);
int fmm_vector_width();

bool cpu_has_avx2();    ///< AVX2 and FMA
bool cpu_has_avx512();  ///< AVX-512F

/// sum over j in [begin, end) of q[j] / |t - p_j|, skipping p_j == t (SSE2 and scalar).
double direct_sum(double tx, double ty, double tz, const double* px, const double* py,
                  const double* pz, const double* q, std::uint32_t begin, std::uint32_t end,
                  double inv_scale2);

/// The same sum over all sources of the leaves list[0, count) (node ids into `nodes`), with
/// 256-bit (AVX2 and FMA) or 512-bit (AVX-512F) vectors; call only where the CPU has them.
double direct_row_avx2(double tx, double ty, double tz, const double* px, const double* py,
                       const double* pz, const double* q, const Cluster* nodes,
                       const std::int32_t* list, std::size_t count, double inv_scale2);
double direct_row_avx512(double tx, double ty, double tz, const double* px, const double* py,
                         const double* pz, const double* q, const Cluster* nodes,
                         const std::int32_t* list, std::size_t count, double inv_scale2);

/// direct_row with the widest kernel the CPU and set_fmm_vector_width allow (direct_sum per
/// leaf without AVX2).
double direct_leaves(double tx, double ty, double tz, const double* px, const double* py,
                     const double* pz, const double* q, const Cluster* nodes,
                     const std::int32_t* list, std::size_t count, double inv_scale2);

/// The multipole-to-local sums of one batch of four source clusters into `local` (SSE2, and
/// with 256-bit fused multiply-adds where the CPU has them).
void m2l_sums(std::size_t kc, const std::size_t* start, const std::uint16_t* tb,
              const std::uint16_t* tc, const double* dv, const double* mv, const double* inv_fact,
              double* local);
void m2l_sums_avx2(std::size_t kc, const std::size_t* start, const std::uint16_t* tb,
                   const std::uint16_t* tc, const double* dv, const double* mv,
                   const double* inv_fact, double* local);

/// The Taylor coefficients of 1 / |R_p + w| for a batch of four separations (interleaved).
void taylor_batch(std::size_t kc, const TaylorRecurrence* recurrence, const double* rx,
                  const double* ry, const double* rz, const double* inv_r2, const double* fact,
                  double* raw, double* scaled);

}  // namespace tetseg::preprocess::charge_detail
