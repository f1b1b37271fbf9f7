#include "render.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include "tool_support.hpp"

namespace tetseg::tools {
namespace {

using V3 = std::array<double, 3>;

double dot(const V3& a, const V3& b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
V3 sub(const V3& a, const V3& b) {
  return {a[0] - b[0], a[1] - b[1], a[2] - b[2]};
}
V3 normalized(const V3& a) {
  const double n = std::sqrt(dot(a, a));
  return n > 0 ? V3{a[0] / n, a[1] / n, a[2] / n} : V3{0, 0, 0};
}

constexpr int kSuper = 2;  // supersampling factor per axis

struct Camera {
  V3 right, up, forward;
  double cx = 0, cy = 0, scale = 1;
  int width = 0, height = 0;  // supersampled
  // Screen position (pixels, y down) and depth (larger is farther).
  V3 project(const V3& p) const {
    return {(dot(p, right) - cx) * scale + width * 0.5, height * 0.5 - (dot(p, up) - cy) * scale,
            dot(p, forward)};
  }
};

void put_be32(std::vector<std::uint8_t>& out, std::uint32_t v) {
  out.push_back(static_cast<std::uint8_t>(v >> 24));
  out.push_back(static_cast<std::uint8_t>(v >> 16));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
  out.push_back(static_cast<std::uint8_t>(v));
}

void put_chunk(std::vector<std::uint8_t>& out, const char* type,
               const std::vector<std::uint8_t>& data) {
  put_be32(out, static_cast<std::uint32_t>(data.size()));
  const std::size_t start = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data.begin(), data.end());
  put_be32(out, crc32(out.data() + start, out.size() - start));
}

}  // namespace

std::uint32_t crc32(const std::uint8_t* data, std::size_t size, std::uint32_t crc) noexcept {
  static const auto table = [] {
    std::array<std::uint32_t, 256> t{};
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (std::size_t i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xFF] ^ (crc >> 8);
  return ~crc;
}

std::uint32_t adler32(const std::uint8_t* data, std::size_t size) noexcept {
  std::uint32_t a = 1, b = 0;
  for (std::size_t i = 0; i < size; ++i) {
    a = (a + data[i]) % 65521u;
    b = (b + a) % 65521u;
  }
  return (b << 16) | a;
}

namespace {

/// Deflate bit writer: bits go LSB first; Huffman codes are written most significant bit first.
class BitWriter {
 public:
  explicit BitWriter(std::vector<std::uint8_t>& out) : m_out(out) {}
  void bits(std::uint32_t value, int count) {
    for (int i = 0; i < count; ++i) {
      if (m_used == 0) m_out.push_back(0);
      m_out.back() |= static_cast<std::uint8_t>(((value >> i) & 1u) << m_used);
      m_used = (m_used + 1) & 7;
    }
  }
  void code(std::uint32_t value, int count) {
    for (int i = count - 1; i >= 0; --i) bits((value >> i) & 1u, 1);
  }

 private:
  std::vector<std::uint8_t>& m_out;
  int m_used = 0;
};

/// A literal/length symbol with the fixed Huffman code of RFC 1951, 3.2.6.
void fixed_symbol(BitWriter& w, std::uint32_t symbol) {
  if (symbol < 144)
    w.code(0x30 + symbol, 8);
  else if (symbol < 256)
    w.code(0x190 + symbol - 144, 9);
  else if (symbol < 280)
    w.code(symbol - 256, 7);
  else
    w.code(0xC0 + symbol - 280, 8);
}

/// One fixed-Huffman block: literals, and runs of the previous byte as (length, distance 1).
void deflate_fixed(const std::vector<std::uint8_t>& data, std::vector<std::uint8_t>& out) {
  static constexpr std::uint16_t kBase[29] = {3,  4,  5,  6,   7,   8,   9,   10,  11, 13,
                                              15, 17, 19, 23,  27,  31,  35,  43,  51, 59,
                                              67, 83, 99, 115, 131, 163, 195, 227, 258};
  static constexpr std::uint8_t kExtra[29] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2,
                                              2, 3, 3, 3, 3, 4, 4, 4, 4, 5, 5, 5, 5, 0};
  BitWriter w(out);
  w.bits(1, 1);  // final block
  w.bits(1, 2);  // fixed Huffman codes
  std::size_t i = 0;
  while (i < data.size()) {
    std::size_t run = 0;
    if (i > 0)
      while (run < 258 && i + run < data.size() && data[i + run] == data[i - 1]) ++run;
    if (run >= 3) {
      int k = 28;
      while (kBase[k] > run) --k;
      fixed_symbol(w, 257 + static_cast<std::uint32_t>(k));
      w.bits(static_cast<std::uint32_t>(run - kBase[k]), kExtra[k]);
      w.code(0, 5);  // distance code 0: distance 1
      i += run;
    } else {
      fixed_symbol(w, data[i]);
      ++i;
    }
  }
  fixed_symbol(w, 256);  // end of block
}

}  // namespace

std::vector<std::uint8_t> encode_png(const std::vector<std::uint8_t>& rgb, int width, int height,
                                     bool compress) {
  const std::size_t row = static_cast<std::size_t>(width) * 3;
  std::vector<std::uint8_t> raw;
  raw.reserve((row + 1) * static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    const std::uint8_t* line = rgb.data() + row * static_cast<std::size_t>(y);
    if (compress) {
      raw.push_back(1);  // filter: Sub (flat areas become runs of zeros)
      for (std::size_t x = 0; x < row; ++x)
        raw.push_back(static_cast<std::uint8_t>(line[x] - (x >= 3 ? line[x - 3] : 0)));
    } else {
      raw.push_back(0);  // filter: none
      raw.insert(raw.end(), line, line + row);
    }
  }
  std::vector<std::uint8_t> z{0x78, 0x01};
  if (compress) {
    deflate_fixed(raw, z);
  } else {
    std::size_t pos = 0;
    do {
      const std::size_t len = std::min<std::size_t>(65535, raw.size() - pos);
      const bool last = pos + len == raw.size();
      z.push_back(last ? 1 : 0);
      z.push_back(static_cast<std::uint8_t>(len & 0xFF));
      z.push_back(static_cast<std::uint8_t>(len >> 8));
      z.push_back(static_cast<std::uint8_t>(~len & 0xFF));
      z.push_back(static_cast<std::uint8_t>((~len >> 8) & 0xFF));
      z.insert(z.end(), raw.begin() + static_cast<std::ptrdiff_t>(pos),
               raw.begin() + static_cast<std::ptrdiff_t>(pos + len));
      pos += len;
    } while (pos < raw.size());
  }
  put_be32(z, adler32(raw.data(), raw.size()));

  std::vector<std::uint8_t> png{0x89, 'P', 'N', 'G', '\r', '\n', 0x1A, '\n'};
  std::vector<std::uint8_t> ihdr;
  put_be32(ihdr, static_cast<std::uint32_t>(width));
  put_be32(ihdr, static_cast<std::uint32_t>(height));
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8-bit, RGB, deflate, adaptive filters, no interlace
  put_chunk(png, "IHDR", ihdr);
  put_chunk(png, "IDAT", z);
  put_chunk(png, "IEND", {});
  return png;
}

std::vector<std::uint8_t> render_rgb(const RenderMesh& mesh, const RenderOptions& options) {
  if (options.width < 16 || options.height < 16 || options.width > 8192 || options.height > 8192)
    throw ToolError(kExitUsage, "", "image size must be within 16..8192 pixels");
  Camera cam;
  cam.forward = normalized(options.view);
  if (dot(cam.forward, cam.forward) == 0.0) throw ToolError(kExitUsage, "", "zero view direction");
  V3 up = sub(options.up, [&] {
    const double d = dot(options.up, cam.forward);
    return V3{d * cam.forward[0], d * cam.forward[1], d * cam.forward[2]};
  }());
  if (dot(up, up) < 1e-12) up = std::abs(cam.forward[2]) < 0.9 ? V3{0, 0, 1} : V3{0, 1, 0};
  up = normalized(sub(up, [&] {
    const double d = dot(up, cam.forward);
    return V3{d * cam.forward[0], d * cam.forward[1], d * cam.forward[2]};
  }()));
  cam.up = up;
  cam.right = cross(cam.forward, cam.up);
  cam.width = options.width * kSuper;
  cam.height = options.height * kSuper;

  const std::size_t np = mesh.positions.size();
  auto valid = [&](const std::array<std::uint32_t, 3>& t) {
    return t[0] < np && t[1] < np && t[2] < np;
  };
  double lox = 1e300, hix = -1e300, loy = 1e300, hiy = -1e300, loz = 1e300, hiz = -1e300;
  for (const auto& t : mesh.triangles) {
    if (!valid(t)) continue;
    for (std::uint32_t v : t) {
      const V3& p = mesh.positions[v];
      lox = std::min(lox, dot(p, cam.right));
      hix = std::max(hix, dot(p, cam.right));
      loy = std::min(loy, dot(p, cam.up));
      hiy = std::max(hiy, dot(p, cam.up));
      loz = std::min(loz, dot(p, cam.forward));
      hiz = std::max(hiz, dot(p, cam.forward));
    }
  }
  std::vector<std::uint8_t> image(static_cast<std::size_t>(cam.width) * cam.height * 3);
  for (std::size_t i = 0; i < image.size(); i += 3)
    std::copy(options.background.begin(), options.background.end(), image.begin() + i);
  std::vector<double> zbuf(static_cast<std::size_t>(cam.width) * cam.height,
                           std::numeric_limits<double>::infinity());
  if (lox <= hix) {
    const double margin = 0.05;
    const double sx = (hix - lox) > 0 ? cam.width * (1 - 2 * margin) / (hix - lox) : 1.0;
    const double sy = (hiy - loy) > 0 ? cam.height * (1 - 2 * margin) / (hiy - loy) : 1.0;
    cam.scale = std::min(sx, sy);
    cam.cx = 0.5 * (lox + hix);
    cam.cy = 0.5 * (loy + hiy);
  }
  const V3 light = normalized({-cam.forward[0] + 0.4 * cam.up[0] - 0.3 * cam.right[0],
                               -cam.forward[1] + 0.4 * cam.up[1] - 0.3 * cam.right[1],
                               -cam.forward[2] + 0.4 * cam.up[2] - 0.3 * cam.right[2]});
  for (std::size_t ti = 0; ti < mesh.triangles.size(); ++ti) {
    const auto& t = mesh.triangles[ti];
    if (!valid(t)) continue;
    const V3 n = normalized(cross(sub(mesh.positions[t[1]], mesh.positions[t[0]]),
                                  sub(mesh.positions[t[2]], mesh.positions[t[0]])));
    if (dot(n, cam.forward) >= 0.0) continue;  // back face
    const double shade = 0.45 + 0.55 * std::max(0.0, dot(n, light));
    const Rgb base = ti < mesh.face_colors.size() ? mesh.face_colors[ti] : Rgb{180, 180, 180};
    Rgb color;
    for (int k = 0; k < 3; ++k)
      color[k] = static_cast<std::uint8_t>(std::clamp(std::lround(base[k] * shade), 0L, 255L));
    const V3 a = cam.project(mesh.positions[t[0]]);
    const V3 b = cam.project(mesh.positions[t[1]]);
    const V3 c = cam.project(mesh.positions[t[2]]);
    const double area = (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0]);
    if (area == 0.0 || !std::isfinite(area)) continue;
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a[0], b[0], c[0]}))));
    const int x1 =
        std::min(cam.width - 1, static_cast<int>(std::ceil(std::max({a[0], b[0], c[0]}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a[1], b[1], c[1]}))));
    const int y1 =
        std::min(cam.height - 1, static_cast<int>(std::ceil(std::max({a[1], b[1], c[1]}))));
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x) {
        const double px = x + 0.5, py = y + 0.5;
        const double w0 = ((b[0] - px) * (c[1] - py) - (b[1] - py) * (c[0] - px)) / area;
        const double w1 = ((c[0] - px) * (a[1] - py) - (c[1] - py) * (a[0] - px)) / area;
        const double w2 = 1.0 - w0 - w1;
        if (w0 < 0 || w1 < 0 || w2 < 0) continue;
        const double z = w0 * a[2] + w1 * b[2] + w2 * c[2];
        const std::size_t i = static_cast<std::size_t>(y) * cam.width + x;
        if (z >= zbuf[i]) continue;
        zbuf[i] = z;
        std::copy(color.begin(), color.end(), image.begin() + 3 * i);
      }
  }
  const double bias = 0.02 * std::max(hiz - loz, 1e-12);
  auto splat = [&](double x, double y, double z, double radius, const Rgb& color, bool on_top) {
    const int r = static_cast<int>(std::ceil(radius));
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx) {
        const int px = static_cast<int>(std::floor(x)) + dx;
        const int py = static_cast<int>(std::floor(y)) + dy;
        if (px < 0 || py < 0 || px >= cam.width || py >= cam.height) continue;
        if (dx * dx + dy * dy > radius * radius + 0.5) continue;
        const std::size_t i = static_cast<std::size_t>(py) * cam.width + px;
        if (!on_top && std::isfinite(zbuf[i]) && z > zbuf[i] + bias) continue;
        std::copy(color.begin(), color.end(), image.begin() + 3 * i);
      }
  };
  const double radius = 0.5 * options.line_width * kSuper;
  for (const auto& loop : mesh.loops) {
    for (std::size_t i = 0; i < loop.size(); ++i) {
      const std::uint32_t va = loop[i], vb = loop[(i + 1) % loop.size()];
      if (va >= np || vb >= np) continue;
      const V3 a = cam.project(mesh.positions[va]);
      const V3 b = cam.project(mesh.positions[vb]);
      const double len = std::hypot(b[0] - a[0], b[1] - a[1]);
      const int steps = std::max(1, static_cast<int>(std::ceil(len * 2)));
      for (int s = 0; s <= steps; ++s) {
        const double f = static_cast<double>(s) / steps;
        splat(a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * (b[2] - a[2]), radius,
              mesh.loop_color, false);
      }
    }
  }
  for (std::uint32_t v : mesh.points) {
    if (v >= np) continue;
    const V3 p = cam.project(mesh.positions[v]);
    splat(p[0], p[1], p[2], 2.5 * kSuper, mesh.point_color, mesh.points_on_top);
  }
  // Downsample.
  std::vector<std::uint8_t> out(static_cast<std::size_t>(options.width) * options.height * 3);
  for (int y = 0; y < options.height; ++y)
    for (int x = 0; x < options.width; ++x)
      for (int k = 0; k < 3; ++k) {
        int sum = 0;
        for (int sy = 0; sy < kSuper; ++sy)
          for (int sx = 0; sx < kSuper; ++sx)
            sum += image[3 * ((static_cast<std::size_t>(y) * kSuper + sy) * cam.width +
                              static_cast<std::size_t>(x) * kSuper + sx) +
                         k];
        out[3 * (static_cast<std::size_t>(y) * options.width + x) + k] =
            static_cast<std::uint8_t>((sum + kSuper * kSuper / 2) / (kSuper * kSuper));
      }
  return out;
}

}  // namespace tetseg::tools
