#pragma once
/// \file
/// Plain mesh types shared by every preprocessing stage. No CGAL, no Eigen: stages that need
/// them convert inside their own .cpp files.

#include <array>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace tetseg::preprocess {

using Vec3 = std::array<double, 3>;
using Tri = std::array<std::uint32_t, 3>;
using Tet = std::array<std::uint32_t, 4>;

/// A tetrahedral mesh. Tets are positively oriented: det[b-a, c-a, d-a] > 0.
struct TetMesh {
  std::vector<Vec3> nodes;
  std::vector<Tet> tets;
};

/// A triangle surface (as read from OBJ/PLY/STL/OFF/..., or generated). Not necessarily a
/// tet mesh's boundary.
struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<Tri> triangles;
};

/// The boundary of a tet mesh: faces of exactly one tet, wound outward ((b-a)x(c-a) points
/// out of the solid), in tet-mesh node ids.
struct Surface {
  std::vector<Tri> triangles;                 ///< tet-mesh node ids
  std::vector<std::uint32_t> surface_nodes;   ///< sorted node ids used by triangles
  std::vector<std::uint32_t> interior_nodes;  ///< sorted node ids not on the surface
};

/// Bad input: a file that cannot be read, is malformed, or describes an invalid mesh. The CLI
/// maps it to exit code 3 and prints `tetseg: error: <file>: <message>`.
class InputError : public std::runtime_error {
 public:
  InputError(std::string file, const std::string& message)
      : std::runtime_error(message), m_file(std::move(file)) {}
  const std::string& file() const noexcept { return m_file; }

 private:
  std::string m_file;
};

/// A job that ran past its time limit (`--time-limit`; the CLI's exit code 5): the message
/// names the stage. An InputError, since the input's geometry decides how long a stage runs.
class TimeLimitExceeded : public InputError {
 public:
  using InputError::InputError;
};

/// Output that could not be written (exit code 4).
class OutputError : public std::runtime_error {
 public:
  OutputError(std::string file, const std::string& message)
      : std::runtime_error(message), m_file(std::move(file)) {}
  const std::string& file() const noexcept { return m_file; }

 private:
  std::string m_file;
};

}  // namespace tetseg::preprocess
