#pragma once
// Two doubles per value, computed lane by lane with the scalar operations (GCC/Clang vector
// extensions; SSE2 on plain x86-64): each lane is bitwise the scalar result, as the runtime is
// compiled with -ffp-contract=off (no product fused into a sum, in either). Internal.

#include <cmath>

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

}  // namespace tetseg
#endif
