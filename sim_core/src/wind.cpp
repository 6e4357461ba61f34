// Wind (docs/rigid-body-milestone.md 4.8) in closed form.
//
// The spec samples each hull edge i (from vertex a to the next, clockwise) at P points
// p_k = a + s_k e, s_k = (k + 1/2) / P, and applies at each
//     f_k = beta (l / P) ((w - v(p_k)) . n) n,     n = (-e.y, e.x) / l  (outward for CW hulls)
// where v(p) = V + omega J (p - X) and J rotates by +90 degrees.
//
// Work in body space: u = R^T (w - V), e and n fixed. Because J e . n = l and e x n = l,
//     (w - v(p_k)) . n = g0 - omega l s_k,   g0 = u . n - omega (J a) . n
//     (p_k - X) x n    = h0 + l s_k,          h0 = a x n
// so the per-edge sums over k only need mean(s) = 1/2 and mean(s^2) = 1/3 - 1/(12 P^2):
//     F   = beta l (u . n - omega (J m) . n) n,   m = a + e / 2 (edge midpoint)
//     tau = beta l [ (u . n)(h0 + l/2) - omega (q h0 + (q + h0) l/2 + l^2 mean(s^2)) ],  q = (J a) . n
// Both are linear in u and omega; summing the coefficients over the edges once per shape makes
// the per-body cost independent of both the vertex count and P. Zero-length edges carry no
// weight (l = 0) and are skipped rather than normalised.
#include <cmath>

#include "rbsim/core.hpp"
#include "wind_moments.hpp"

namespace rbsim {

namespace {
double cross(const Vec2& a, const Vec2& b) {
  return a.x() * b.y() - a.y() * b.x();
}
Vec2 perp(const Vec2& a) {
  return {-a.y(), a.x()};
}  // J a
}  // namespace

detail::WindMoments compute_wind_moments(std::span<const Vec2> hull, int points_per_edge) {
  const double p = points_per_edge;
  const double mean_s2 = 1.0 / 3.0 - 1.0 / (12.0 * p * p);
  detail::WindMoments m;
  const std::size_t count = hull.size();
  for (std::size_t i = 0; i < count; ++i) {
    const Vec2& a = hull[i];
    const Vec2 e = hull[(i + 1) % count] - a;
    const double l = e.norm();
    if (l == 0.0) continue;
    const Vec2 n = perp(e) / l;
    const Vec2 mid = a + 0.5 * e;
    m.axx += l * n.x() * n.x();
    m.axy += l * n.x() * n.y();
    m.ayy += l * n.y() * n.y();
    const double jm = perp(mid).dot(n);
    m.bx += l * jm * n.x();
    m.by += l * jm * n.y();
    const double h0 = cross(a, n), q = perp(a).dot(n);
    m.cx += l * (h0 + 0.5 * l) * n.x();
    m.cy += l * (h0 + 0.5 * l) * n.y();
    m.d += l * (q * h0 + 0.5 * (q + h0) * l + l * l * mean_s2);
  }
  return m;
}

void World::accumulate_wind() {
  const std::size_t shapes = shapes_.size();
  const std::int32_t n = body_count();
  for (std::size_t k = 0; k < winds_.size(); ++k) {
    const WindDef& wind = winds_[k];
    const detail::WindMoments* moments = wind_moments_.data() + k * shapes;
    const double beta = wind.beta, wx = wind.velocity.x(), wy = wind.velocity.y();
    for (std::int32_t b = 0; b < n; ++b) {
      const detail::WindMoments& m = moments[shape_[b]];
      const double c = cos_[b], s = sin_[b], om = omega_[b];
      // relative wind in body space: u = R^T (w - V)
      const double rx = wx - vx_[b], ry = wy - vy_[b];
      const double ux = c * rx + s * ry, uy = c * ry - s * rx;
      const double fbx = beta * (m.axx * ux + m.axy * uy - om * m.bx);
      const double fby = beta * (m.axy * ux + m.ayy * uy - om * m.by);
      fx_[b] += c * fbx - s * fby;
      fy_[b] += s * fbx + c * fby;
      tau_[b] += beta * (m.cx * ux + m.cy * uy - om * m.d);
    }
  }
}

}  // namespace rbsim
