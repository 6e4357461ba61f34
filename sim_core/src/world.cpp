// World construction, validation and the graded quantities.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <initializer_list>
#include <limits>
#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <string>
#include <unordered_map>

#include "body_constants.hpp"
#include "finite.hpp"
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

// Hash of the exact bits of a body-space hull, so bit-identical hulls share one Shape.
struct HullKey {
  std::string bytes;
  bool operator==(const HullKey&) const = default;
};
struct HullKeyHash {
  std::size_t operator()(const HullKey& k) const { return std::hash<std::string>{}(k.bytes); }
};

Status validate_definition(const WorldDef& def) {
  if (!(std::isfinite(def.dt) && def.dt > 0)) return invalid("dt must be finite and > 0");
  const auto n = static_cast<std::int32_t>(def.bodies.size());
  for (std::int32_t b = 0; b < n; ++b) {
    if (Status st = detail::validate_body(def.bodies[b], b); !st) return st;
  }
  for (std::size_t s = 0; s < def.springs.size(); ++s) {
    if (Status st = detail::validate_spring(def.springs[s], n, static_cast<std::int32_t>(s)); !st) return st;
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

namespace detail {

Status validate_body(const BodyDef& body, std::int32_t index) {
  const auto who = [index](const char* what) {
    return invalid((index < 0 ? std::string("added body: ") : "body " + std::to_string(index) + ": ") + what);
  };
  if (body.hull.size() < 2) return who("needs at least 2 hull vertices");
  if (body.masses.size() != body.hull.size()) return who("one mass per hull vertex");
  for (std::size_t v = 0; v < body.hull.size(); ++v) {
    if (!finite(body.hull[v])) return who("vertex position not finite");
    if (!(std::isfinite(body.masses[v]) && body.masses[v] > 0)) return who("vertex mass must be > 0");
  }
  if (!finite(body.velocity) || !std::isfinite(body.omega)) return who("velocity not finite");
  if (!(std::isfinite(body.radius) && body.radius > 0)) return who("radius must be > 0");
  return Ok{};
}

Status validate_spring(const SpringDef& sp, std::int32_t bodies, std::int32_t index) {
  const auto who = [index](const char* what) {
    return invalid((index < 0 ? std::string("added spring: ") : "spring " + std::to_string(index) + ": ") +
                   what);
  };
  for (std::int32_t end : {sp.body_i, sp.body_j}) {
    if (end != kFixed && (end < 0 || end >= bodies)) return who("body index out of range");
  }
  if (!finite(sp.anchor_i) || !finite(sp.anchor_j)) return who("anchor not finite");
  if (!(std::isfinite(sp.stiffness) && sp.stiffness >= 0)) return who("k must be >= 0");
  if (!(std::isfinite(sp.rest_length) && sp.rest_length >= 0)) return who("l0 must be >= 0");
  return Ok{};
}

Result<MassProperties> mass_properties(const BodyDef& body, std::int32_t index, std::vector<Vec2>& local) {
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
  const auto who = [index](const char* what) {
    return invalid((index < 0 ? std::string("added body: ") : "body " + std::to_string(index) + ": ") + what);
  };
  if (!std::isfinite(inertia) || !std::isfinite(com.x()) || !std::isfinite(com.y())) {
    return who("mass, centre of mass or moment of inertia overflows");
  }
  if (!(inertia > 0.0)) return who("all vertices coincide (moment of inertia is 0)");
  return MassProperties{m, com, inertia};
}

}  // namespace detail

Result<World> World::create(const WorldDef& def) {
  if (Status st = validate_definition(def); !st) return st.error();
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
  std::fill(w.cos_.begin(), w.cos_.end(), 1.0);  // theta starts at 0

  std::unordered_map<HullKey, std::int32_t, HullKeyHash> shape_of;
  std::vector<Vec2> local;
  for (std::size_t b = 0; b < n; ++b) {
    const BodyDef& body = def.bodies[b];
    Result<detail::MassProperties> props = detail::mass_properties(body, static_cast<std::int32_t>(b), local);
    if (!props) return props.error();
    const double m = props.value().mass, inertia = props.value().inertia;
    const Vec2 com = props.value().com;
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
  w.shape_refs_.assign(w.shapes_.size(), 0);
  for (const std::int32_t shape : w.shape_) ++w.shape_refs_[shape];
  w.init_identity();

  w.wind_moments_.reserve(w.winds_.size() * w.shapes_.size());
  for (const WindDef& wind : w.winds_) {
    for (const Shape& shape : w.shapes_) {
      const std::span<const Vec2> hull(w.shape_vertices_.data() + shape.first, shape.count);
      w.wind_moments_.push_back(compute_wind_moments(hull, wind.points_per_edge));
    }
  }
  w.finite_bound_ = w.compute_finite_bound();
  return w;
}

double World::compute_finite_bound() const {
  // With every state value at most B in magnitude, per body |P| <= sqrt2 M B, |L_point| <= 2 M B^2,
  // |L_spin| <= I B, T_point <= M B^2, T_spin <= I B^2 / 2; U_gravity <= sqrt2 M |g| B per body and
  // field; a spring's length is at most 2 sqrt2 B + |a_i| + |a_j| (anchors rotate rigidly), so
  // U_spring <= k (3B + 2A + l0)^2 / 2. Each of the N + S terms of a total is thus at most
  // 4 C (3B + 2A + l0 + 1)^2 with C = max(M, I, k, M sum|g|, 1); keeping all of them together under
  // 1e300 leaves every product and sum finite with room to spare.
  double mass = 1.0, inertia = 1.0, stiffness = 1.0, reach = 0.0, rest = 0.0, g = 0.0;
  for (std::int32_t b = 0; b < body_count(); ++b) {
    mass = std::max(mass, mass_[b]);
    inertia = std::max(inertia, inertia_[b]);
  }
  for (const SpringDef& s : springs_) {
    stiffness = std::max(stiffness, s.stiffness);
    reach = std::max({reach, s.anchor_i.norm(), s.anchor_j.norm()});
    rest = std::max(rest, s.rest_length);
  }
  for (const GravityDef& field : gravity_) g += field.acceleration.norm();
  const double c = std::max({mass, inertia, stiffness, mass * g});
  const double terms = static_cast<double>(body_count()) + static_cast<double>(spring_count()) + 1.0;
  const double b = (std::sqrt(1e300 / (4.0 * terms * c)) - 2.0 * reach - rest - 1.0) / 3.0;
  return std::isfinite(b) && b > 0.0 ? b : 0.0;  // 0: every step takes the exact search
}

namespace {

// max |v| over columns, NaN when any value is NaN (inf is the max).
double peak_abs(std::initializer_list<const std::vector<double>*> columns) {
  double peak = 0.0;
  for (const std::vector<double>* column : columns) {
    for (double v : *column) {
      const double a = std::abs(v);
      if (!(a <= peak)) peak = a;  // a NaN sticks: nothing compares <= it
      if (peak != peak) return peak;
    }
  }
  return peak;
}

// Whether every |v| <= limit (false for NaN). This runs after every step of every run, and -O2
// does not vectorise an all-of reduction, so on x86-64 it is SSE2 (part of the base ISA): two
// lanes, two independent masks per iteration.
bool all_within(std::initializer_list<const std::vector<double>*> columns, double limit) {
  for (const std::vector<double>* column : columns) {
    const double* p = column->data();
    const std::size_t n = column->size();
    std::size_t i = 0;
#if defined(__SSE2__)
    const __m128d magnitude = _mm_castsi128_pd(_mm_set1_epi64x(INT64_MAX));  // clears the sign
    const __m128d hi = _mm_set1_pd(limit);
    __m128d in0 = _mm_cmpeq_pd(hi, hi), in1 = in0;  // all ones (limit is not NaN)
    for (; i + 4 <= n; i += 4) {
      in0 = _mm_and_pd(in0, _mm_cmple_pd(_mm_and_pd(_mm_loadu_pd(p + i), magnitude), hi));
      in1 = _mm_and_pd(in1, _mm_cmple_pd(_mm_and_pd(_mm_loadu_pd(p + i + 2), magnitude), hi));
    }
    if (_mm_movemask_pd(_mm_and_pd(in0, in1)) != 3) return false;  // NaN fails <= too
#endif
    for (; i < n; ++i) {
      if (!(std::abs(p[i]) <= limit)) return false;
    }
  }
  return true;
}

}  // namespace

bool World::velocities_within(double limit) const {
  return all_within({&vx_, &vy_, &omega_}, limit);
}

double World::peak_velocity() const {
  return peak_abs({&vx_, &vy_, &omega_});
}

double World::peak_position() const {
  return peak_abs({&x_, &y_, &theta_});
}

std::span<const Vec2> World::hull(BodyId b) const {
  const Shape& s = shapes_[shape_[b.index]];
  return {shape_vertices_.data() + s.first, static_cast<std::size_t>(s.count)};
}

bool polygon_contains(std::span<const Vec2> polygon, const Vec2& q) {
  // Each edge crossing the horizontal line through q, with q on its left going up (+1) or on its
  // right going down (-1): the sum is how often the boundary winds around q.
  int winding = 0;
  for (std::size_t k = 0; k < polygon.size(); ++k) {
    const Vec2& a = polygon[k];
    const Vec2& e = polygon[(k + 1) % polygon.size()];
    const Vec2 edge = e - a, to_q = q - a;
    const double side = edge.x() * to_q.y() - edge.y() * to_q.x();  // (e - a) x (q - a)
    if (a.y() <= q.y() && e.y() > q.y() && side > 0) ++winding;
    if (a.y() > q.y() && e.y() <= q.y() && side < 0) --winding;
  }
  return winding != 0;
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
  if (uses_rotations()) ::sincos(theta_[i], &sin_[i], &cos_[i]);  // as update_rotations()
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
           winds_.capacity() * sizeof(WindDef) + slots_.capacity() * sizeof(Slot);
  for (const auto* column : {&shape_refs_, &body_ids_, &body_slot_, &spring_ids_, &free_slots_}) {
    bytes += column->capacity() * sizeof(std::int32_t);
  }
  return bytes;
}

}  // namespace rbsim
