#pragma once
/// \file
/// The tools' one mesh I/O layer: readers of PLY (ASCII, binary little and big endian), OBJ
/// and MEDIT vertex positions, and writers of VTK XML (.vtu) and ASCII PLY text. Errors are
/// values (IoStatus), never exceptions or exit codes: callers name the file and choose how to
/// fail. Depends on the C++ standard library only. Safe on hostile input: counts are checked
/// against the file size before anything is allocated.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace tetseg::io {

/// Empty `error` on success; otherwise what is wrong, without the file name.
struct IoStatus {
  std::string error;
  bool ok() const { return error.empty(); }
};

using Point = std::array<double, 3>;

/// One scalar (non-list) property of a PLY element: a value per element, and whether the
/// file stores it as a floating-point type.
struct PlyProperty {
  std::string name;
  bool floating = false;
  std::vector<double> values;
};

/// What a PLY file holds: the vertex positions, the faces as index lists (any length) and the
/// faces' scalar properties. Other elements and vertex properties are read and dropped.
struct PlyMesh {
  std::vector<Point> vertices;
  std::vector<std::vector<std::uint32_t>> faces;
  std::vector<PlyProperty> face_properties;
  /// The face property called `name`, or nullptr.
  const PlyProperty* face_property(const std::string& name) const;
};

/// Reads a PLY file: vertex x, y, z of any numeric type (required when there are vertices);
/// faces from a `vertex_indices` (or `vertex_index`) list. Checks that coordinates are finite
/// and face indices refer to vertices. Errors start with "PLY: ".
IoStatus read_ply(const std::string& path, PlyMesh& mesh);

/// Vertex positions, xyz per vertex in file order, of a Wavefront .obj ("v" lines), .ply or
/// MEDIT .mesh ("Vertices" section) file, by extension. Connectivity is ignored. Refuses
/// non-finite coordinates and files without vertices.
IoStatus read_vertex_positions(const std::string& path, std::vector<double>& xyz);

/// A named array of the points or cells of an unstructured grid; `type` is a VTK type name
/// (Float64, Float32, Int32, UInt32, UInt8): integer types are written as integers, floating
/// ones with 9 significant digits.
struct DataArray {
  std::string name;
  std::string type;
  std::vector<double> values;
};

/// A VTK unstructured grid: cells given by their VTK type (5 triangle, 4 poly-line, 1 vertex)
/// and point indices.
struct UnstructuredGrid {
  std::vector<Point> points;
  std::vector<std::uint8_t> cell_types;
  std::vector<std::vector<std::uint32_t>> cells;
  std::vector<DataArray> point_data;
  std::vector<DataArray> cell_data;  ///< the first is the active scalar
};

/// VTK XML UnstructuredGrid, ASCII. Deterministic.
std::string vtu_text(const UnstructuredGrid& grid);

/// A PLY property to write: a value per element; `type` a PLY type name (uchar, int,
/// double, ...), integer types written as integers, floating ones with 9 significant digits.
struct PlyOutProperty {
  std::string name;
  std::string type;
  std::vector<double> values;
};

/// What ply_text writes: vertices (x, y, z doubles), triangles (`vertex_indices`) with face
/// properties, and optionally edges (`vertex1`, `vertex2`) with edge properties.
struct PlyOutMesh {
  std::string comment;
  std::vector<Point> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  std::vector<PlyOutProperty> face_properties;
  std::vector<std::array<std::uint32_t, 2>> edges;  ///< written when not empty
  std::vector<PlyOutProperty> edge_properties;
};

/// ASCII PLY. Deterministic.
std::string ply_text(const PlyOutMesh& mesh);

}  // namespace tetseg::io
