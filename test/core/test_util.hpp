// Helpers shared by the core property tests.
#pragma once

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>
#include <utility>

#include "rbsim/core.hpp"

namespace rbsim::test {

inline World make_world(const WorldDef& def) {
  Result<World> w = World::create(def);
  if (!w) throw std::runtime_error("World::create failed: " + w.error().message);
  return std::move(w.value());
}

inline double cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}
inline Vec2 perp(const Vec2& a) {
  return {-a.y(), a.x()};
}  // J a: +90 degrees
inline Vec2 rotate(double theta, const Vec2& v) {
  const double c = std::cos(theta), s = std::sin(theta);
  return {c * v.x() - s * v.y(), s * v.x() + c * v.y()};
}

// Bit-for-bit equality (distinguishes -0.0 and +0.0, treats equal NaNs as equal).
inline bool same_bits(double a, double b) {
  return std::memcmp(&a, &b, sizeof a) == 0;
}

struct Totals {
  Vec2 p{0.0, 0.0};
  double l = 0.0, l_spin = 0.0, l_scale = 0.0;
};
inline Totals totals(const World& w) {
  Totals t;
  for (std::int32_t b = 0; b < w.body_count(); ++b) {
    const BodyQuantities q = w.quantities(BodyId{b});
    t.p += q.momentum;
    t.l += q.l_point + q.l_spin;
    t.l_spin += q.l_spin;
    t.l_scale += std::abs(q.l_point) + std::abs(q.l_spin);
  }
  return t;
}

// Definitions by field name, so the tests do not depend on the order of the struct members.
inline SpringDef spring(std::int32_t body_i, Vec2 anchor_i, std::int32_t body_j, Vec2 anchor_j, double k,
                        double l0) {
  SpringDef s;
  s.body_i = body_i;
  s.anchor_i = anchor_i;
  s.body_j = body_j;
  s.anchor_j = anchor_j;
  s.stiffness = k;
  s.rest_length = l0;
  return s;
}
inline WindDef wind(double beta, Vec2 velocity, std::int32_t points_per_edge) {
  WindDef w;
  w.beta = beta;
  w.velocity = velocity;
  w.points_per_edge = points_per_edge;
  return w;
}

}  // namespace rbsim::test
