#pragma once
// Two doubles per value, computed lane by lane with the scalar operations (GCC/Clang vector
// extensions; SSE2 on plain x86-64): each lane is bitwise the scalar result, as the runtime is
// compiled with -ffp-contract=off (no product fused into a sum, in either). Internal.

#include <cmath>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#if defined(__GNUC__)
#define TETSEG_HAVE_LANES2 1

namespace tetseg {

typedef double Lanes2 __attribute__((vector_size(16)));
typedef long long Lanes2Bits __attribute__((vector_size(16)));

/// |x| lane by lane, bitwise std::fabs (the sign bit cleared).
inline Lanes2 magnitude(Lanes2 x) noexcept {
  const Lanes2Bits no_sign = {0x7fffffffffffffffLL, 0x7fffffffffffffffLL};
  return reinterpret_cast<Lanes2>(reinterpret_cast<Lanes2Bits>(x) & no_sign);
}

/// Bit l set when lane l of a comparison result (`a < b` of two Lanes2: all ones or zero per
/// lane) is set; _mm_movemask_pd on SSE2.
inline int sign_bits(Lanes2Bits m) noexcept {
#if defined(__SSE2__)
  return _mm_movemask_pd(reinterpret_cast<__m128d>(m));
#else
  return int(m[0] & 1) | int(m[1] & 1) << 1;
#endif
}

}  // namespace tetseg
#endif
