// World construction, validation and the graded quantities.
#include <cmath>
#include <cstring>
#include <string>
#include <unordered_map>

#include "rbsim/core.hpp"
#include "wind_moments.hpp"

namespace rbsim {

const char* version() {
  return RBSIM_VERSION;
}

const char* to_string(Integrator integrator) {
  switch (integrator) {
    case Integrator::ExplicitEuler:
      return "explicit-euler";
    case Integrator::SymplecticEuler:
      return "symplectic-euler";
  }
  return "?";
}

namespace {

Error invalid(const std::string& what) {
  return Error{"invalid world: " + what};
}

bool finite(const Vec2& v) {
  return std::isfinite(v.x()) && std::isfinite(v.y());
}

// Hash of the exact bits of a body-space hull, so bit-identical hulls share one Shape.
struct HullKey {
  std::string bytes;
  bool operator==(const HullKey&) const = default;
};
struct HullKeyHash {
  std::size_t operator()(const HullKey& k) const { return std::hash<std::string>{}(k.bytes); }
};

Status validate(const WorldDef& def) {
  if (!(std::isfinite(def.dt) && def.dt > 0)) return invalid("dt must be finite and > 0");
  const auto n = static_cast<std::int32_t>(def.bodies.size());
  for (std::int32_t b = 0; b < n; ++b) {
    const BodyDef& body = def.bodies[b];
    const std::string who = "body " + std::to_string(b) + ": ";
    if (body.hull.size() < 2) return invalid(who + "needs at least 2 hull vertices");
    if (body.masses.size() != body.hull.size()) return invalid(who + "one mass per hull vertex");
    for (std::size_t v = 0; v < body.hull.size(); ++v) {
      if (!finite(body.hull[v])) return invalid(who + "vertex position not finite");
      if (!(std::isfinite(body.masses[v]) && body.masses[v] > 0))
        return invalid(who + "vertex mass must be > 0");
    }
    if (!finite(body.velocity) || !std::isfinite(body.omega)) return invalid(who + "velocity not finite");
    if (!(std::isfinite(body.radius) && body.radius > 0)) return invalid(who + "radius must be > 0");
  }
  for (std::size_t s = 0; s < def.springs.size(); ++s) {
    const SpringDef& sp = def.springs[s];
    const std::string who = "spring " + std::to_string(s) + ": ";
    for (std::int32_t end : {sp.body_i, sp.body_j}) {
      if (end != kFixed && (end < 0 || end >= n)) return invalid(who + "body index out of range");
    }
    if (!finite(sp.anchor_i) || !finite(sp.anchor_j)) return invalid(who + "anchor not finite");
    if (!(std::isfinite(sp.stiffness) && sp.stiffness >= 0)) return invalid(who + "k must be >= 0");
    if (!(std::isfinite(sp.rest_length) && sp.rest_length >= 0)) return invalid(who + "l0 must be >= 0");
  }
  for (const GravityDef& g : def.gravity) {
    if (!finite(g.acceleration)) return invalid("gravity not finite");
  }
  for (const WindDef& w : def.winds) {
    if (!(std::isfinite(w.beta) && w.beta >= 0)) return invalid("wind beta must be >= 0");
    if (!finite(w.velocity)) return invalid("wind velocity not finite");
    if (w.points_per_edge < 1) return invalid("wind points per edge must be >= 1");
  }
  return Ok{};
}

}  // namespace

Result<World> World::create(const WorldDef& def) {
  if (Status st = validate(def); !st) return st.error();
  World w;
  w.integrator_ = def.integrator;
  w.dt_ = def.dt;
  w.springs_ = def.springs;
  w.gravity_ = def.gravity;
  w.winds_ = def.winds;

  const std::size_t n = def.bodies.size();
  for (auto* column : {&w.x_, &w.y_, &w.theta_, &w.vx_, &w.vy_, &w.omega_, &w.fx_, &w.fy_, &w.tau_, &w.cos_,
                       &w.sin_, &w.mass_, &w.inertia_, &w.radius_}) {
    column->assign(n, 0.0);
  }
  w.shape_.assign(n, 0);
  std::fill(w.cos_.begin(), w.cos_.end(), 1.0);

  std::unordered_map<HullKey, std::int32_t, HullKeyHash> shape_of;
  std::vector<Vec2> local;
  for (std::size_t b = 0; b < n; ++b) {
    const BodyDef& body = def.bodies[b];
    // M = sum m_i;  X = sum m_i r_i / M;  I = sum m_i |r_i - X|^2  (docs/rigid-body-milestone.md 3.1, 3.3.2)
    double m = 0.0;
    Vec2 mx(0.0, 0.0);
    for (std::size_t v = 0; v < body.hull.size(); ++v) {
      m += body.masses[v];
      mx += body.masses[v] * body.hull[v];
    }
    const Vec2 com = mx / m;
    double inertia = 0.0;
    local.clear();
    for (std::size_t v = 0; v < body.hull.size(); ++v) {
      local.push_back(body.hull[v] - com);
      inertia += body.masses[v] * local.back().squaredNorm();
    }
    if (!std::isfinite(inertia) || !std::isfinite(com.x()) || !std::isfinite(com.y())) {
      return invalid("body " + std::to_string(b) + ": mass, centre of mass or moment of inertia overflows");
    }
    if (!(inertia > 0.0)) {
      return invalid("body " + std::to_string(b) + ": all vertices coincide (moment of inertia is 0)");
    }
    w.mass_[b] = m;
    w.inertia_[b] = inertia;
    w.radius_[b] = body.radius;
    w.x_[b] = com.x();
    w.y_[b] = com.y();
    w.vx_[b] = body.velocity.x();
    w.vy_[b] = body.velocity.y();
    w.omega_[b] = body.omega;

    HullKey key{std::string(reinterpret_cast<const char*>(local.data()), local.size() * sizeof(Vec2))};
    auto [it, inserted] = shape_of.try_emplace(std::move(key), static_cast<std::int32_t>(w.shapes_.size()));
    if (inserted) {
      w.shapes_.push_back(Shape{static_cast<std::int32_t>(w.shape_vertices_.size()),
                                static_cast<std::int32_t>(local.size())});
      w.shape_vertices_.insert(w.shape_vertices_.end(), local.begin(), local.end());
    }
    w.shape_[b] = it->second;
  }
  w.shape_vertices_.shrink_to_fit();
  w.shapes_.shrink_to_fit();

  w.wind_moments_.reserve(w.winds_.size() * w.shapes_.size());
  for (const WindDef& wind : w.winds_) {
    for (const Shape& shape : w.shapes_) {
      const std::span<const Vec2> hull(w.shape_vertices_.data() + shape.first, shape.count);
      w.wind_moments_.push_back(compute_wind_moments(hull, wind.points_per_edge));
    }
  }
  return w;
}

std::span<const Vec2> World::hull(BodyId b) const {
  const Shape& s = shapes_[shape_[b.index]];
  return {shape_vertices_.data() + s.first, static_cast<std::size_t>(s.count)};
}

Vec2 World::world_vertex(BodyId b, std::int32_t vertex) const {
  const Vec2& r0 = hull(b)[vertex];
  const double c = std::cos(theta_[b.index]), s = std::sin(theta_[b.index]);
  return {c * r0.x() - s * r0.y() + x_[b.index], s * r0.x() + c * r0.y() + y_[b.index]};
}

BodyState World::state(BodyId b) const {
  const auto i = b.index;
  return BodyState{{x_[i], y_[i]}, theta_[i], {vx_[i], vy_[i]}, omega_[i]};
}

void World::set_state(BodyId b, const BodyState& s) {
  const auto i = b.index;
  x_[i] = s.position.x();
  y_[i] = s.position.y();
  theta_[i] = s.theta;
  vx_[i] = s.velocity.x();
  vy_[i] = s.velocity.y();
  omega_[i] = s.omega;
}

BodyQuantities World::quantities(BodyId b) const {
  const auto i = b.index;
  const double m = mass_[i], inertia = inertia_[i];
  BodyQuantities q;
  q.momentum = {m * vx_[i], m * vy_[i]};
  q.l_point = m * (x_[i] * vy_[i] - y_[i] * vx_[i]);
  q.l_spin = inertia * omega_[i];
  q.t_point = 0.5 * m * (vx_[i] * vx_[i] + vy_[i] * vy_[i]);
  q.t_spin = 0.5 * inertia * omega_[i] * omega_[i];
  return q;
}

Energy World::energy() const {
  Energy e;
  for (const GravityDef& g : gravity_) {
    // U = -sum_i m_i g . r_i = -M g . X  (the body-space offsets sum to zero)
    for (std::int32_t b = 0; b < body_count(); ++b) {
      e.u_gravity -= mass_[b] * (g.acceleration.x() * x_[b] + g.acceleration.y() * y_[b]);
    }
  }
  for (std::int32_t s = 0; s < spring_count(); ++s) e.u_spring += spring_state(SpringId{s}).potential;
  for (std::int32_t b = 0; b < body_count(); ++b) {
    const BodyQuantities q = quantities(BodyId{b});
    e.t_point += q.t_point;
    e.t_spin += q.t_spin;
  }
  return e;
}

SceneTotals World::totals() const {
  SceneTotals t;
  for (std::int32_t b = 0; b < body_count(); ++b) {
    const BodyQuantities q = quantities(BodyId{b});
    t.momentum += q.momentum;
    t.angular += q.l_point + q.l_spin;
  }
  return t;
}

std::optional<World::NonFinite> World::find_nonfinite() const {
  // v * 0 is 0 for every finite v and NaN for inf or NaN, so one branch-free pass per group
  // decides whether the exact search is needed. Derived quantities (T = M |V|^2 / 2, U, ...) can
  // overflow while the state is still finite, so they are checked too: no output may carry inf.
  double sum = 0.0;
  for (const auto* column : {&x_, &y_, &theta_, &vx_, &vy_, &omega_}) {
    for (double v : *column) sum += v * 0.0;
  }
  if (sum != 0.0) {
    static constexpr const char* kNames[] = {"x", "y", "theta", "vx", "vy", "omega"};
    for (std::int32_t b = 0; b < body_count(); ++b) {
      const double values[] = {x_[b], y_[b], theta_[b], vx_[b], vy_[b], omega_[b]};
      for (int q = 0; q < 6; ++q) {
        if (!std::isfinite(values[q])) return NonFinite{BodyId{b}, kNames[q]};
      }
    }
  }
  for (std::int32_t b = 0; b < body_count(); ++b) {
    const BodyQuantities q = quantities(BodyId{b});
    const double values[] = {q.momentum.x(), q.momentum.y(), q.l_point, q.l_spin, q.t_point, q.t_spin};
    static constexpr const char* kNames[] = {"px", "py", "L_point", "L_spin", "T_point", "T_spin"};
    for (int k = 0; k < 6; ++k) {
      if (!std::isfinite(values[k])) return NonFinite{BodyId{b}, kNames[k]};
    }
  }
  const Energy e = energy();
  if (!std::isfinite(e.u_gravity)) return NonFinite{BodyId{-1}, "U_gravity"};
  if (!std::isfinite(e.u_spring)) return NonFinite{BodyId{-1}, "U_spring"};
  if (!std::isfinite(e.total())) return NonFinite{BodyId{-1}, "E"};
  return std::nullopt;
}

std::size_t World::memory_bytes() const {
  std::size_t bytes = 0;
  for (const auto* column : {&x_, &y_, &theta_, &vx_, &vy_, &omega_, &fx_, &fy_, &tau_, &cos_, &sin_, &mass_,
                             &inertia_, &radius_}) {
    bytes += column->capacity() * sizeof(double);
  }
  bytes += shape_.capacity() * sizeof(std::int32_t) + shapes_.capacity() * sizeof(Shape) +
           shape_vertices_.capacity() * sizeof(Vec2) + wind_moments_.capacity() * sizeof(WindMoments) +
           springs_.capacity() * sizeof(SpringDef) + gravity_.capacity() * sizeof(GravityDef) +
           winds_.capacity() * sizeof(WindDef);
  return bytes;
}

}  // namespace rbsim
