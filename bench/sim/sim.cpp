// XPBD soft body with ground friction and collider-checked self-contact (sim.hpp).

#include "sim.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <stdexcept>

namespace tetseg::tools {
namespace {

using preprocess::InputError;

double tet_volume(const double* a, const double* b, const double* c, const double* d) {
  const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
  const double v[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
  const double w[3] = {d[0] - a[0], d[1] - a[1], d[2] - a[2]};
  return (u[0] * (v[1] * w[2] - v[2] * w[1]) - u[1] * (v[0] * w[2] - v[2] * w[0]) +
          u[2] * (v[0] * w[1] - v[1] * w[0])) /
         6.0;
}

}  // namespace

std::vector<double> place_above_ground(const std::vector<preprocess::Vec3>& nodes, int up_axis,
                                       double ground, double drop_height, double tilt_x,
                                       double tilt_y) {
  std::vector<double> x(nodes.size() * 3);
  double centre[3] = {0, 0, 0};
  for (const auto& p : nodes)
    for (int k = 0; k < 3; ++k) centre[k] += p[k];
  for (double& c : centre) c /= nodes.empty() ? 1.0 : double(nodes.size());
  const double a = tilt_x * M_PI / 180.0, ca = std::cos(a), sa = std::sin(a);
  const double b = tilt_y * M_PI / 180.0, cb = std::cos(b), sb = std::sin(b);
  double lowest = INFINITY;
  for (std::size_t i = 0; i < nodes.size(); ++i) {
    const double px = nodes[i][0] - centre[0], py = nodes[i][1] - centre[1],
                 pz = nodes[i][2] - centre[2];
    const double y = ca * py - sa * pz, z1 = sa * py + ca * pz;  // about x
    x[i * 3 + 0] = centre[0] + cb * px + sb * z1;                // then about y
    x[i * 3 + 1] = centre[1] + y;
    x[i * 3 + 2] = centre[2] - sb * px + cb * z1;
    lowest = std::min(lowest, x[i * 3 + up_axis]);
  }
  const double shift = ground + drop_height - lowest;
  for (std::size_t i = 0; i < nodes.size(); ++i) x[i * 3 + up_axis] += shift;
  return x;
}

SoftBody::SoftBody(const preprocess::TetMesh& mesh, const std::vector<double>& start,
                   const SimOptions& options, const std::string& what)
    : m_opt(options) {
  if (!(options.frame_dt > 0) || options.substeps == 0 || options.iterations == 0 ||
      options.up_axis < 0 || options.up_axis > 2 || !(options.friction >= 0) ||
      !(options.density > 0) || !(options.edge_compliance >= 0) ||
      !(options.volume_compliance >= 0) || !(options.damping >= 0))
    throw InputError(what, "simulation option out of range");
  m_node_count = mesh.nodes.size();
  if (start.size() != m_node_count * 3) throw InputError(what, "start position count mismatch");

  // Masses (lumped tet volumes), rest volumes, unique edges in sorted order.
  m_tets = mesh.tets;
  m_inv_mass.assign(m_node_count, 0.0);
  m_tet_rest.resize(m_tets.size());
  std::vector<std::array<std::uint32_t, 2>> edges;
  edges.reserve(m_tets.size() * 6);
  for (std::size_t t = 0; t < m_tets.size(); ++t) {
    const auto& q = m_tets[t];
    const double v = tet_volume(mesh.nodes[q[0]].data(), mesh.nodes[q[1]].data(),
                                mesh.nodes[q[2]].data(), mesh.nodes[q[3]].data());
    if (!(v > 0)) throw InputError(what, "tet " + std::to_string(t) + " is not positive");
    m_tet_rest[t] = v;
    for (std::uint32_t n : q) m_inv_mass[n] += v * options.density / 4.0;
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) edges.push_back({std::min(q[i], q[j]), std::max(q[i], q[j])});
  }
  for (double& m : m_inv_mass) m = m > 0 ? 1.0 / m : 0.0;
  std::sort(edges.begin(), edges.end());
  edges.erase(std::unique(edges.begin(), edges.end()), edges.end());
  m_edges = std::move(edges);
  m_edge_rest.resize(m_edges.size());
  for (std::size_t e = 0; e < m_edges.size(); ++e) {
    const auto& a = mesh.nodes[m_edges[e][0]];
    const auto& b = mesh.nodes[m_edges[e][1]];
    m_edge_rest[e] = std::sqrt((a[0] - b[0]) * (a[0] - b[0]) + (a[1] - b[1]) * (a[1] - b[1]) +
                               (a[2] - b[2]) * (a[2] - b[2]));
  }

  m_x = start;
  m_x_prev = start;
  m_v.assign(m_node_count * 3, 0.0);

  if (options.twist_rate != 0) {
    if (options.twist_axis < 0 || options.twist_axis > 2 || !(options.twist_ends > 0) ||
        !(options.twist_ends < 0.5))
      throw InputError(what, "twist axis must be 0..2 and the held ends in (0, 0.5)");
    const int a = options.twist_axis;
    double lo = INFINITY, hi = -INFINITY;
    for (std::size_t i = 0; i < m_node_count; ++i) {
      lo = std::min(lo, start[i * 3 + a]);
      hi = std::max(hi, start[i * 3 + a]);
      for (int k = 0; k < 3; ++k) m_center[k] += start[i * 3 + k] / double(m_node_count);
    }
    const double band = options.twist_ends * (hi - lo);
    for (std::uint32_t i = 0; i < m_node_count; ++i) {
      const double c = start[i * 3 + a];
      if (c > lo + band && c < hi - band) continue;
      m_held.push_back(
          {i, c >= hi - band ? 1.0 : -1.0, {start[i * 3], start[i * 3 + 1], start[i * 3 + 2]}});
      m_inv_mass[i] = 0;
    }
  }
}

void SoftBody::hold_twisted_ends() {
  const int a = m_opt.twist_axis, u = (a + 1) % 3, v = (a + 2) % 3;
  for (const HeldNode& n : m_held) {
    const double angle = n.sign * 0.5 * m_opt.twist_rate * (std::acos(-1.0) / 180.0) * m_time;
    const double c = std::cos(angle), s = std::sin(angle);
    const double du = n.start[u] - m_center[u], dv = n.start[v] - m_center[v];
    double* p = m_x.data() + std::size_t(n.node) * 3;
    p[a] = n.start[a];
    p[u] = m_center[u] + c * du - s * dv;
    p[v] = m_center[v] + s * du + c * dv;
  }
}

void SoftBody::predict(double h, SimCounters& counters) {
  const int up = m_opt.up_axis;
  const double damp = std::max(0.0, 1.0 - m_opt.damping * h);
  m_x_prev = m_x;
  for (std::size_t i = 0; i < m_node_count; ++i) {
    if (m_inv_mass[i] == 0) continue;
    m_v[i * 3 + up] -= m_opt.gravity * h;
    for (int k = 0; k < 3; ++k) {
      m_v[i * 3 + k] *= damp;
      m_x[i * 3 + k] += m_v[i * 3 + k] * h;
    }
  }
  m_time += h;
  hold_twisted_ends();
  for (std::uint32_t it = 0; it < m_opt.iterations; ++it) solve_constraints(h);
  apply_ground(counters);
}

void SoftBody::finish(double h) {
  for (std::size_t i = 0; i < m_x.size(); ++i) m_v[i] = (m_x[i] - m_x_prev[i]) / h;
}

bool SoftBody::freeze(std::uint32_t n) {
  double* p = m_x.data() + std::size_t(n) * 3;
  const double* q = m_x_prev.data() + std::size_t(n) * 3;
  if (p[0] == q[0] && p[1] == q[1] && p[2] == q[2]) return false;
  p[0] = q[0];
  p[1] = q[1];
  p[2] = q[2];
  return true;
}

void SoftBody::solve_constraints(double h) {
  double* x = m_x.data();
  const double* w = m_inv_mass.data();
  const double ae = m_opt.edge_compliance / (h * h);
  for (std::size_t e = 0; e < m_edges.size(); ++e) {
    const std::uint32_t a = m_edges[e][0], b = m_edges[e][1];
    const double wsum = w[a] + w[b];
    if (wsum == 0) continue;
    double d[3] = {x[a * 3] - x[b * 3], x[a * 3 + 1] - x[b * 3 + 1], x[a * 3 + 2] - x[b * 3 + 2]};
    const double len = std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (len == 0) continue;
    const double lambda = -(len - m_edge_rest[e]) / (wsum + ae);
    for (int k = 0; k < 3; ++k) {
      const double n = d[k] / len;
      x[a * 3 + k] += w[a] * lambda * n;
      x[b * 3 + k] -= w[b] * lambda * n;
    }
  }
  // Volume: C = V - V0 with gradients (x_j - x_i) x (x_k - x_i) / 6 for each opposite face.
  static constexpr int kFace[4][3] = {{1, 3, 2}, {0, 2, 3}, {0, 3, 1}, {0, 1, 2}};
  const double av = m_opt.volume_compliance / (h * h);
  for (std::size_t t = 0; t < m_tets.size(); ++t) {
    const auto& q = m_tets[t];
    double g[4][3];
    double wsum = 0;
    for (int j = 0; j < 4; ++j) {
      const double* p0 = x + std::size_t(q[kFace[j][0]]) * 3;
      const double* p1 = x + std::size_t(q[kFace[j][1]]) * 3;
      const double* p2 = x + std::size_t(q[kFace[j][2]]) * 3;
      const double u[3] = {p1[0] - p0[0], p1[1] - p0[1], p1[2] - p0[2]};
      const double v[3] = {p2[0] - p0[0], p2[1] - p0[1], p2[2] - p0[2]};
      g[j][0] = (u[1] * v[2] - u[2] * v[1]) / 6.0;
      g[j][1] = (u[2] * v[0] - u[0] * v[2]) / 6.0;
      g[j][2] = (u[0] * v[1] - u[1] * v[0]) / 6.0;
      wsum += w[q[j]] * (g[j][0] * g[j][0] + g[j][1] * g[j][1] + g[j][2] * g[j][2]);
    }
    if (wsum + av == 0) continue;
    const double vol = tet_volume(x + std::size_t(q[0]) * 3, x + std::size_t(q[1]) * 3,
                                  x + std::size_t(q[2]) * 3, x + std::size_t(q[3]) * 3);
    const double lambda = -(vol - m_tet_rest[t]) / (wsum + av);
    for (int j = 0; j < 4; ++j)
      for (int k = 0; k < 3; ++k) x[std::size_t(q[j]) * 3 + k] += lambda * w[q[j]] * g[j][k];
  }
}

void SoftBody::apply_ground(SimCounters& counters) {
  const int up = m_opt.up_axis;
  const int t1 = (up + 1) % 3, t2 = (up + 2) % 3;
  for (std::size_t i = 0; i < m_node_count; ++i) {
    double* p = m_x.data() + i * 3;
    const double pen = m_opt.ground - p[up];
    if (!(pen > 0)) continue;
    ++counters.ground_contacts;
    p[up] = m_opt.ground;
    // Coulomb friction on the tangential displacement of the substep (position-based).
    const double* q = m_x_prev.data() + i * 3;
    const double d1 = p[t1] - q[t1], d2 = p[t2] - q[t2];
    const double dl = std::sqrt(d1 * d1 + d2 * d2);
    const double limit = m_opt.friction * pen;
    if (dl <= limit) {
      p[t1] = q[t1];
      p[t2] = q[t2];
    } else {
      const double s = limit / dl;
      p[t1] -= d1 * s;
      p[t2] -= d2 * s;
    }
  }
}

struct Simulation::Body {
  std::unique_ptr<SoftBody> soft;  // null for an obstacle
  Obstacle obstacle;
  std::string what;
};

Simulation::Simulation(const SimOptions& options)
    : m_opt(options), m_scene(tetseg::SceneOptions{}) {
  m_contacts.resize(std::max<std::size_t>(1, options.contact_capacity));
}

Simulation::~Simulation() = default;

void Simulation::add_body(const preprocess::TetMesh& mesh, const tetseg::Asset& asset,
                          const std::vector<double>& start, const std::string& what) {
  if (asset.node_count() != mesh.nodes.size())
    throw InputError(what, "the asset has " + std::to_string(asset.node_count()) +
                               " nodes, the tet mesh " + std::to_string(mesh.nodes.size()));
  Body b;
  b.soft = std::make_unique<SoftBody>(mesh, start, m_opt, what);
  b.what = what;
  const std::shared_ptr<const tetseg::BodyShape> shape = tetseg::BodyShape::from_asset(asset);
  if (!shape) throw InputError(what, "cannot build the body's surface topology");
  tetseg::BodyOptions o;
  o.mode = m_opt.collider_mode;
  if (m_scene.add_body(shape, o) != tetseg::ColliderStatus::kOk)
    throw InputError(what, "cannot add the body to the scene (mode " +
                               std::string(tetseg::to_string(m_opt.collider_mode)) + ")");
  m_bodies.push_back(std::move(b));
}

void Simulation::add_obstacle(Obstacle obstacle, const std::string& what) {
  const std::size_t nodes = obstacle.positions.size() / 3;
  std::vector<std::uint32_t> flat;
  for (const auto& t : obstacle.triangles) flat.insert(flat.end(), t.begin(), t.end());
  const std::shared_ptr<const tetseg::BodyShape> shape = tetseg::BodyShape::from_triangles(
      flat.data(), obstacle.triangles.size(), static_cast<std::uint32_t>(nodes));
  if (!shape || obstacle.positions.size() != nodes * 3)
    throw InputError(what, "invalid obstacle triangles");
  tetseg::BodyOptions o;
  o.still = true;
  o.self_collision = false;
  if (m_scene.add_body(shape, o) != tetseg::ColliderStatus::kOk)
    throw InputError(what, "cannot add the obstacle to the scene");
  Body b;
  b.obstacle = std::move(obstacle);
  b.what = what;
  m_bodies.push_back(std::move(b));
}

void Simulation::set_positions() {
  for (std::uint32_t i = 0; i < m_bodies.size(); ++i) {
    const Body& b = m_bodies[i];
    const tetseg::ColliderStatus st =
        b.soft ? m_scene.set_positions(i, b.soft->previous().data(), b.soft->positions().data(),
                                       b.soft->positions().size())
               : m_scene.set_positions(i, b.obstacle.positions.data(), nullptr,
                                       b.obstacle.positions.size());
    if (st != tetseg::ColliderStatus::kOk)
      throw std::runtime_error(std::string("scene positions failed: ") + tetseg::to_string(st));
  }
}

void Simulation::check_start() {
  set_positions();
  const tetseg::RestCheck rc = m_scene.check_rest_intersection();
  if (rc.status != tetseg::ColliderStatus::kOk)
    throw InputError(m_bodies.empty() ? "" : m_bodies[0].what,
                     std::string("start check failed: ") + tetseg::to_string(rc.status));
  if (!rc.intersecting) return;
  const Body& a = m_bodies[rc.bodies[0]];
  const Body& b = m_bodies[rc.bodies[1]];
  if (rc.bodies[0] == rc.bodies[1])
    throw InputError(a.what, "the start surface self-intersects (triangles " +
                                 std::to_string(rc.triangle_a) + " and " +
                                 std::to_string(rc.triangle_b) + ")");
  throw InputError(a.what, "the start surface touches body " + std::to_string(rc.bodies[1]) + " (" +
                               b.what + ")");
}

void Simulation::advance_frame() {
  const double h = m_opt.frame_dt / m_opt.substeps;
  for (std::uint32_t s = 0; s < m_opt.substeps; ++s) substep(h);
}

void Simulation::substep(double h) {
  ++m_counters.substeps;
  for (Body& b : m_bodies)
    if (b.soft) b.soft->predict(h, m_counters);
  if (m_opt.self_contact) resolve_contacts();
  for (Body& b : m_bodies)
    if (b.soft) b.soft->finish(h);
}

void Simulation::resolve_contacts() {
  std::uint32_t rounds = 0;
  bool first = true;
  for (;;) {
    set_positions();
    const tetseg::ColliderStatus st = m_scene.step();
    if (st != tetseg::ColliderStatus::kOk)
      throw std::runtime_error(std::string("scene step failed: ") + tetseg::to_string(st));
    ++rounds;
    ++m_counters.query_rounds;
    bool hit = false;
    tetseg::ContactsResult r;
    tetseg::ColliderStatus qs = m_scene.any_collision(hit);
    if (qs == tetseg::ColliderStatus::kOk && hit)
      qs = m_scene.contacts(m_contacts.data(), m_contacts.size(), r);
    if (qs != tetseg::ColliderStatus::kOk)
      throw std::runtime_error(std::string("scene query failed: ") + tetseg::to_string(qs));
    if (!hit) break;
    if (first) {
      ++m_counters.substeps_with_contact;
      if (m_record && (m_counters.substeps_with_contact - 1) % m_record_every == 0) {
        append_starts(*m_record);  // the query as asked: nothing frozen yet
        append_positions(*m_record);
        ++m_counters.queries_recorded;
      }
    }
    first = false;
    m_counters.contacts_resolved += r.found;
    bool progress = false;
    for (std::size_t c = 0; c < r.written; ++c) {
      const tetseg::Contact& k = m_contacts[c];
      if (k.bodies[0] != k.bodies[1]) ++m_counters.body_contacts;
      // Vertex-face: node 0 in bodies[0], 1..3 in bodies[1]; edge-edge: 0..1 and 2..3.
      const int split = k.kind == tetseg::ContactKind::kVertexFace ? 1 : 2;
      for (int j = 0; j < 4; ++j) {
        SoftBody* soft = m_bodies[k.bodies[j < split ? 0 : 1]].soft.get();
        if (soft && soft->freeze(k.nodes[j])) {
          ++m_counters.nodes_frozen;
          progress = true;
        }
      }
    }
    // A contact always has a moving node, so progress holds; guard against a broken scene.
    if (!progress) throw std::runtime_error("contact response made no progress");
  }
  m_counters.max_rounds = std::max(m_counters.max_rounds, rounds);
}

void Simulation::append_positions(std::vector<double>& out) const {
  for (const Body& b : m_bodies) {
    const std::vector<double>& x = b.soft ? b.soft->positions() : b.obstacle.positions;
    out.insert(out.end(), x.begin(), x.end());
  }
}

void Simulation::record_queries(std::vector<double>* out, std::uint32_t every) {
  m_record = out;
  m_record_every = std::max<std::uint32_t>(1, every);
}

void Simulation::append_starts(std::vector<double>& out) const {
  for (const Body& b : m_bodies) {
    const std::vector<double>& x = b.soft ? b.soft->previous() : b.obstacle.positions;
    out.insert(out.end(), x.begin(), x.end());
  }
}

std::size_t Simulation::node_count() const noexcept {
  std::size_t n = 0;
  for (const Body& b : m_bodies)
    n += b.soft ? b.soft->node_count() : b.obstacle.positions.size() / 3;
  return n;
}

}  // namespace tetseg::tools
