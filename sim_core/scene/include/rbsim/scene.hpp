// FOSSSim-style XML scenes: loading, validation with located errors, and the scene's cold data
// (names, colours, viewport) that the dynamics never touch.
#pragma once

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

}  // namespace rbsim
