#pragma once
/// \file
/// Elementary continuous collision tests between two primitives that move linearly over a
/// step t in [0,1]: x(t) = (1-t) x0 + t x1. Conservative in floating point: a contact that
/// exact arithmetic finds is never missed, and the reported time of impact is never later
/// than the true first contact. Thread-safe, allocation-free.

#include <array>
#include <cstdint>

namespace tetseg {

using Vec3d = std::array<double, 3>;

struct CcdOptions {
  /// Minimum separation in length units: contacts are reported when the primitives come
  /// within this distance. 0 = exact contact.
  double min_separation = 0.0;
};

enum class CcdOutcome : std::uint8_t {
  kNoContact = 0,
  kContact,         ///< contact at toi in (0,1]
  kContactAtStart,  ///< touching (within min_separation) at t = 0
};

struct CcdResult {
  CcdOutcome outcome = CcdOutcome::kNoContact;
  double toi = 1.0;  ///< lower bound on the first contact time, in [0,1]; valid on contact
  bool hit() const noexcept { return outcome != CcdOutcome::kNoContact; }
};

/// Vertex p against triangle (a,b,c); suffix 0 = start of step, 1 = end.
CcdResult vertex_face_ccd(const Vec3d& p0, const Vec3d& a0, const Vec3d& b0, const Vec3d& c0,
                          const Vec3d& p1, const Vec3d& a1, const Vec3d& b1, const Vec3d& c1,
                          const CcdOptions& options = {}) noexcept;

/// Edge (a,b) against edge (c,d).
CcdResult edge_edge_ccd(const Vec3d& a0, const Vec3d& b0, const Vec3d& c0, const Vec3d& d0,
                        const Vec3d& a1, const Vec3d& b1, const Vec3d& c1, const Vec3d& d1,
                        const CcdOptions& options = {}) noexcept;

}  // namespace tetseg
