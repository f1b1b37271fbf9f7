#pragma once
// A generated skinned test character: a closed tube (capped cylinder along +x) carried by a
// chain of bones, with smooth linear-blend-skinning weights; poses that bend it at the joints
// (about z) until it touches itself; the glTF 2.0 file (with its skin) that describes it.
// Header-only, no dependencies: used by tetseg-character, the skin tests and the skinned
// benchmark (docs/benchmarks.md, "Skinned character").
//
// Rest vertices and weights are float32 values (what glTF stores), held as doubles, so the
// glTF file reads back with exactly these vertices and weights; everything computed from them
// (bone matrices, skinned positions) is double.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <string>
#include <vector>

namespace tetseg::test {

/// A row-major 3x4 affine matrix: (R | t), applied as R p + t.
using Affine = std::array<double, 12>;

inline Affine affine_identity() {
  return {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};
}

/// a * b (apply b first).
inline Affine affine_multiply(const Affine& a, const Affine& b) {
  Affine out{};
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      double sum = (c == 3) ? a[4 * r + 3] : 0.0;
      for (int k = 0; k < 3; ++k) sum += a[4 * r + k] * b[4 * k + c];
      out[4 * r + c] = sum;
    }
  }
  return out;
}

inline Affine affine_translation(double x, double y, double z) {
  return {1, 0, 0, x, 0, 1, 0, y, 0, 0, 1, z};
}

/// Rotation by `angle` radians about the z axis.
inline Affine affine_rotation_z(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c, -s, 0, 0, s, c, 0, 0, 0, 0, 1, 0};
}

/// Rotation by `angle` radians about the y axis.
inline Affine affine_rotation_y(double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  return {c, 0, s, 0, 0, 1, 0, 0, -s, 0, c, 0};
}

/// m p.
inline std::array<double, 3> affine_apply(const Affine& m, const double* p) {
  std::array<double, 3> out{};
  for (int r = 0; r < 3; ++r)
    out[r] = m[4 * r] * p[0] + m[4 * r + 1] * p[1] + m[4 * r + 2] * p[2] + m[4 * r + 3];
  return out;
}

/// One bone's influence on a vertex.
struct BoneWeight {
  std::uint32_t bone = 0;
  double weight = 0.0;  ///< > 0; a vertex's weights sum to 1 within float rounding
};

struct SkinnedTubeOptions {
  std::uint32_t bones = 4;            ///< bones along the tube, >= 1
  double bone_length = 1.0;           ///< length of each bone along x
  double radius = 0.25;               ///< tube radius; caps are hemispheres
  std::uint32_t around = 24;          ///< vertices per ring, >= 3
  std::uint32_t rings_per_bone = 12;  ///< rings per bone along the cylinder, >= 1
  std::uint32_t cap_rings = 4;        ///< rings of each hemispherical cap (pole excluded), >= 1
  double blend = 0.35;  ///< half-width of the weight blend at a joint, / bone_length, in (0, 0.5)
  /// The tube narrows at each joint to (1 - joint_pinch) x radius (a Gaussian of width
  /// 0.15 bone lengths), a concave neck like a limb's joint; 0: a plain capsule. In [0, 1).
  double joint_pinch = 0.3;
};

/// The tube at rest (bind pose), a capsule narrowed at the joints: bone b spans x in [b, b+1] *
/// bone_length, its joint (origin) at x = b * bone_length; bone b's parent is b - 1. Each vertex
/// has one or two bones (the two beside its nearest joint, smoothly blended within `blend` of the
/// joint).
struct SkinnedTube {
  SkinnedTubeOptions options;
  std::vector<double> rest;                             ///< vertex_count * 3 (float32 values)
  std::vector<std::array<std::uint32_t, 3>> triangles;  ///< closed, outward winding
  std::vector<std::vector<BoneWeight>> weights;         ///< per vertex (float32 values, sum 1)
  std::vector<std::string> bone_names;                  ///< "bone0", "bone1", ...
  std::size_t vertex_count() const { return rest.size() / 3; }
  /// Bone b's inverse bind matrix (a translation by -b * bone_length along x).
  Affine inverse_bind(std::uint32_t b) const {
    return affine_translation(-double(b) * options.bone_length, 0, 0);
  }
};

inline SkinnedTube make_skinned_tube(const SkinnedTubeOptions& options = {}) {
  SkinnedTube tube;
  tube.options = options;
  const double r = options.radius, s = options.bone_length;
  const double length = s * options.bones;
  // Profile (x, ring radius) from the -x pole to the +x pole, poles excluded.
  std::vector<std::array<double, 2>> profile;
  for (std::uint32_t k = 1; k <= options.cap_rings; ++k) {
    const double phi = 0.5 * M_PI * k / options.cap_rings;  // 0 at the pole
    profile.push_back({-r * std::cos(phi), r * std::sin(phi)});
  }
  const std::uint32_t body_rings = options.bones * options.rings_per_bone;
  for (std::uint32_t j = 1; j < body_rings; ++j) {
    const double x = length * j / body_rings;
    double narrowing = 0;
    for (std::uint32_t b = 1; b < options.bones; ++b) {
      const double d = (x - b * s) / (0.15 * s);
      narrowing = std::max(narrowing, options.joint_pinch * std::exp(-d * d));
    }
    profile.push_back({x, r * (1 - narrowing)});
  }
  for (std::uint32_t k = options.cap_rings; k >= 1; --k) {
    const double phi = 0.5 * M_PI * k / options.cap_rings;
    profile.push_back({length + r * std::cos(phi), r * std::sin(phi)});
  }
  // float32 values; cos(pi/2) and the like become exact zeros (so that a tube with 4 or 8
  // vertices per ring and one cap ring has coordinates that print exactly).
  auto add_vertex = [&](double x, double y, double z) {
    for (double v : {x, y, z}) tube.rest.push_back(std::fabs(v) < 1e-12 ? 0.0 : double(float(v)));
  };
  add_vertex(-r, 0, 0);
  for (const auto& [x, ring_radius] : profile) {
    for (std::uint32_t j = 0; j < options.around; ++j) {
      const double a = 2 * M_PI * j / options.around;
      add_vertex(x, ring_radius * std::cos(a), ring_radius * std::sin(a));
    }
  }
  add_vertex(length + r, 0, 0);
  const std::uint32_t rings = static_cast<std::uint32_t>(profile.size());
  const std::uint32_t n = options.around;
  const std::uint32_t last = 1 + rings * n;
  auto at = [&](std::uint32_t ring, std::uint32_t j) { return 1 + ring * n + j % n; };
  // Wound outward: seen from -x the first fan turns clockwise (a grows from +y towards +z).
  for (std::uint32_t j = 0; j < n; ++j) tube.triangles.push_back({0, at(0, j + 1), at(0, j)});
  for (std::uint32_t i = 0; i + 1 < rings; ++i) {
    for (std::uint32_t j = 0; j < n; ++j) {
      tube.triangles.push_back({at(i, j), at(i, j + 1), at(i + 1, j + 1)});
      tube.triangles.push_back({at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    }
  }
  for (std::uint32_t j = 0; j < n; ++j)
    tube.triangles.push_back({last, at(rings - 1, j), at(rings - 1, j + 1)});

  // Renumber the vertices in order of first use by the triangles, so that readers which
  // number vertices that way (tetseg's surface readers) and readers which keep the file's
  // order agree.
  std::vector<std::uint32_t> new_id(tube.vertex_count(), UINT32_MAX);
  std::vector<double> renumbered;
  for (auto& t : tube.triangles) {
    for (std::uint32_t& v : t) {
      if (new_id[v] == UINT32_MAX) {
        new_id[v] = static_cast<std::uint32_t>(renumbered.size() / 3);
        renumbered.insert(renumbered.end(), &tube.rest[3 * v], &tube.rest[3 * v] + 3);
      }
      v = new_id[v];
    }
  }
  tube.rest = std::move(renumbered);

  const double w = options.blend * s;
  for (std::size_t v = 0; v < tube.vertex_count(); ++v) {
    const double x = tube.rest[3 * v];
    std::vector<BoneWeight> vw;
    if (options.bones == 1) {
      vw.push_back({0, 1.0});
    } else {
      const double nearest = std::round(x / s);
      const auto joint = static_cast<std::uint32_t>(
          std::clamp(nearest, 1.0, double(options.bones - 1)));  // between bones joint-1, joint
      const double u = std::clamp((x - joint * s + w) / (2 * w), 0.0, 1.0);
      // Smoothstep, rounded to a multiple of 2^-20: t and 1 - t are both exact float32
      // values, so the weights (as glTF stores them) sum to 1 exactly.
      const double t = std::round(u * u * (3 - 2 * u) * 1048576.0) / 1048576.0;
      if (t < 1) vw.push_back({joint - 1, 1.0 - t});
      if (t > 0) vw.push_back({joint, t});
    }
    tube.weights.push_back(vw);
  }
  for (std::uint32_t b = 0; b < options.bones; ++b)
    tube.bone_names.push_back("bone" + std::to_string(b));
  return tube;
}

/// Skinning matrices (bone world transform times inverse bind matrix) of the pose in which
/// bone b turns by `angles_z[b]` about z at its joint (relative to its parent; bone 0 about the
/// origin), then by `angles_y[b]` about y (empty: none). Identity angles give identities.
inline std::vector<Affine> tube_skinning_matrices(const SkinnedTube& tube,
                                                  const std::vector<double>& angles_z,
                                                  const std::vector<double>& angles_y = {}) {
  std::vector<Affine> out;
  Affine world = affine_identity();
  for (std::uint32_t b = 0; b < tube.options.bones; ++b) {
    const Affine local =
        affine_multiply(affine_translation(b == 0 ? 0.0 : tube.options.bone_length, 0, 0),
                        affine_multiply(affine_rotation_z(angles_z.at(b)),
                                        affine_rotation_y(angles_y.empty() ? 0.0 : angles_y[b])));
    world = affine_multiply(world, local);
    out.push_back(affine_multiply(world, tube.inverse_bind(b)));
  }
  return out;
}

/// The tube as a game engine's vertex buffer holds it: split at seams. Every `stride`-th vertex
/// (from vertex 1) is stored twice, the copy right after it, with the same position and
/// weights, and every odd-numbered triangle that uses it uses the copy, as a UV or normal seam
/// splits a fan. Merged by position it is the original tube; `original_vertex[v]` is the tube
/// vertex that file vertex v stands for.
struct SplitTube {
  SkinnedTube tube;
  std::vector<std::uint32_t> original_vertex;
};
inline SplitTube split_tube_vertices(const SkinnedTube& tube, std::uint32_t stride = 5) {
  SplitTube out{tube, {}};
  out.tube.rest.clear();
  out.tube.weights.clear();
  const auto n = static_cast<std::uint32_t>(tube.vertex_count());
  std::vector<std::uint32_t> first(n), copy(n, UINT32_MAX);
  auto emit = [&](std::uint32_t v) {
    const auto id = static_cast<std::uint32_t>(out.original_vertex.size());
    out.original_vertex.push_back(v);
    out.tube.rest.insert(out.tube.rest.end(), &tube.rest[3 * v], &tube.rest[3 * v] + 3);
    out.tube.weights.push_back(tube.weights[v]);
    return id;
  };
  for (std::uint32_t v = 0; v < n; ++v) {
    first[v] = emit(v);
    if (v % stride == 1) copy[v] = emit(v);
  }
  for (std::size_t t = 0; t < out.tube.triangles.size(); ++t)
    for (std::uint32_t& v : out.tube.triangles[t])
      v = (t % 2 == 1 && copy[v] != UINT32_MAX) ? copy[v] : first[v];
  return out;
}

/// Linear blend skinning of the rest vertices: per vertex `sum weight * (M_bone * rest)`, in
/// the vertex's weight order, in double. Returns vertex_count * 3.
inline std::vector<double> skin_tube(const SkinnedTube& tube, const std::vector<Affine>& matrices) {
  std::vector<double> out(tube.rest.size(), 0.0);
  for (std::size_t v = 0; v < tube.vertex_count(); ++v) {
    for (const BoneWeight& bw : tube.weights[v]) {
      const auto p = affine_apply(matrices.at(bw.bone), &tube.rest[3 * v]);
      for (int k = 0; k < 3; ++k) out[3 * v + k] += bw.weight * p[k];
    }
  }
  return out;
}

/// The bending sequence: `frames` poses (>= 2), frame 0 the rest pose; every joint turns
/// about z by max_angle * f / (frames - 1), and (when `wobble` != 0) by
/// wobble * sin(pi f / (frames - 1)) about y, so the curl is not planar. With 4 bones and a
/// max_angle of 90 degrees the tip comes back onto the root: the tube touches itself from
/// about 70 degrees on. Per frame, the bones' skinning matrices.
inline std::vector<std::vector<Affine>> tube_bend_sequence(const SkinnedTube& tube,
                                                           std::uint32_t frames, double max_angle,
                                                           double wobble = 0.0) {
  std::vector<std::vector<Affine>> out;
  for (std::uint32_t f = 0; f < frames; ++f) {
    const double t = frames > 1 ? double(f) / (frames - 1) : 0.0;
    std::vector<double> az(tube.options.bones, max_angle * t), ay(tube.options.bones, 0.0);
    az[0] = 0;
    for (std::uint32_t b = 1; b < tube.options.bones; ++b)
      ay[b] = wobble * std::sin(M_PI * t) * ((b % 2) ? 1.0 : -1.0);
    out.push_back(tube_skinning_matrices(tube, az, ay));
  }
  return out;
}

namespace detail {
inline std::string base64(const std::vector<std::uint8_t>& bytes) {
  static const char* table = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (std::size_t i = 0; i < bytes.size(); i += 3) {
    const std::uint32_t b0 = bytes[i];
    const std::uint32_t b1 = i + 1 < bytes.size() ? bytes[i + 1] : 0;
    const std::uint32_t b2 = i + 2 < bytes.size() ? bytes[i + 2] : 0;
    const std::uint32_t v = (b0 << 16) | (b1 << 8) | b2;
    out += table[(v >> 18) & 63];
    out += table[(v >> 12) & 63];
    out += i + 1 < bytes.size() ? table[(v >> 6) & 63] : '=';
    out += i + 2 < bytes.size() ? table[v & 63] : '=';
  }
  return out;
}
template <class T>
void append_bytes(std::vector<std::uint8_t>& out, T value) {
  std::uint8_t b[sizeof(T)];
  std::memcpy(b, &value, sizeof(T));  // little-endian hosts only (glTF is little-endian)
  out.insert(out.end(), b, b + sizeof(T));
}
}  // namespace detail

/// The tube as a self-contained glTF 2.0 file (.gltf, one base64 buffer): one mesh primitive
/// (POSITION float32, indices uint32, JOINTS_0 uint16 x4, WEIGHTS_0 float32 x4), the bone
/// chain as nodes bone0 -> bone1 -> ..., a skin with the inverse bind matrices, and a node
/// "tube" holding the skinned mesh. Deterministic.
inline std::string tube_gltf(const SkinnedTube& tube) {
  std::vector<std::uint8_t> buffer;
  const std::size_t nv = tube.vertex_count(), nt = tube.triangles.size();
  const std::uint32_t nb = tube.options.bones;
  std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (std::size_t v = 0; v < nv; ++v) {
    for (int k = 0; k < 3; ++k) {
      detail::append_bytes(buffer, float(tube.rest[3 * v + k]));
      lo[k] = std::min(lo[k], tube.rest[3 * v + k]);
      hi[k] = std::max(hi[k], tube.rest[3 * v + k]);
    }
  }
  const std::size_t indices_offset = buffer.size();
  for (const auto& t : tube.triangles)
    for (std::uint32_t i : t) detail::append_bytes(buffer, i);
  const std::size_t joints_offset = buffer.size();
  for (const auto& vw : tube.weights)
    for (std::size_t k = 0; k < 4; ++k)
      detail::append_bytes(buffer, std::uint16_t(k < vw.size() ? vw[k].bone : 0));
  const std::size_t weights_offset = buffer.size();
  for (const auto& vw : tube.weights)
    for (std::size_t k = 0; k < 4; ++k)
      detail::append_bytes(buffer, float(k < vw.size() ? vw[k].weight : 0.0));
  const std::size_t bind_offset = buffer.size();
  for (std::uint32_t b = 0; b < nb; ++b) {
    const Affine m = tube.inverse_bind(b);
    for (int c = 0; c < 4; ++c) {  // column-major 4x4
      for (int r = 0; r < 3; ++r) detail::append_bytes(buffer, float(m[4 * r + c]));
      detail::append_bytes(buffer, float(c == 3 ? 1 : 0));
    }
  }
  auto num = [](double v) {
    char text[64];
    std::snprintf(text, sizeof text, "%.9g", v);
    return std::string(text);
  };
  auto view = [&](std::size_t offset, std::size_t length) {
    return "{\"buffer\":0,\"byteOffset\":" + std::to_string(offset) +
           ",\"byteLength\":" + std::to_string(length) + "}";
  };
  std::string j = "{\"asset\":{\"version\":\"2.0\",\"generator\":\"tetseg-character\"},\n";
  j += "\"scene\":0,\"scenes\":[{\"nodes\":[0," + std::to_string(nb) + "]}],\n\"nodes\":[";
  for (std::uint32_t b = 0; b < nb; ++b) {
    j += "{\"name\":\"" + tube.bone_names[b] + "\"";
    if (b > 0) j += ",\"translation\":[" + num(tube.options.bone_length) + ",0,0]";
    if (b + 1 < nb) j += ",\"children\":[" + std::to_string(b + 1) + "]";
    j += "},";
  }
  j += "{\"name\":\"tube\",\"mesh\":0,\"skin\":0}],\n";
  j += "\"skins\":[{\"inverseBindMatrices\":4,\"skeleton\":0,\"joints\":[";
  for (std::uint32_t b = 0; b < nb; ++b) j += (b ? "," : "") + std::to_string(b);
  j += "]}],\n";
  j += "\"meshes\":[{\"name\":\"tube\",\"primitives\":[{\"attributes\":{\"POSITION\":0,"
       "\"JOINTS_0\":2,\"WEIGHTS_0\":3},\"indices\":1,\"mode\":4}]}],\n";
  j += "\"accessors\":[";
  j += "{\"bufferView\":0,\"componentType\":5126,\"count\":" + std::to_string(nv) +
       ",\"type\":\"VEC3\",\"min\":[" + num(lo[0]) + "," + num(lo[1]) + "," + num(lo[2]) +
       "],\"max\":[" + num(hi[0]) + "," + num(hi[1]) + "," + num(hi[2]) + "]},\n";
  j += "{\"bufferView\":1,\"componentType\":5125,\"count\":" + std::to_string(3 * nt) +
       ",\"type\":\"SCALAR\"},\n";
  j += "{\"bufferView\":2,\"componentType\":5123,\"count\":" + std::to_string(nv) +
       ",\"type\":\"VEC4\"},\n";
  j += "{\"bufferView\":3,\"componentType\":5126,\"count\":" + std::to_string(nv) +
       ",\"type\":\"VEC4\"},\n";
  j += "{\"bufferView\":4,\"componentType\":5126,\"count\":" + std::to_string(nb) +
       ",\"type\":\"MAT4\"}],\n";
  j += "\"bufferViews\":[" + view(0, indices_offset) + "," +
       view(indices_offset, joints_offset - indices_offset) + "," +
       view(joints_offset, weights_offset - joints_offset) + "," +
       view(weights_offset, bind_offset - weights_offset) + "," +
       view(bind_offset, buffer.size() - bind_offset) + "],\n";
  j += "\"buffers\":[{\"byteLength\":" + std::to_string(buffer.size()) +
       ",\"uri\":\"data:application/octet-stream;base64," + detail::base64(buffer) + "\"}]}\n";
  return j;
}

}  // namespace tetseg::test
