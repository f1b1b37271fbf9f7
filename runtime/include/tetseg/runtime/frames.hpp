#pragma once
/// \file
/// Frame-sequence files: the positions of all tet-mesh nodes at each frame of an animation
/// (docs/format.md, "Frame sequences"). Little-endian:
///
///     offset 0   8 bytes   magic "TSFRAMES"
///     offset 8   uint32    version (1)
///     offset 12  uint32    node_count  (1 .. format::kMaxNodes)
///     offset 16  uint32    frame_count (>= 1)
///     offset 20  uint32    reserved, 0
///     offset 24  float64   frame_count * node_count * 3 positions (frame-major, then node, xyz)
///
/// The file size must be exactly 24 + 24 * node_count * frame_count bytes.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace tetseg {

inline constexpr char kFramesMagic[8] = {'T', 'S', 'F', 'R', 'A', 'M', 'E', 'S'};
inline constexpr std::uint32_t kFramesVersion = 1;
inline constexpr std::size_t kFramesHeaderBytes = 24;

enum class FramesStatus : std::uint8_t {
  kOk = 0,
  kTooShort,            ///< fewer bytes than the header
  kBadMagic,            ///< not a frame-sequence file
  kUnsupportedVersion,  ///< version is not 1
  kBadHeader,           ///< zero or too many nodes, zero frames, or reserved != 0
  kSizeMismatch,        ///< payload size differs from the header's counts
  kNonFinite,           ///< a position is NaN or infinite
  kIoError,             ///< the file could not be opened, read or written
  kOutOfMemory,
};
/// Short stable name, never null.
const char* to_string(FramesStatus status) noexcept;

/// A decoded frame sequence. `positions` holds frame_count * node_count * 3 doubles.
struct FrameSequence {
  std::uint32_t node_count = 0;
  std::uint32_t frame_count = 0;
  std::vector<double> positions;
  /// Positions of frame `f` (node_count * 3 doubles); `f < frame_count` is the caller's job.
  const double* frame(std::size_t f) const noexcept {
    return positions.data() + f * std::size_t(node_count) * 3;
  }
};

/// Decodes `size` bytes. Safe on untrusted input: sizes are checked against the bytes
/// present before allocating; never throws. On failure `out` is empty and `detail`
/// (optional) explains in one line.
FramesStatus read_frames(const std::uint8_t* data, std::size_t size, FrameSequence& out,
                         std::string* detail = nullptr) noexcept;
/// Reads a whole file and decodes it; kIoError when it cannot be read.
FramesStatus read_frames_file(const std::string& path, FrameSequence& out,
                              std::string* detail = nullptr) noexcept;
/// Encodes `frames` (positions.size() must be frame_count * node_count * 3, else the result
/// is empty). Deterministic.
std::vector<std::uint8_t> write_frames(const FrameSequence& frames);

}  // namespace tetseg
