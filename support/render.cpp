#include "render.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <iterator>
#include <limits>
#include <sstream>

#include <png.h>

#include <new>
#include <stdexcept>

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

}  // namespace

namespace {

void append_to_vector(png_structp png, png_bytep data, png_size_t size) {
  auto* out = static_cast<std::vector<std::uint8_t>*>(png_get_io_ptr(png));
  out->insert(out->end(), data, data + size);
}

}  // namespace

std::vector<std::uint8_t> encode_png(const std::vector<std::uint8_t>& rgb, int width, int height,
                                     bool compress) {
  std::vector<std::uint8_t> out;
  std::vector<png_bytep> rows(static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y) {
    // libpng reads the rows only; its API takes them as non-const.
    rows[static_cast<std::size_t>(y)] = const_cast<png_bytep>(
        rgb.data() + static_cast<std::size_t>(width) * 3 * static_cast<std::size_t>(y));
  }
  png_structp png = png_create_write_struct(PNG_LIBPNG_VER_STRING, nullptr, nullptr, nullptr);
  png_infop info = png ? png_create_info_struct(png) : nullptr;
  if (!info) {
    png_destroy_write_struct(&png, nullptr);
    throw std::bad_alloc();
  }
  if (setjmp(png_jmpbuf(png))) {  // libpng reports errors by longjmp here
    png_destroy_write_struct(&png, &info);
    throw std::runtime_error("PNG encoding failed");
  }
  png_set_write_fn(png, &out, append_to_vector, nullptr);
  png_set_IHDR(png, info, static_cast<png_uint_32>(width), static_cast<png_uint_32>(height), 8,
               PNG_COLOR_TYPE_RGB, PNG_INTERLACE_NONE, PNG_COMPRESSION_TYPE_DEFAULT,
               PNG_FILTER_TYPE_DEFAULT);
  if (compress) {
    png_set_compression_level(png, 9);
  } else {
    png_set_compression_level(png, 0);  // zlib stored blocks
    png_set_filter(png, PNG_FILTER_TYPE_BASE, PNG_FILTER_NONE);
  }
  png_set_rows(png, info, rows.data());
  png_write_png(png, info, PNG_TRANSFORM_IDENTITY, nullptr);
  png_destroy_write_struct(&png, &info);
  return out;
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
