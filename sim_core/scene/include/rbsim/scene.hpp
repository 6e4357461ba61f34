// FOSSSim-style XML scenes: loading, validation with located errors, and the scene's cold data
// (names, colours, viewport) that the dynamics never touch; and spawnable fragments, one body in
// the same dialect.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/core.hpp"

namespace rbsim {

struct Color {
  double r = 0.0, g = 0.0, b = 0.0;  // each in [0, 1]
  bool operator==(const Color&) const = default;
};

struct Viewport {
  double cx = 0.0, cy = 0.0;  // centre
  double size = 1.0;          // half-extent of the shorter side (FOSSSim convention)
};

// A gravity or wind force of the scene, in file order: forces are numbered together from 0 as
// the scene lists them (the `forces.<i>.*` parameters, rbsim/control.hpp); `index` is into
// WorldDef::gravity or WorldDef::winds. Springs are numbered apart (WorldDef::springs).
struct ForceRef {
  enum class Kind : std::uint8_t { Gravity, Wind };
  Kind kind = Kind::Gravity;
  std::int32_t index = 0;
};

struct Scene {
  std::string path;  // as given to load_scene
  std::string name;  // file stem, e.g. "test00ee"
  std::string description;
  std::string tag;  // <scenetag>
  WorldDef world;
  double duration = 0.0;  // seconds of simulated time
  std::optional<double> max_sim_freq;
  std::optional<Viewport> viewport;
  Color background{1.0, 1.0, 1.0};
  std::vector<Color> body_colors;     // one per body
  std::vector<Color> spring_colors;   // one per spring
  std::vector<ForceRef> forces;       // the gravity and wind forces in file order
  std::vector<std::string> warnings;  // "file:line: warning: ..." lines, e.g. unknown nodes

  // Steps to cover `duration`: ceil(duration / dt) in double precision, so 0.07 / 0.01 gives 8.
  std::int64_t step_count() const;
};

// Number of steps of size dt that cover a duration (see Scene::step_count); 0 for a duration <= 0
// (or NaN), INT64_MAX when the count does not fit.
std::int64_t steps_for(double duration, double dt);

// Loads and validates a scene file. On failure the error message is one line:
//   "<file>:<line>: <node> attribute 'a': <rule broken>"
// (node and attribute omitted where they do not apply, e.g. malformed XML or a missing file).
Result<Scene> load_scene(const std::string& path);
// Same, from text already in memory; `path` only names the source in messages.
Result<Scene> parse_scene(std::string_view text, const std::string& path);

// The default colour of body `index` when the scene gives none (a fixed palette).
Color default_body_color(std::int32_t index);

// A spawnable fragment: FOSSSim scene XML describing ONE body to add to a running world
// (simulation_interfaces' SpawnEntity resource). Read by the scene loader's own element and
// attribute rules, with errors worded as load_scene's ("<file>:<line>: <node> attribute 'a': rule").
//   - The root is <scene> (another: "<robot>: a fragment's root must be <scene>").
//   - <rigidbodyvertex x y m>: indices local to the fragment, from 0; each vertex on the body's hull.
//   - Exactly one <rigidbody p... vx vy omega r> (none, or a second, refused at its line).
//   - <rigidbodyspringforce pix piy pjx pjy k l0> with each end either `i`/`j` (0 = the fragment's
//     body, -1 = fixed in space, nothing else) or `ibody`/`jbody`, the name (not blank) of a body of
//     the running world (never both; the parser records the name, the world resolves it).
//   - <rigidbodycolor body="0" r g b>, <rigidbodyspringcolor spring="k" r g b> (k indexes the
//     fragment's springs), <description text> (once).
//   - Scene-wide elements (simtype, duration, maxsimfreq, viewport, backgroundcolor, scenetag,
//     rigidbodyintegrator, rigidbodygravityforce, rigidbodywindforce) refused at their line;
//     unknown nodes and attributes are warnings, as in scenes.
//   - FragmentLimits: text over max_bytes refused before parsing; the first vertex or spring over
//     its limit refused at its line. Degenerate bodies are refused as in scenes.
// Any text gives a Fragment or an Error (it is network input).
struct FragmentLimits {
  std::size_t max_bytes = 1 << 20;  // text size
  std::int32_t max_vertices = 10000;
  std::int32_t max_springs = 1000;
};

struct FragmentSpringEnd {
  enum class Kind : std::uint8_t { Self, Fixed, Named };
  Kind kind = Kind::Fixed;
  std::string body;       // Kind::Named: the name of an existing body of the running world
  Vec2 anchor{0.0, 0.0};  // body space (relative to that body's centre of mass), or a world point if Fixed
};

struct FragmentSpring {
  FragmentSpringEnd end_i, end_j;
  double stiffness = 0, rest_length = 0;
  std::optional<Color> color;  // <rigidbodyspringcolor>
};

struct Fragment {
  std::string path;         // as given (names the source in messages)
  std::string description;  // <description text=...>, optional
  // hull = the fragment's vertex positions as written (fragment-local coordinates), in the
  // <rigidbody>'s p order, with their masses; velocity, omega, radius
  BodyDef body;
  std::optional<Color> color;           // <rigidbodycolor body="0">
  std::vector<FragmentSpring> springs;  // in file order
  std::vector<std::string> warnings;    // as Scene::warnings
};

// Parses and validates a fragment; `path` only names the source in messages.
Result<Fragment> parse_fragment(std::string_view text, const std::string& path,
                                const FragmentLimits& limits = {});

// The spring colour of a scene that gives none.
Color default_spring_color();

// The cold data of a world's bodies and springs as they stand, in the world's dense order (as
// World's arrays): what outputs name and colour them. A scene's bodies are body_<id>, coloured as
// it says; a spawned body has its own name and its fragment's colours (default_body_color(id),
// default_spring_color() when it gives none). `epoch` counts the structural changes of the
// session (0: the world as loaded), so an output knows a change from the start. A world loaded in
// the session (simulation_interfaces' LoadWorld, UnloadWorld: rbsim/control.hpp) brings a scene of
// its own: `scene` is the world's (its name, duration, forces, viewport), `world` counts the worlds
// loaded (0: the first; an output that cannot follow a world whose steps start again at 0 refuses a
// change that raises it).
struct Entities {
  std::vector<std::string> body_names;
  std::vector<Color> body_colors;
  std::vector<Color> spring_colors;
  std::uint32_t epoch = 0;
  std::uint32_t world = 0;
  const Scene* scene = nullptr;  // valid until the next world loads (the Controller keeps it)
};
// A scene's entities as loaded (epoch 0, world 0, `scene` it).
Entities entities_of(const Scene& scene);
// The one rule for a scene body's name: body_<id>.
std::string scene_body_name(std::int32_t id);
// Its inverse: the id when `name` is body_<digits> (no sign, no leading zero, so each id has one
// name), else nullopt.
std::optional<std::int32_t> scene_body_id(std::string_view name);

}  // namespace rbsim
