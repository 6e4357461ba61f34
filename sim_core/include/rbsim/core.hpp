// rbsim simulation core: 2D rigid bodies made of point-mass vertices, no collisions.
//
// Units are whatever the scene uses, consistently (FOSSSim scenes are SI-like: m, kg, s).
// Angles are radians, counter-clockwise positive; torque and angular momentum are the z
// component of the 3D cross product, so a x b = a.x b.y - a.y b.x.
//
// The world keeps its hot state as flat arrays (struct of arrays): one entry per body for
// position, angle, velocity, angular velocity, force and torque. Hull shapes are stored once and
// referenced by index. Nothing here knows about files, DDS or MCAP.
#pragma once

#include <Eigen/Core>

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "rbsim/status.hpp"

namespace rbsim {

// rbsim's version, "MAJOR.MINOR.PATCH": project(VERSION) in the top-level CMakeLists.txt, the one
// place it is set (rbsim --version, the MCAP header's library string, the packages).
const char* version();

using Vec2 = Eigen::Vector2d;

// Whether `q` lies inside `polygon` (a non-zero winding number, either vertex order; fewer than 3
// vertices enclose nothing): a hull's inside, for the checks and the entity filters above the core.
bool polygon_contains(std::span<const Vec2> polygon, const Vec2& q);

// ---------------------------------------------------------------------------------------------
// Definitions (what a scene describes). Plain structs with defaults.

enum class Integrator : std::uint8_t {
  ExplicitEuler,    // x += dt v (old v), v += dt a
  SymplecticEuler,  // v += dt a, x += dt v (new v): implicit in velocity for the position update
};

const char* to_string(Integrator integrator);

struct BodyDef {
  std::vector<Vec2> hull;      // world positions at t = 0, clockwise order; >= 2 vertices
  std::vector<double> masses;  // one per hull vertex, each > 0
  Vec2 velocity{0.0, 0.0};     // centre-of-mass velocity
  double omega = 0.0;          // angular velocity about the centre of mass (rad/s, CCW > 0)
  double radius = 0.1;         // rendering radius (not used by the dynamics)
};

inline constexpr std::int32_t kFixed = -1;  // spring end fixed in space

struct SpringDef {
  std::int32_t body_i = kFixed;  // body index or kFixed
  std::int32_t body_j = kFixed;
  Vec2 anchor_i{0.0, 0.0};  // body space offset from the centre of mass, or world point if fixed
  Vec2 anchor_j{0.0, 0.0};
  double stiffness = 0.0;    // k
  double rest_length = 0.0;  // l0
};

struct GravityDef {
  Vec2 acceleration{0.0, 0.0};  // g: every vertex feels m_i g (FOSSSim's fx, fy)
};

struct WindDef {
  double beta = 1.0;        // drag coefficient per unit edge length
  Vec2 velocity{0.0, 0.0};  // wind velocity
  std::int32_t points_per_edge = 2;
};

struct WorldDef {
  Integrator integrator = Integrator::SymplecticEuler;
  double dt = 0.01;
  std::vector<BodyDef> bodies;
  std::vector<SpringDef> springs;  // each force kind is applied in this (file) order
  std::vector<GravityDef> gravity;
  std::vector<WindDef> winds;
};

// A body's or spring's position in the world's dense arrays, valid until the next structural
// change (add_body, remove_body, add_spring, remove_spring): the index every per-body column, and
// every message built from them, uses at this step.
struct BodyId {
  std::int32_t index = -1;
};
struct SpringId {
  std::int32_t index = -1;
};

// A body's handle, valid across structural changes (Box2D's b2BodyId): the body's slot plus one
// (0 is the null handle) and the generation the slot had when the body was made. The generation
// is the body's id plus one, and ids are never reused within a world's lineage (see
// World::continue_ids), so a handle to a removed body never finds another one: find() refuses it.
struct BodyHandle {
  std::int32_t index1 = 0;
  std::uint32_t generation = 0;
  bool operator==(const BodyHandle&) const = default;
};

struct BodyState {
  Vec2 position{0.0, 0.0};  // centre of mass X
  double theta = 0.0;       // rotation from body space
  Vec2 velocity{0.0, 0.0};  // V = dX/dt
  double omega = 0.0;
};

// The graded per-body quantities (docs/rigid-body-milestone.md section 4).
struct BodyQuantities {
  Vec2 momentum{0.0, 0.0};  // P = M V
  double l_point = 0.0;     // M (X x V)
  double l_spin = 0.0;      // I omega
  double t_point = 0.0;     // M |V|^2 / 2
  double t_spin = 0.0;      // I omega^2 / 2
};

struct SpringState {
  Vec2 end_i{0.0, 0.0};  // world endpoints
  Vec2 end_j{0.0, 0.0};
  double length = 0.0;
  double potential = 0.0;  // k (l - l0)^2 / 2
};

// Scene-wide energies. Wind is not conservative and has no potential.
struct Energy {
  double u_gravity = 0.0;  // sum over bodies of -M g . X
  double u_spring = 0.0;
  double t_point = 0.0;
  double t_spin = 0.0;
  double potential() const { return u_gravity + u_spring; }
  double kinetic() const { return t_point + t_spin; }
  double total() const { return potential() + kinetic(); }
};

// Scene-wide sums of the per-body quantities: P = sum of M V, L = sum of (L_point + L_spin), both
// about the world origin.
struct SceneTotals {
  Vec2 momentum{0.0, 0.0};
  double angular = 0.0;
};

namespace detail {
// The wind force and torque on a hull are linear in the body-frame relative wind u and in
// omega; these are their coefficients, summed over the edges once per shape (src/wind.cpp).
struct WindMoments {
  double axx = 0, axy = 0, ayy = 0;  // F_body = beta (A u - omega b), A symmetric
  double bx = 0, by = 0;
  double cx = 0, cy = 0, d = 0;  // torque = beta (c . u - omega d)
};
}  // namespace detail

// ---------------------------------------------------------------------------------------------
class World {
 public:
  // Validates the definition (positive masses, dt > 0, indices in range, non-degenerate bodies)
  // and computes M, X, I and body-space hulls. Body space has its origin at the centre of mass
  // and is aligned with world space at t = 0, so theta starts at 0.
  static Result<World> create(const WorldDef& def);

  // Advances one time step of dt: clears forces, accumulates gravity, springs and wind (each
  // in definition order), integrates. Does not allocate.
  void step();

  // -- Structure: bodies and springs added and removed between steps (src/structure.cpp) --
  //
  // The arrays stay dense and in a stable order: a new body or spring is appended, a removal
  // closes the gap by moving the later entries down one (O(n) at that boundary). Order is kept
  // because it fixes every sum (a body's spring forces add up in spring order, the totals in body
  // order), so a world edited this way steps bit for bit as a world created from the edited
  // definition: a body added at step k with state s is the definition's last body, set to s at k.
  //
  // Ids: the scene's bodies and springs get their file index; each body or spring added later gets
  // the next unused id, never one given before (removed or not). ids are what messages carry, so a
  // body's identity survives the removal of bodies before it; body_ids() and spring_ids() are
  // strictly increasing in dense order, so find_body_id() and find_spring_id() are binary searches.

  // Reserves every per-body and per-spring array (no allocation until a change goes past it); a
  // change beyond the reserve grows the arrays at that boundary, never inside step().
  void reserve(std::int32_t bodies, std::int32_t springs);
  // Continues the ids of an earlier world of the same session (a reset or reload creates a new
  // World): the next added body and spring take ids at least these.
  void continue_ids(std::int32_t next_body_id, std::int32_t next_spring_id);
  std::int32_t next_body_id() const { return next_body_id_; }
  std::int32_t next_spring_id() const { return next_spring_id_; }

  // Adds a body whose hull and masses are `def`'s (in any frame: the body space is the hull about
  // its centre of mass, as create() makes it, and def.velocity/omega are ignored) in `state`: the
  // centre of mass at state.position, rotated by state.theta from that frame, moving with
  // state.velocity and state.omega. Refuses what create() refuses, and a non-finite state.
  [[nodiscard]] Result<BodyHandle> add_body(const BodyDef& def, const BodyState& state);
  // Adds a spring between bodies of this world (body_i/j are dense indices or kFixed); returns
  // its id. Refuses what create() refuses.
  [[nodiscard]] Result<std::int32_t> add_spring(const SpringDef& def);
  // Removes a body and, first, every spring attached to it (their ids, in spring order, appended
  // to `removed_springs` if given). A stale or null handle is refused and changes nothing.
  [[nodiscard]] Status remove_body(BodyHandle body, std::vector<std::int32_t>* removed_springs = nullptr);
  [[nodiscard]] Status remove_spring(std::int32_t spring_id);

  BodyHandle handle(BodyId b) const;
  std::optional<BodyId> find(BodyHandle h) const;  // nullopt: null, removed or never made
  std::int32_t body_id(BodyId b) const { return body_ids_[b.index]; }
  std::int32_t spring_id(SpringId s) const { return spring_ids_[s.index]; }
  std::span<const std::int32_t> body_ids() const { return body_ids_; }
  std::span<const std::int32_t> spring_ids() const { return spring_ids_; }
  std::optional<BodyId> find_body_id(std::int32_t id) const;
  std::optional<SpringId> find_spring_id(std::int32_t id) const;

  std::int32_t body_count() const { return static_cast<std::int32_t>(x_.size()); }
  std::int32_t spring_count() const { return static_cast<std::int32_t>(springs_.size()); }
  Integrator integrator() const { return integrator_; }
  double dt() const { return dt_; }
  std::int64_t step_index() const { return step_; }
  double time() const { return static_cast<double>(step_) * dt_; }

  // Per-body constants.
  double mass(BodyId b) const { return mass_[b.index]; }
  double inertia(BodyId b) const { return inertia_[b.index]; }
  double radius(BodyId b) const { return radius_[b.index]; }
  // Hull vertices in body space (relative to the centre of mass at theta = 0).
  std::span<const Vec2> hull(BodyId b) const;
  Vec2 world_vertex(BodyId b, std::int32_t vertex) const;

  BodyState state(BodyId b) const;
  void set_state(BodyId b, const BodyState& s);  // e.g. to restart from a recorded step
  void set_step_index(std::int64_t step) { step_ = step; }
  BodyQuantities quantities(BodyId b) const;

  // Changes between steps (a control command at a step boundary, never inside step()). Each
  // refuses a value the scene loader would refuse (non-finite, negative k, l0 or beta, fewer than
  // 1 point per edge, an index out of range) and then changes nothing; callers validate first
  // (rbsim/control.hpp), these guard the core. Derived data stays consistent: finite_bound()
  // follows gravity and the springs, a wind's edge moments follow its points per edge. Runners
  // that cached finite_bound() or the peaks must read them again (the Driver does). None of them
  // allocates.
  [[nodiscard]] Status set_gravity(std::int32_t field, const Vec2& acceleration);  // gravity()[field]
  [[nodiscard]] Status set_wind(std::int32_t wind, const WindDef& def);            // winds()[wind]
  [[nodiscard]] Status set_spring(SpringId s, double stiffness, double rest_length);
  // An instantaneous linear impulse J (N s, world axes) at the body point p (m, body frame,
  // relative to the centre of mass): V += J / M, omega += ((R(theta) p) x J) / I.
  [[nodiscard]] Status apply_impulse(BodyId b, const Vec2& impulse, const Vec2& point);
  // Force and torque accumulated by the last step() (zero before the first step).
  Vec2 force(BodyId b) const { return {fx_[b.index], fy_[b.index]}; }
  double torque(BodyId b) const { return tau_[b.index]; }

  const SpringDef& spring(SpringId s) const { return springs_[s.index]; }
  SpringState spring_state(SpringId s) const;
  std::span<const GravityDef> gravity() const { return gravity_; }
  std::span<const WindDef> winds() const { return winds_; }

  // U = gravity + springs, as graded by the reference.
  double potential_energy() const { return energy().potential(); }
  Energy energy() const;
  // Summed in body order from zero, so every output that carries them (energy CSV, EnergyTerms,
  // plots) holds the same bits.
  SceneTotals totals() const;

  // Raw state arrays for adapters that copy whole columns.
  std::span<const double> x() const { return x_; }
  std::span<const double> y() const { return y_; }
  std::span<const double> theta() const { return theta_; }
  std::span<const double> vx() const { return vx_; }
  std::span<const double> vy() const { return vy_; }
  std::span<const double> omega() const { return omega_; }
  // The same arrays, writable in place, for an adapter that hands out views of the world's own
  // memory (the Python package's NumPy views). Writing them between steps sets the state the next
  // step starts from, as set_state() does; after writing theta, call sync_rotations() before the
  // next step (or spring_state()), since springs and wind read the rotations derived from it.
  struct StateColumns {
    std::span<double> x, y, theta, vx, vy, omega;
  };
  StateColumns state_columns() { return {x_, y_, theta_, vx_, vy_, omega_}; }
  void sync_rotations() {
    if (uses_rotations()) update_rotations();
  }
  std::span<const double> masses() const { return mass_; }
  std::span<const double> inertias() const { return inertia_; }
  std::span<const double> radii() const { return radius_; }

  // The first non-finite value in the state or in a quantity derived from it, if any (checked
  // after each step by runners, so a diverging scene stops with a clear error instead of writing
  // inf or NaN).
  struct NonFinite {
    BodyId body;           // index -1 for a scene-wide quantity
    const char* quantity;  // "x" .. "omega", "px" .. "T_spin", "U_gravity", "U_spring" or "E"
  };
  std::optional<NonFinite> find_nonfinite() const;

  // The divergence check's cheap pass. While every |x|, |y|, |theta|, |vx|, |vy|, |omega| is at
  // most finite_bound() (fixed by create() from the masses, inertias, stiffnesses, gravity and
  // spring geometry), every quantity derived from the state (P, L, T, U, E, spring states) is
  // finite, so a runner needs find_nonfinite()'s exact search only when a peak exceeds it.
  double finite_bound() const { return finite_bound_; }
  // max |vx|, |vy|, |omega| (or max |x|, |y|, |theta|); NaN when any of them is NaN.
  double peak_velocity() const;
  double peak_position() const;
  // Whether every |vx|, |vy|, |omega| is at most `limit` (false for NaN): the per-step pass,
  // vectorised.
  bool velocities_within(double limit) const;

  // The invariants of the arrays at a step boundary: one entry per body in every per-body array,
  // positive finite masses, inertias and radii, every shape, spring end and wind moment index in
  // range, cos/sin equal to those of theta wherever springs or wind read them (a writer of
  // state_columns() that forgot sync_rotations() breaks this one), dt > 0, step >= 0. Returns the
  // first one broken. step() asserts it (RBSIM_ASSERT: Debug builds and the sanitizer stage); it
  // costs a pass over the arrays.
  [[nodiscard]] Status validate() const;

  // Heap bytes held by the world (capacity of every array), for the per-body memory budget.
  std::size_t memory_bytes() const;
  std::int32_t shape_count() const { return static_cast<std::int32_t>(shapes_.size()); }

 private:
  // A hull in body space, stored once in shape_vertices_.
  struct Shape {
    std::int32_t first = 0;
    std::int32_t count = 0;
  };
  using WindMoments = detail::WindMoments;
  World() = default;

  // A slot of the handle table: the body's dense index (-1 while free) and the generation of the
  // body that holds or last held it.
  struct Slot {
    std::int32_t dense = -1;
    std::uint32_t generation = 0;
  };

  double compute_finite_bound() const;
  std::int32_t add_shape(std::span<const Vec2> local);
  void release_shape(std::int32_t shape);
  void compact_shapes();
  void erase_body_columns(std::int32_t dense);
  void init_identity();
  Status validate_identity() const;
  void update_rotations();
  bool uses_rotations() const { return !springs_.empty() || !winds_.empty(); }
  void accumulate_gravity();
  void accumulate_springs();
  void accumulate_wind();
  void integrate();

  Integrator integrator_ = Integrator::SymplecticEuler;
  double dt_ = 0.0;
  double finite_bound_ = 0.0;
  std::int64_t step_ = 0;

  // Hot state, one entry per body.
  std::vector<double> x_, y_, theta_, vx_, vy_, omega_;
  std::vector<double> fx_, fy_, tau_;
  std::vector<double> cos_, sin_;  // cos/sin of theta, kept current while uses_rotations()
  // Per-body constants.
  std::vector<double> mass_, inertia_, radius_;
  std::vector<std::int32_t> shape_;  // index into shapes_

  // Shapes: stored once, shared by bodies whose body-space hulls are bit-identical.
  std::vector<Shape> shapes_;
  std::vector<Vec2> shape_vertices_;       // all hulls, body space, concatenated
  std::vector<WindMoments> wind_moments_;  // [wind * shapes + shape]
  std::vector<std::int32_t> shape_refs_;   // bodies using each shape; 0: garbage until compacted
  std::int32_t dead_shapes_ = 0;

  // Identity (cold): per body its id and slot, per spring its id; the slot table and its free
  // list (last freed, first reused, so handles are deterministic).
  std::vector<std::int32_t> body_ids_, body_slot_, spring_ids_;
  std::vector<Slot> slots_;
  std::vector<std::int32_t> free_slots_;
  std::int32_t next_body_id_ = 0, next_spring_id_ = 0;

  std::vector<SpringDef> springs_;
  std::vector<GravityDef> gravity_;
  std::vector<WindDef> winds_;
};

}  // namespace rbsim
