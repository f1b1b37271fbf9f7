#include "payload.hpp"

#include <cereal/archives/portable_binary.hpp>

#include <cstddef>
#include <cstring>
#include <istream>
#include <limits>
#include <ostream>
#include <stdexcept>
#include <streambuf>
#include <type_traits>

namespace tetseg::format::detail {
namespace {

static_assert(sizeof(Triangle) == 3 * sizeof(std::uint32_t), "Triangle must be packed");
static_assert(sizeof(std::array<double, 3>) == 3 * sizeof(double), "position must be packed");
// BVH nodes and boundary loops are stored as runs of u32, in member order.
static_assert(std::is_trivially_copyable<BvhNode>::value && sizeof(BvhNode) == 12 &&
                  offsetof(BvhNode, first) == 0 && offsetof(BvhNode, second) == 4 &&
                  offsetof(BvhNode, count) == 8,
              "BvhNode must be three packed u32");
static_assert(std::is_trivially_copyable<BoundaryLoop>::value && sizeof(BoundaryLoop) == 8 &&
                  offsetof(BoundaryLoop, node_offset) == 0 &&
                  offsetof(BoundaryLoop, node_count) == 4,
              "BoundaryLoop must be two packed u32");
static_assert(std::numeric_limits<float>::is_iec559 && std::numeric_limits<double>::is_iec559,
              "the payload stores IEEE 754 floats");

/// The first payload byte written by cereal's PortableBinary archive: 1 = little-endian.
constexpr std::uint8_t kLittleEndianTag = 1;

/// Appends everything written to a byte vector.
class VectorSink final : public std::streambuf {
 public:
  explicit VectorSink(std::vector<std::uint8_t>& out) : m_out(out) {}

 protected:
  int_type overflow(int_type c) override {
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      m_out.push_back(static_cast<std::uint8_t>(traits_type::to_char_type(c)));
    }
    return traits_type::not_eof(c);
  }
  std::streamsize xsputn(const char* s, std::streamsize n) override {
    const auto* bytes = reinterpret_cast<const std::uint8_t*>(s);
    m_out.insert(m_out.end(), bytes, bytes + n);
    return n;
  }

 private:
  std::vector<std::uint8_t>& m_out;
};

/// Reads from a caller-owned byte range without copying it; knows how many bytes remain.
class MemorySource final : public std::streambuf {
 public:
  MemorySource(const std::uint8_t* data, std::size_t size) {
    // The get area is never written through: std::streambuf only wants non-const pointers.
    char* begin = const_cast<char*>(reinterpret_cast<const char*>(data));
    setg(begin, begin, begin + size);
  }
  std::size_t remaining() const { return static_cast<std::size_t>(egptr() - gptr()); }
};

/// The payload does not decode (truncated, trailing bytes, bad tag).
struct DecodeError : std::runtime_error {
  using std::runtime_error::runtime_error;
};
/// A count in the payload exceeds a documented limit.
struct LimitError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

class Encoder {
 public:
  explicit Encoder(std::vector<std::uint8_t>& out)
      : m_sink(out),
        m_stream(&m_sink),
        m_ar(m_stream, cereal::PortableBinaryOutputArchive::Options::LittleEndian()) {}

  template <class T>
  void scalar(T value) {
    static_assert(std::is_arithmetic<T>::value, "scalars only");
    m_ar(value);
  }
  void count(std::size_t n) { scalar(static_cast<std::uint64_t>(n)); }
  template <class T>
  void array(const T* data, std::size_t n) {
    if (n > 0) m_ar(cereal::binary_data(data, n * sizeof(T)));
  }
  void string(const std::string& s) {
    count(s.size());
    array(s.data(), s.size());
  }

 private:
  VectorSink m_sink;
  std::ostream m_stream;
  cereal::PortableBinaryOutputArchive m_ar;
};

class Decoder {
 public:
  Decoder(const std::uint8_t* data, std::size_t size)
      : m_source(data, size),
        m_stream(&m_source),
        m_ar(m_stream, cereal::PortableBinaryInputArchive::Options::LittleEndian()) {}

  template <class T>
  T scalar() {
    static_assert(std::is_arithmetic<T>::value, "scalars only");
    T value{};
    m_ar(value);
    return value;
  }

  /// Reads a size tag and checks it against the bytes that remain (each element needs at
  /// least `min_element_bytes`) and then against `limit`. Nothing is allocated here.
  std::size_t count(const char* what, std::uint64_t limit, std::size_t min_element_bytes) {
    const auto n = scalar<std::uint64_t>();
    const std::size_t left = m_source.remaining();
    if (n > left / min_element_bytes) {
      throw DecodeError(std::string(what) + ": size " + std::to_string(n) + " needs at least " +
                        (n > std::numeric_limits<std::uint64_t>::max() / min_element_bytes
                             ? std::string("more than 2^64")
                             : std::to_string(n * min_element_bytes)) +
                        " bytes but only " + std::to_string(left) + " remain");
    }
    if (n > limit) {
      throw LimitError(std::string(what) + ": size " + std::to_string(n) + " exceeds the limit " +
                       std::to_string(limit));
    }
    return static_cast<std::size_t>(n);
  }

  template <class T>
  void array(T* data, std::size_t n) {
    if (n > 0) m_ar(cereal::binary_data(data, n * sizeof(T)));
  }

  void string(const char* what, std::string& s) {
    const std::size_t n = count(what, kMaxStringBytes, 1);
    s.resize(n);
    array(s.data(), n);
  }

  std::size_t remaining() const { return m_source.remaining(); }

 private:
  MemorySource m_source;
  std::istream m_stream;
  cereal::PortableBinaryInputArchive m_ar;
};

/// Vectors of u32 or of records made only of u32 members (checked by the static_asserts).
template <class T>
void decode_u32_vector(Decoder& d, const char* what, std::uint64_t limit, std::vector<T>& v) {
  static_assert(sizeof(T) % sizeof(std::uint32_t) == 0, "u32 records only");
  const std::size_t n = d.count(what, limit, sizeof(T));
  v.resize(n);
  if (n > 0) d.array(reinterpret_cast<std::uint32_t*>(v.data()), n * (sizeof(T) / 4));
}

/// Bytes of one cluster record: 1.0 stores the detector node, 1.1 the detector point (four
/// node ids, four weights, the tet id) and the flags, 1.2 also the detector's term range and
/// rest position.
constexpr std::size_t cluster_record_bytes(std::uint16_t minor) {
  return minor == 0 ? 24 : minor == 1 ? 76 : 108;
}

/// Bytes of one detector term (u32 index, f64 weight).
constexpr std::size_t kDetectorTermBytes = 12;
/// Largest detector_terms count: every cluster with the most terms.
constexpr std::uint64_t kMaxDetectorTermsTotal = std::uint64_t(kMaxClusters) * kMaxDetectorTerms;

}  // namespace

std::size_t payload_bytes(const Asset& a, std::uint16_t minor) {
  std::size_t n = 1 + 4 + 8 * 11;
  if (minor >= 2) {
    n += 8 + 8 + 8 + kDetectorTermBytes * a.detector_terms.size();
    n += 8 + 4 * a.source_vertex_nodes.size();
    for (const std::string& name : a.bone_names) n += 8 + name.size();
  }
  n += 24 * a.rest_positions.size() + 12 * a.triangles.size() + 4 * a.triangle_cluster.size();
  n += cluster_record_bytes(minor) * a.clusters.size() + 4 * a.cluster_triangles.size() +
       12 * a.bvh_nodes.size();
  n += 8 * a.boundaries.size() + 4 * a.boundary_nodes.size();
  n += a.provenance.tool_version.size() + a.provenance.source.size();
  for (const auto& [key, value] : a.provenance.options) n += 16 + key.size() + value.size();
  return n;
}

void encode_payload(const Asset& a, std::uint16_t minor, std::vector<std::uint8_t>& out) {
  out.reserve(out.size() + payload_bytes(a, minor));
  Encoder e(out);  // writes the little-endian tag byte
  e.scalar(a.node_count);
  if (minor >= 2) {
    e.scalar(static_cast<std::uint32_t>(a.body_kind));
    e.scalar(static_cast<std::uint32_t>(a.detector_form));
  }
  e.count(a.rest_positions.size());
  if (!a.rest_positions.empty())
    e.array(a.rest_positions.front().data(), 3 * a.rest_positions.size());
  e.count(a.triangles.size());
  if (!a.triangles.empty()) e.array(a.triangles.front().data(), 3 * a.triangles.size());
  e.count(a.triangle_cluster.size());
  e.array(a.triangle_cluster.data(), a.triangle_cluster.size());
  e.count(a.clusters.size());
  for (const Cluster& c : a.clusters) {
    if (minor == 0) {
      e.scalar(c.detector.nodes[0]);
    } else {
      for (std::uint32_t id : c.detector.nodes) e.scalar(id);
      for (double w : c.detector.weights) e.scalar(w);
      e.scalar(c.detector.tet);
      e.scalar(c.flags);
    }
    e.scalar(c.rest_positive_fraction);
    e.scalar(c.triangle_offset);
    e.scalar(c.triangle_count);
    e.scalar(c.bvh_offset);
    e.scalar(c.bvh_count);
    if (minor >= 2) {
      e.scalar(c.detector_term_offset);
      e.scalar(c.detector_term_count);
      for (double x : c.detector_rest) e.scalar(x);
    }
  }
  e.count(a.cluster_triangles.size());
  e.array(a.cluster_triangles.data(), a.cluster_triangles.size());
  e.count(a.bvh_nodes.size());
  e.array(reinterpret_cast<const std::uint32_t*>(a.bvh_nodes.data()), 3 * a.bvh_nodes.size());
  e.count(a.boundaries.size());
  e.array(reinterpret_cast<const std::uint32_t*>(a.boundaries.data()), 2 * a.boundaries.size());
  e.count(a.boundary_nodes.size());
  e.array(a.boundary_nodes.data(), a.boundary_nodes.size());
  if (minor >= 2) {
    e.count(a.detector_terms.size());
    for (const DetectorTerm& term : a.detector_terms) {
      e.scalar(term.index);
      e.scalar(term.weight);
    }
    e.count(a.bone_names.size());
    for (const std::string& name : a.bone_names) e.string(name);
    e.count(a.source_vertex_nodes.size());
    e.array(a.source_vertex_nodes.data(), a.source_vertex_nodes.size());
  }
  e.string(a.provenance.tool_version);
  e.string(a.provenance.source);
  e.count(a.provenance.options.size());
  for (const auto& [key, value] : a.provenance.options) {
    e.string(key);
    e.string(value);
  }
}

Status decode_payload(const std::uint8_t* data, std::size_t size, std::uint16_t minor, Asset& a,
                      std::string& detail) noexcept {
  try {
    if (size == 0) {
      detail = "payload is empty";
      return Status::kDecodeFailed;
    }
    if (data[0] != kLittleEndianTag) {
      detail = "payload byte 0 is " + std::to_string(data[0]) + ", expected 1 (little-endian)";
      return Status::kDecodeFailed;
    }
    Decoder d(data, size);
    a.node_count = d.scalar<std::uint32_t>();
    if (minor >= 2) {
      // Any value decodes; validation judges unknown kinds and forms.
      a.body_kind = static_cast<BodyKind>(d.scalar<std::uint32_t>());
      a.detector_form = static_cast<DetectorForm>(d.scalar<std::uint32_t>());
    }
    {
      const std::size_t n = d.count("rest_positions", kMaxNodes, 3 * sizeof(double));
      a.rest_positions.resize(n);
      if (n > 0) d.array(a.rest_positions.front().data(), 3 * n);
    }
    {
      const std::size_t n = d.count("triangles", kMaxTriangles, sizeof(Triangle));
      a.triangles.resize(n);
      if (n > 0) d.array(a.triangles.front().data(), 3 * n);
    }
    decode_u32_vector(d, "triangle_cluster", kMaxTriangles, a.triangle_cluster);
    {
      const std::size_t n = d.count("clusters", kMaxClusters, cluster_record_bytes(minor));
      a.clusters.resize(n);
      for (Cluster& c : a.clusters) {
        if (minor == 0) {
          c.detector = DetectorPoint::at_node(d.scalar<std::uint32_t>());
        } else {
          for (std::uint32_t& id : c.detector.nodes) id = d.scalar<std::uint32_t>();
          for (double& w : c.detector.weights) w = d.scalar<double>();
          c.detector.tet = d.scalar<std::uint32_t>();
          c.flags = d.scalar<std::uint32_t>();
        }
        c.rest_positive_fraction = d.scalar<float>();
        c.triangle_offset = d.scalar<std::uint32_t>();
        c.triangle_count = d.scalar<std::uint32_t>();
        c.bvh_offset = d.scalar<std::uint32_t>();
        c.bvh_count = d.scalar<std::uint32_t>();
        if (minor >= 2) {
          c.detector_term_offset = d.scalar<std::uint32_t>();
          c.detector_term_count = d.scalar<std::uint32_t>();
          for (double& x : c.detector_rest) x = d.scalar<double>();
        }
      }
    }
    decode_u32_vector(d, "cluster_triangles", kMaxTriangles, a.cluster_triangles);
    decode_u32_vector(d, "bvh_nodes", kMaxBvhNodes, a.bvh_nodes);
    decode_u32_vector(d, "boundaries", kMaxBoundaryLoops, a.boundaries);
    decode_u32_vector(d, "boundary_nodes", kMaxBoundaryNodes, a.boundary_nodes);
    if (minor >= 2) {
      const std::size_t terms =
          d.count("detector_terms", kMaxDetectorTermsTotal, kDetectorTermBytes);
      a.detector_terms.resize(terms);
      for (DetectorTerm& term : a.detector_terms) {
        term.index = d.scalar<std::uint32_t>();
        term.weight = d.scalar<double>();
      }
      // Each name is at least its 8-byte size tag.
      const std::size_t bones = d.count("bone_names", kMaxBones, 8);
      a.bone_names.resize(bones);
      for (std::string& name : a.bone_names) d.string("bone name", name);
      decode_u32_vector(d, "source_vertex_nodes", kMaxSourceVertices, a.source_vertex_nodes);
    }
    d.string("provenance.tool_version", a.provenance.tool_version);
    d.string("provenance.source", a.provenance.source);
    {
      // Each option is at least two empty strings: two 8-byte size tags.
      const std::size_t n = d.count("provenance.options", kMaxProvenanceOptions, 16);
      a.provenance.options.resize(n);
      for (auto& [key, value] : a.provenance.options) {
        d.string("provenance option key", key);
        d.string("provenance option value", value);
      }
    }
    if (d.remaining() != 0) {
      detail = std::to_string(d.remaining()) + " trailing bytes after the last payload field";
      return Status::kDecodeFailed;
    }
    return Status::kOk;
  } catch (const LimitError& e) {
    try {
      detail = e.what();
    } catch (...) {
    }
    return Status::kInvalidContent;
  } catch (const std::exception& e) {
    // cereal::Exception (truncated input), DecodeError, std::bad_alloc, ...
    try {
      detail = e.what();
    } catch (...) {
    }
    return Status::kDecodeFailed;
  } catch (...) {
    return Status::kDecodeFailed;
  }
}

}  // namespace tetseg::format::detail
