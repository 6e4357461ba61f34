// FOSSSim XML scene loader. Every rejection names file, line, node, attribute and the rule.
#include "rbsim/scene.hpp"

#include <tinyxml2.h>

#include <cmath>
#include <filesystem>
#include <limits>

#include "loader.hpp"
#include "rbsim/assert.hpp"
#include "rbsim/read_file.hpp"

namespace rbsim {

std::int64_t steps_for(double duration, double dt) {
  const double n = std::ceil(duration / dt);
  if (!(n > 0.0)) return 0;  // also NaN
  // A duration of 1e100 s is a valid scene that runs until stopped: more steps than int64 holds
  // saturate (converting such a double to an integer is undefined; the fuzzer found it).
  constexpr double kMax = 9223372036854774784.0;  // the largest double below 2^63
  return n >= kMax ? std::numeric_limits<std::int64_t>::max() : static_cast<std::int64_t>(n);
}

std::int64_t Scene::step_count() const {
  return steps_for(duration, world.dt);
}

Color default_body_color(std::int32_t index) {
  // A qualitative palette (Tableau 10) that reads well on a white background.
  static constexpr Color kPalette[] = {{0.122, 0.467, 0.706}, {1.000, 0.498, 0.055}, {0.173, 0.627, 0.173},
                                       {0.839, 0.153, 0.157}, {0.580, 0.404, 0.741}, {0.549, 0.337, 0.294},
                                       {0.890, 0.467, 0.761}, {0.498, 0.498, 0.498}, {0.737, 0.741, 0.133},
                                       {0.090, 0.745, 0.812}};
  return kPalette[static_cast<std::size_t>(index) % std::size(kPalette)];
}

namespace {

using scene_detail::BodyRead;
using scene_detail::ColorRead;
using scene_detail::Deferred;
using scene_detail::VertexRead;

// A whole scene: the scene-wide elements here, the body elements through the shared readers.
class SceneLoader : public scene_detail::Reader {
 public:
  explicit SceneLoader(std::string path) : Reader(std::move(path)) {}

  Scene load(const tinyxml2::XMLDocument& doc);

 private:
  void element(const tinyxml2::XMLElement* e);
  bool scene_wide_element(const tinyxml2::XMLElement* e);
  void resolve();

  Scene scene_;
  std::vector<VertexRead> vertices_;
  std::vector<BodyRead> bodies_;
  std::vector<std::pair<Deferred, Deferred>> spring_ends_;
  std::vector<ColorRead> body_colors_, spring_colors_;
};

// The elements that describe the whole scene (scene_detail::kSceneWideElements); false for others.
bool SceneLoader::scene_wide_element(const tinyxml2::XMLElement* e) {
  const std::string_view name = e->Name();
  if (name == "simtype") {
    once(e);
    check_attributes(e, {"type"}, false);
    const std::string type = raw(e, "type");
    if (type == "particle-system")
      fail(e, "type", "simtype 'particle-system' is not supported (rbsim simulates 'rigid-body')");
    if (type != "rigid-body") fail(e, "type", "unknown simtype \"" + type + "\" (expected 'rigid-body')");
  } else if (name == "duration") {
    once(e);
    check_attributes(e, {"time"}, false);
    scene_.duration = non_negative(e, "time");
  } else if (name == "maxsimfreq") {
    once(e);
    check_attributes(e, {"max"}, false);
    scene_.max_sim_freq = positive(e, "max");
  } else if (name == "viewport") {
    once(e);
    check_attributes(e, {"cx", "cy", "size"}, false);
    scene_.viewport = Viewport{number(e, "cx"), number(e, "cy"), positive(e, "size")};
  } else if (name == "backgroundcolor") {
    once(e);
    check_attributes(e, {"r", "g", "b"}, false);
    scene_.background = color(e);
  } else if (name == "scenetag") {
    once(e);
    check_attributes(e, {"tag"}, false);
    scene_.tag = raw(e, "tag");
  } else if (name == "rigidbodyintegrator") {
    once(e);
    check_attributes(e, {"type", "dt"}, false);
    const std::string type = raw(e, "type");
    if (type == "explicit-euler") {
      scene_.world.integrator = Integrator::ExplicitEuler;
    } else if (type == "symplectic-euler") {
      scene_.world.integrator = Integrator::SymplecticEuler;
    } else {
      fail(e, "type", "unknown integrator \"" + type + "\" (expected explicit-euler or symplectic-euler)");
    }
    scene_.world.dt = positive(e, "dt");
  } else if (name == "rigidbodygravityforce") {
    check_attributes(e, {"fx", "fy"}, false);
    scene_.forces.push_back(
        {ForceRef::Kind::Gravity, static_cast<std::int32_t>(scene_.world.gravity.size())});
    scene_.world.gravity.push_back(GravityDef{{number(e, "fx"), number(e, "fy")}});
  } else if (name == "rigidbodywindforce") {
    check_attributes(e, {"beta", "fx", "fy", "pointsperedge"}, false);
    WindDef w;
    w.beta = non_negative(e, "beta");
    w.velocity = {number(e, "fx"), number(e, "fy")};
    const std::int64_t points = integer(e, "pointsperedge");
    if (points < 2 || points > 1'000'000) {
      fail(e, "pointsperedge", "must be an integer in [2, 1000000] (got " + std::to_string(points) + ")");
    }
    w.points_per_edge = static_cast<std::int32_t>(points);
    scene_.forces.push_back({ForceRef::Kind::Wind, static_cast<std::int32_t>(scene_.world.winds.size())});
    scene_.world.winds.push_back(w);
  } else {
    return false;
  }
  return true;
}

void SceneLoader::element(const tinyxml2::XMLElement* e) {
  const std::string_view name = e->Name();
  const bool scene_wide = scene_wide_element(e);
  RBSIM_ASSERT(scene_wide == scene_detail::is_scene_wide(name),
               "kSceneWideElements lists what a scene reads");
  if (scene_wide) return;
  if (name == "description") {
    scene_.description = description(e);
  } else if (name == "rigidbodyvertex") {
    vertices_.push_back(vertex(e));
  } else if (name == "rigidbody") {
    bodies_.push_back(body(e));
  } else if (name == "rigidbodyspringforce") {
    scene_.world.springs.push_back(spring(e, {"i", "pix", "piy", "j", "pjx", "pjy", "k", "l0"}));
    spring_ends_.push_back({{e, "i", integer(e, "i")}, {e, "j", integer(e, "j")}});
  } else if (name == "rigidbodycolor") {
    body_colors_.push_back(body_color(e));
  } else if (name == "rigidbodyspringcolor") {
    spring_colors_.push_back(spring_color(e));
  } else {
    unknown_node(e);
  }
}

// Vertices form one global list in file order; bodies, springs and colours may refer ahead.
void SceneLoader::resolve() {
  for (const BodyRead& body : bodies_) scene_.world.bodies.push_back(resolve_hull(body, vertices_));
  const auto body_count = static_cast<std::int64_t>(bodies_.size());
  for (std::size_t s = 0; s < spring_ends_.size(); ++s) {
    const auto& [i, j] = spring_ends_[s];
    for (const Deferred* end : {&i, &j}) check_body_index(*end, body_count, "(-1 = fixed point)");
    scene_.world.springs[s].body_i = static_cast<std::int32_t>(i.value);
    scene_.world.springs[s].body_j = static_cast<std::int32_t>(j.value);
  }
  for (std::int32_t b = 0; b < body_count; ++b) scene_.body_colors.push_back(default_body_color(b));
  scene_.spring_colors.assign(spring_ends_.size(), default_spring_color());
  apply_colors(body_colors_, scene_.body_colors, "body");
  apply_colors(spring_colors_, scene_.spring_colors, "spring");
  // Checks that need whole bodies (e.g. coincident vertices) are the core's.
  for (std::size_t b = 0; b < bodies_.size(); ++b) check_not_degenerate(bodies_[b], scene_.world.bodies[b]);
}

Scene SceneLoader::load(const tinyxml2::XMLDocument& doc) {
  const tinyxml2::XMLElement* root = Reader::root(doc, "root node must be <scene>");
  for (const tinyxml2::XMLElement* e = root->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    element(e);
  }
  const int end_line = root->GetLineNum();
  if (!seen("rigidbodyintegrator")) fail(end_line, "<scene>: missing node <rigidbodyintegrator>");
  if (!seen("duration")) fail(end_line, "<scene>: missing node <duration>");
  resolve();
  scene_.warnings = take_warnings();
  return std::move(scene_);
}

std::string stem_of(const std::string& path) {
  return std::filesystem::path(path).stem().string();
}

}  // namespace

Result<Scene> parse_scene(std::string_view text, const std::string& path) {
  SceneLoader loader(path);
  Result<Scene> loaded = scene_detail::parse_with(loader, text, path, "file");
  if (!loaded) return loaded.error();
  Scene scene = std::move(loaded.value());
  scene.path = path;
  scene.name = stem_of(path);
  // Backstop: anything the loader let through must also satisfy the core's own validation.
  if (Result<World> w = World::create(scene.world); !w) return with_context(path + ": ", w.error());
  return scene;
}

Result<Scene> load_scene(const std::string& path) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) return Error{path + ": is a directory, not a scene file"};
  Result<std::string> text = read_text_file(path, "scene file");
  if (!text) return text.error();
  return parse_scene(text.value(), path);
}

}  // namespace rbsim
