// rbsim.Scene and rbsim.World: a loaded scene, and the simulation stepping in the World's own
// memory, its state arrays handed to NumPy as views (no copies).
#include <nanobind/ndarray.h>
#include <nanobind/stl/array.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <memory>

#include "bindings.hpp"
#include "interrupt.hpp"
#include "rbsim/parameters.hpp"
#include "rbsim/run.hpp"
#include "rbsim/scene.hpp"

namespace rbsim::python {

namespace {

using namespace nb::literals;

struct PyScene {
  std::shared_ptr<const Scene> scene;
};

// A World with what the Python API adds: its scene (parameters are named after it), the parameter
// table of a run of it (the names, types and rules `rbsim node` and `--commands` use), and whether
// theta was handed out writable (then the rotations are re-derived before stepping).
struct PyWorld {
  PyWorld(std::shared_ptr<const Scene> s, World w)
      : scene(std::move(s)),
        world(std::move(w)),
        table(*scene, scene->step_count(), control::RunSettings{}) {}
  std::shared_ptr<const Scene> scene;
  World world;
  control::ParameterTable table;
  bool theta_exposed = false;
};

using StateView = nb::ndarray<nb::numpy, double, nb::ndim<1>, nb::c_contig>;
using ConstView = nb::ndarray<nb::numpy, const double, nb::ndim<1>, nb::c_contig>;

PyScene load(nb::handle path_like) {
  const std::string path = fs_path(path_like);
  Result<Scene> loaded = load_scene(path);
  if (!loaded) raise_scene_error(path, loaded.error().message);
  return PyScene{std::make_shared<const Scene>(std::move(loaded.value()))};
}

PyWorld world_of(const PyScene& scene) {
  Result<World> created = World::create(scene.scene->world);
  if (!created) raise_error(scene.scene->path + ": " + created.error().message);
  return PyWorld(scene.scene, std::move(created.value()));
}

void make_world(PyWorld* self, const PyScene& scene) {
  new (self) PyWorld(world_of(scene));
}

// After a call to step(): the Driver's divergence rule, checked once per call rather than once per
// step (the peaks against World::finite_bound(), the exact search only past them).
void check_finite(const World& world) {
  const double bound = world.finite_bound();
  if (world.peak_velocity() <= bound && world.peak_position() <= bound) return;
  const std::optional<World::NonFinite> bad = world.find_nonfinite();
  if (!bad) return;
  raise_divergence(
      describe_divergence({world.step_index(), bad->body.index, bad->quantity, world.integrator()}));
}

void step(PyWorld& w, std::int64_t n) {
  if (n < 0) throw nb::value_error("World.step: n must be >= 0");
  std::int64_t done = 0;
  {
    nb::gil_scoped_release unlocked;
    if (w.theta_exposed) w.world.sync_rotations();
    InterruptPoll interrupted;
    for (; done < n && !interrupted(); ++done) w.world.step();
  }
  if (done < n) raise_interrupt();
  check_finite(w.world);
}

std::span<double> column(World& world, int which) {
  const World::StateColumns c = world.state_columns();
  const std::span<double> columns[] = {c.x, c.y, c.theta, c.vx, c.vy, c.omega};
  return columns[which];
}

constexpr const char* kColumnNames[] = {"x", "y", "theta", "vx", "vy", "omega"};
constexpr const char* kColumnDocs[] = {
    "Centre-of-mass x (m), one per body: a writable view of the World's own memory (the next step "
    "starts from what is written).",
    "Centre-of-mass y (m), one per body (writable view).",
    "Rotation from body space (rad, counter-clockwise), one per body (writable view).",
    "Centre-of-mass velocity x (m/s), one per body (writable view).",
    "Centre-of-mass velocity y (m/s), one per body (writable view).",
    "Angular velocity (rad/s, counter-clockwise), one per body (writable view).",
};

// Assigning a whole array (`world.x = values`) copies it in; the view itself stays the World's.
void assign(PyWorld& w, int which, nb::handle value) {
  nb::object array = nb::module_::import_("numpy").attr("asarray")(value, "dtype"_a = "float64");
  const std::size_t n = static_cast<std::size_t>(w.world.body_count());
  const nb::tuple shape = nb::cast<nb::tuple>(array.attr("shape"));
  if (shape.size() != 1 || nb::cast<std::size_t>(shape[0]) != n) {
    throw nb::value_error(("World." + std::string(kColumnNames[which]) + ": expected shape (" +
                           std::to_string(n) + ",), got " + nb::cast<std::string>(nb::str(shape)))
                              .c_str());
  }
  nb::object contiguous = nb::module_::import_("numpy").attr("ascontiguousarray")(array);
  const auto in = nb::cast<nb::ndarray<const double, nb::ndim<1>, nb::c_contig, nb::device::cpu>>(contiguous);
  std::copy_n(in.data(), n, column(w.world, which).begin());
  if (which == 2) w.world.sync_rotations();
}

nb::object parameter_value(const control::ParameterValue& v) {
  switch (v.type) {
    case control::ParameterType::Bool:
      return nb::bool_(v.bool_value);
    case control::ParameterType::Integer:
      return nb::int_(v.integer_value);
    case control::ParameterType::Double:
      return nb::float_(v.double_value);
    case control::ParameterType::String:
      return nb::str(v.string_value.c_str());
    default:
      return nb::none();
  }
}

std::size_t find_parameter(const PyWorld& w, const std::string& name) {
  const std::optional<std::size_t> i = w.table.find(name);
  if (!i) {
    throw nb::key_error(("World: no parameter '" + name + "' (World.parameters() lists them)").c_str());
  }
  return *i;
}

// A Python value as the parameter's type: bool, int, float or str. An int is taken for a double
// parameter (Python writes 2 for 2.0); otherwise types are as strict as rclcpp's.
control::ParameterValue to_parameter_value(const control::ParameterValue& current, nb::handle value) {
  if (nb::isinstance<nb::bool_>(value)) return control::ParameterValue::of_bool(nb::cast<bool>(value));
  if (nb::isinstance<nb::int_>(value)) {
    if (current.type == control::ParameterType::Double)
      return control::ParameterValue::of_double(nb::cast<double>(value));
    return control::ParameterValue::of_integer(nb::cast<std::int64_t>(value));
  }
  if (nb::isinstance<nb::float_>(value)) return control::ParameterValue::of_double(nb::cast<double>(value));
  if (nb::isinstance<nb::str>(value)) return control::ParameterValue::of_string(nb::cast<std::string>(value));
  throw nb::type_error("World.set_parameter: a value is a bool, int, float or str");
}

void set_parameter(PyWorld& w, const std::string& name, nb::handle value) {
  const std::size_t i = find_parameter(w, name);
  const control::Parameter p{name, to_parameter_value(w.table.value(i), value)};
  const control::SetParametersResult checked = w.table.check(p);
  if (!checked.successful) raise_error("parameter '" + name + "': " + checked.reason);
  const control::ParameterTarget target = w.table.target(i);
  if (control::is_setting(target)) {
    raise_error("parameter '" + name + "' is a setting of a live run (rbsim node), not of a World");
  }
  check(control::apply(target, p.value, w.world));
  w.table.store(i, p.value);
}

nb::dict parameters(const PyWorld& w) {
  nb::dict out;
  for (std::size_t i = 0; i < w.table.size(); ++i) {
    if (control::is_setting(w.table.target(i))) continue;
    out[w.table.descriptor(i).name.c_str()] = parameter_value(w.table.value(i));
  }
  return out;
}

void apply_impulse(PyWorld& w, std::int64_t body, std::array<double, 2> j, std::array<double, 2> p) {
  if (body < 0 || body >= w.world.body_count()) {
    throw nb::index_error(("World.apply_impulse: body " + std::to_string(body) + " is not in [0, " +
                           std::to_string(w.world.body_count()) + ")")
                              .c_str());
  }
  check(w.world.apply_impulse(BodyId{static_cast<std::int32_t>(body)}, {j[0], j[1]}, {p[0], p[1]}));
}

// The energy CSV's columns (kEnergyCsvColumns), the same sums in the same order.
nb::dict energy(const World& world) {
  const Energy e = world.energy();
  nb::dict out;
  out["U"] = e.potential();
  out["T_point"] = e.t_point;
  out["T_spin"] = e.t_spin;
  out["T"] = e.kinetic();
  out["E"] = e.total();
  out["U_gravity"] = e.u_gravity;
  out["U_spring"] = e.u_spring;
  return out;
}

nb::dict totals(const World& world) {
  const SceneTotals t = world.totals();
  nb::dict out;
  out["px"] = t.momentum.x();
  out["py"] = t.momentum.y();
  out["L"] = t.angular;
  return out;
}

void bind_scene(nb::module_& m) {
  nb::class_<PyScene>(
      m, "Scene",
      "A FOSSSim XML scene, loaded and validated (rbsim.load_scene). Immutable: each World made "
      "from it starts from its state at t = 0.")
      .def_prop_ro(
          "path", [](const PyScene& s) { return s.scene->path; }, "The file it was loaded from.")
      .def_prop_ro(
          "name", [](const PyScene& s) { return s.scene->name; }, "The file's stem.")
      .def_prop_ro("description", [](const PyScene& s) { return s.scene->description; })
      .def_prop_ro(
          "dt", [](const PyScene& s) { return s.scene->world.dt; }, "Time step (s).")
      .def_prop_ro(
          "duration", [](const PyScene& s) { return s.scene->duration; }, "Simulated seconds (s).")
      .def_prop_ro(
          "steps", [](const PyScene& s) { return s.scene->step_count(); },
          "Steps that cover the duration: ceil(duration / dt), what `rbsim run` runs.")
      .def_prop_ro("integrator",
                   [](const PyScene& s) { return std::string(to_string(s.scene->world.integrator)); })
      .def_prop_ro("body_count", [](const PyScene& s) { return s.scene->world.bodies.size(); })
      .def_prop_ro("spring_count", [](const PyScene& s) { return s.scene->world.springs.size(); })
      .def_prop_ro(
          "warnings", [](const PyScene& s) { return s.scene->warnings; },
          "The loader's warnings (\"file:line: warning: ...\"), e.g. unknown nodes.")
      .def("world", &world_of, "A new World at t = 0 (the same as rbsim.World(scene)).")
      .def("__repr__", [](const PyScene& s) {
        return "<rbsim.Scene " + s.scene->name + ": " + std::to_string(s.scene->world.bodies.size()) +
               " bodies, " + std::to_string(s.scene->world.springs.size()) + " springs, dt " +
               std::to_string(s.scene->world.dt) + ">";
      });
  m.def("load_scene", &load, "path"_a,
        "Loads and validates a FOSSSim XML scene. Raises rbsim.SceneError (file, line, node, attribute, "
        "rule) when the loader refuses it.");
}

void bind_state(nb::class_<PyWorld>& cls) {
  for (int which = 0; which < 6; ++which) {
    cls.def_prop_rw(
        kColumnNames[which],
        [which](PyWorld& w) {
          if (which == 2) w.theta_exposed = true;
          const std::span<double> c = column(w.world, which);
          return StateView(c.data(), {c.size()});
        },
        [which](PyWorld& w, nb::handle value) { assign(w, which, value); }, nb::rv_policy::reference_internal,
        kColumnDocs[which]);
  }
  const auto constant = [&cls](const char* name, std::span<const double> (World::*get)() const,
                               const char* doc) {
    cls.def_prop_ro(
        name,
        [get](const PyWorld& w) {
          const std::span<const double> c = (w.world.*get)();
          return ConstView(c.data(), {c.size()});
        },
        nb::rv_policy::reference_internal, doc);
  };
  constant("mass", &World::masses, "Body mass M (kg), one per body: a read-only view.");
  constant("inertia", &World::inertias,
           "Moment of inertia I about the centre of mass (kg m^2): read-only view.");
  constant("radius", &World::radii, "Rendering radius (m), not used by the dynamics: read-only view.");
}

}  // namespace

void bind_world(nb::module_& m) {
  bind_scene(m);
  nb::class_<PyWorld> cls(
      m, "World",
      "The simulation of a scene: point-mass bodies under gravity, springs and wind, stepped with the "
      "scene's integrator.\n\n"
      "x, y, theta, vx, vy and omega are NumPy views of the World's own state arrays (no copies): a "
      "step changes them in place, and writing them sets the state the next step starts from. mass, "
      "inertia and radius are read-only views. A view keeps its World alive.");
  cls.def("__init__", &make_world, "scene"_a, "A World at t = 0 of a loaded Scene.")
      .def(
          "step", &step, "n"_a = 1,
          "Advances n steps of dt (the GIL is released meanwhile). Raises rbsim.DivergenceError if the state "
          "is no longer finite afterwards, KeyboardInterrupt on Ctrl-C (the World is then at a step "
          "boundary).")
      .def(
          "step_until",
          [](PyWorld& w, double t) {
            const std::int64_t target = steps_for(t, w.world.dt());
            if (target > w.world.step_index()) step(w, target - w.world.step_index());
          },
          "t"_a, "Steps until the World's time reaches t: to step ceil(t / dt), as `rbsim run --duration`.")
      .def_prop_ro(
          "step_index", [](const PyWorld& w) { return w.world.step_index(); }, "Steps taken.")
      .def_prop_ro(
          "t", [](const PyWorld& w) { return w.world.time(); }, "Simulated time: step_index * dt (s).")
      .def_prop_ro("dt", [](const PyWorld& w) { return w.world.dt(); })
      .def_prop_ro("body_count", [](const PyWorld& w) { return w.world.body_count(); })
      .def_prop_ro("spring_count", [](const PyWorld& w) { return w.world.spring_count(); })
      .def_prop_ro("scene", [](const PyWorld& w) { return PyScene{w.scene}; })
      .def(
          "energy", [](const PyWorld& w) { return energy(w.world); },
          "The graded energies, as the energy CSV's columns: U, T_point, T_spin, T, E, U_gravity, U_spring.")
      .def(
          "totals", [](const PyWorld& w) { return totals(w.world); },
          "Scene totals, as the energy CSV's columns: px, py (momentum) and L (angular momentum about the "
          "origin).")
      .def("set_parameter", &set_parameter, "name"_a, "value"_a,
           "Sets a parameter of the scene as `rbsim node` and `--commands` name them (forces.<i>.fx, "
           "forces.<i>.beta, springs.<j>.k, ...; World.parameters() lists them), applied before the next "
           "step. Raises rbsim.Error, naming the rule, for a read-only parameter or a bad value.")
      .def(
          "get_parameter",
          [](const PyWorld& w, const std::string& name) {
            return parameter_value(w.table.value(find_parameter(w, name)));
          },
          "name"_a)
      .def("parameters", &parameters, "Every parameter of the World with its value, by name.")
      .def(
          "apply_impulse", &apply_impulse, "body"_a, "j"_a, "p"_a = std::array<double, 2>{0.0, 0.0},
          "Applies an instantaneous impulse J (N s, world axes) at the body point p (m, body frame, relative "
          "to the centre of mass): V += J / M, omega += ((R(theta) p) x J) / I.")
      .def("__repr__", [](const PyWorld& w) {
        return "<rbsim.World " + w.scene->name + " at step " + std::to_string(w.world.step_index()) + ": " +
               std::to_string(w.world.body_count()) + " bodies>";
      });
  bind_state(cls);
}

}  // namespace rbsim::python
