#pragma once
// Private helpers of the text mesh readers and writers (not installed): a tokenizer that keeps
// line numbers, strict number parsing, and a buffered writer. Errors are InputError with
// "line N: ..." messages.

#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "tetseg/preprocess/mesh.hpp"

namespace tetseg::preprocess::detail {

/// Reads a whole file into memory. Throws InputError when it cannot be opened or read.
std::string read_file_text(const std::string& path);

/// A whitespace tokenizer over a text buffer that tracks line numbers. Comments starting with
/// `comment` (when not '\0') run to the end of the line.
class Tokenizer {
 public:
  Tokenizer(std::string file, std::string_view text, char comment);

  /// Next token; throws "line N: unexpected end of file (<what>)" when there is none.
  std::string_view next(const char* what);
  /// Next token or an empty view at the end of the input.
  std::string_view next_or_end();
  /// Tokens left on the current line (after the last token returned), consumed.
  std::vector<std::string_view> rest_of_line();
  /// The same into `tokens` (cleared first; its capacity is reused).
  void rest_of_line(std::vector<std::string_view>& tokens);
  /// Whether only whitespace and comments remain.
  bool at_end();
  /// Line of the last token returned (1-based).
  std::size_t line() const { return m_token_line; }
  /// Byte offset of the read position (just after the last token returned).
  std::size_t position() const { return m_pos; }
  /// Line the read position is on.
  std::size_t current_line() const { return m_line; }
  /// The next line holding a token, split into tokens; false at the end of the input. `line`
  /// receives its number.
  bool next_record(std::vector<std::string_view>& tokens, std::size_t& line);
  const std::string& file() const { return m_file; }

  double next_double(const char* what);
  std::int64_t next_int(const char* what);

  [[noreturn]] void fail(const std::string& message) const;
  [[noreturn]] void fail_at(std::size_t line, const std::string& message) const;

 private:
  void skip_space(bool stop_at_newline);

  std::string m_file;
  std::string_view m_text;
  char m_comment;
  std::size_t m_pos = 0;
  std::size_t m_line = 1;
  std::size_t m_token_line = 1;
};

/// The vertices and polygons of a plain ASCII OFF file: the keyword "OFF" alone on its line,
/// the three counts on the next, one vertex of exactly three numbers per line, one face per
/// line (tokens after its corners, a colour, ignored), '#' comments. Numbers are read as CGAL's
/// stream reader reads them (std::from_chars, a leading '+' allowed). False, with both
/// outputs empty, for anything else (other OFF variants, other layouts, a bad number or index,
/// trailing content): read_triangle_mesh then leaves the file to CGAL's reader.
bool read_plain_off(const std::string& text, std::vector<Vec3>& points,
                    std::vector<std::vector<std::size_t>>& polygons);

/// Strict parsers: the whole token must be a number. Return false otherwise.
bool parse_double(std::string_view token, double& value);
bool parse_int(std::string_view token, std::int64_t& value);

/// Appends the shortest decimal form of `value` that reads back exactly.
void append_double(std::string& out, double value);
void append_uint(std::string& out, std::uint64_t value);
/// Appends "x y z" (append_double each, single spaces, nothing before or after).
void append_point(std::string& out, const Vec3& p);

/// Smallest and largest coordinates of `points` ({0,0,0} twice when empty): the Gmsh
/// writers' volume entity.
std::pair<Vec3, Vec3> bounding_box(const std::vector<Vec3>& points);

/// Whether this machine stores the low byte of an integer first (binary readers swap bytes
/// of files written the other way).
bool host_is_little_endian();

/// Writes `text` to `path`; throws OutputError.
void write_text_file(const std::string& path, const std::string& text);

/// Lower-case extension with the dot, or "".
std::string lower_extension(const std::string& path);

/// If every tet with a nonzero volume is negatively oriented (a mirrored convention), swaps
/// two vertices of every tet. Mixed orientations are left for validation to report.
void orient_consistently_negative_meshes(TetMesh& mesh);

TetMesh read_medit(const std::string& path);
TetMesh read_tetgen(const std::string& path);
TetMesh read_gmsh(const std::string& path);
/// The binary part of a Gmsh file (io_gmsh_binary.cpp): `text` is the whole file, `start` the
/// offset just after the data-size field of $MeshFormat; `major` is 2 or 4, `data_size` the
/// header's size_t width (4 or 8; MSH 2 uses it for nothing but doubles are 8 bytes).
TetMesh read_gmsh_binary(const std::string& path, std::string_view text, std::size_t start,
                         int major, std::int64_t data_size);
void write_gmsh41_binary_impl(const std::string& path, const TetMesh& mesh);
void write_medit(const std::string& path, const TetMesh& mesh);
void write_tetgen(const std::string& path, const TetMesh& mesh);
void write_gmsh41(const std::string& path, const TetMesh& mesh);
void write_gmsh22_impl(const std::string& path, const TetMesh& mesh);

}  // namespace tetseg::preprocess::detail
