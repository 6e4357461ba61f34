// FOSSSim XML scene loader. Every rejection names file, line, node, attribute and the rule.
#include "rbsim/scene.hpp"

#include <tinyxml2.h>

#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <limits>
#include <map>

#include "rbsim/read_file.hpp"
#include "xml_dialect.hpp"

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

constexpr Color kDefaultSpringColor{0.25, 0.25, 0.25};

// Thrown only inside this file, caught in parse_scene, and turned into an Error: it keeps the
// dozens of attribute reads below free of error plumbing.
struct SceneError {
  std::string message;
};

class Loader {
 public:
  Loader(std::string path) : path_(std::move(path)) {}

  // Messages are one line: control characters in echoed attribute values (a value may span
  // lines) are shown escaped.
  static std::string one_line(const std::string& s) {
    std::string out;
    for (const char c : s) {
      if (c == '\n') {
        out += "\\n";
      } else if (c == '\r') {
        out += "\\r";
      } else if (c == '\t') {
        out += "\\t";
      } else if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) {
        static constexpr char kHex[] = "0123456789abcdef";
        out += "\\x";
        out += kHex[(static_cast<unsigned char>(c) >> 4) & 0xf];
        out += kHex[static_cast<unsigned char>(c) & 0xf];
      } else {
        out += c;
      }
    }
    return out;
  }
  [[noreturn]] void fail(int line, const std::string& what) const {
    throw SceneError{path_ + ":" + std::to_string(line) + ": " + one_line(what)};
  }
  [[noreturn]] void fail(const tinyxml2::XMLElement* e, const char* attr, const std::string& rule) const {
    fail(e->GetLineNum(), "<" + std::string(e->Name()) + "> attribute '" + attr + "': " + rule);
  }
  void warn(int line, const std::string& what) {
    scene_.warnings.push_back(path_ + ":" + std::to_string(line) + ": warning: " + what);
  }

  const char* raw(const tinyxml2::XMLElement* e, const char* attr) const {
    const char* v = e->Attribute(attr);
    if (v == nullptr) fail(e, attr, "required attribute is missing");
    return v;
  }

  static std::string_view trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
  }

  double number(const tinyxml2::XMLElement* e, const char* attr) const {
    std::string_view s = trim(raw(e, attr));
    if (!s.empty() && s.front() == '+') s.remove_prefix(1);
    double v = 0.0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || end != s.data() + s.size() || ec == std::errc::invalid_argument) {
      fail(e, attr, "must be a number (got \"" + std::string(raw(e, attr)) + "\")");
    }
    if (ec == std::errc::result_out_of_range || !std::isfinite(v)) {
      fail(e, attr, "must be a finite number (got \"" + std::string(raw(e, attr)) + "\")");
    }
    return v;
  }
  double positive(const tinyxml2::XMLElement* e, const char* attr) const {
    const double v = number(e, attr);
    if (!(v > 0)) fail(e, attr, "must be > 0 (got " + std::string(raw(e, attr)) + ")");
    return v;
  }
  double non_negative(const tinyxml2::XMLElement* e, const char* attr) const {
    const double v = number(e, attr);
    if (!(v >= 0)) fail(e, attr, "must be >= 0 (got " + std::string(raw(e, attr)) + ")");
    return v;
  }
  double unit(const tinyxml2::XMLElement* e, const char* attr) const {
    const double v = number(e, attr);
    if (!(v >= 0 && v <= 1))
      fail(e, attr, "colour component must be in [0, 1] (got " + std::string(raw(e, attr)) + ")");
    return v;
  }
  std::int64_t integer(const tinyxml2::XMLElement* e, const char* attr, const char* value) const {
    const std::string_view s = trim(value);
    std::int64_t v = 0;
    const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
    if (s.empty() || end != s.data() + s.size() || ec != std::errc()) {
      fail(e, attr, "must be an integer (got \"" + std::string(value) + "\")");
    }
    return v;
  }
  std::int64_t integer(const tinyxml2::XMLElement* e, const char* attr) const {
    return integer(e, attr, raw(e, attr));
  }
  Color color(const tinyxml2::XMLElement* e) const { return {unit(e, "r"), unit(e, "g"), unit(e, "b")}; }

  Scene load(const tinyxml2::XMLDocument& doc);

 private:
  struct Deferred {  // an index that can only be checked once the whole file is read
    const tinyxml2::XMLElement* element;
    const char* attr;
    std::int64_t value;
  };
  struct BodyRef {
    const tinyxml2::XMLElement* element;
    std::vector<Deferred> vertices;
    BodyDef def;
  };

  void once(const tinyxml2::XMLElement* e) {
    auto [it, fresh] = seen_once_.try_emplace(e->Name(), e->GetLineNum());
    if (!fresh)
      fail(e->GetLineNum(), "<" + std::string(e->Name()) + ">: node may appear only once (first at line " +
                                std::to_string(it->second) + ")");
  }
  void check_attributes(const tinyxml2::XMLElement* e, std::initializer_list<const char*> known,
                        bool repeat_p);
  void element(const tinyxml2::XMLElement* e);

  std::string path_;
  Scene scene_;
  std::map<std::string, int> seen_once_;
  std::vector<Vec2> vertex_pos_;
  std::vector<double> vertex_mass_;
  std::vector<BodyRef> bodies_;
  std::vector<std::pair<Deferred, Deferred>> spring_ends_;
  std::vector<std::pair<Deferred, Color>> body_colors_, spring_colors_;
};

void Loader::check_attributes(const tinyxml2::XMLElement* e, std::initializer_list<const char*> known,
                              bool repeat_p) {
  for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
    const std::string_view full = a->Name();
    const std::string original(original_attribute_name(full));
    if (original != full && !(repeat_p && original == "p")) {
      fail(e, original.c_str(), "attribute given more than once");
    }
    bool ok = false;
    for (const char* k : known) ok = ok || original == k;
    if (!ok)
      warn(a->GetLineNum(), "<" + std::string(e->Name()) + "> unknown attribute '" + original + "' ignored");
  }
}

void Loader::element(const tinyxml2::XMLElement* e) {
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
  } else if (name == "description") {
    once(e);
    check_attributes(e, {"text"}, false);
    scene_.description = raw(e, "text");
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
  } else if (name == "rigidbodyvertex") {
    check_attributes(e, {"x", "y", "m"}, false);
    vertex_pos_.emplace_back(number(e, "x"), number(e, "y"));
    vertex_mass_.push_back(positive(e, "m"));
  } else if (name == "rigidbody") {
    check_attributes(e, {"p", "vx", "vy", "omega", "r"}, true);
    BodyRef body{e, {}, {}};
    for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a != nullptr; a = a->Next()) {
      if (original_attribute_name(a->Name()) == "p")
        body.vertices.push_back({e, "p", integer(e, "p", a->Value())});
    }
    if (body.vertices.size() < 2) {
      fail(e, "p",
           "a rigid body needs at least 2 hull vertices (got " + std::to_string(body.vertices.size()) + ")");
    }
    body.def.velocity = {number(e, "vx"), number(e, "vy")};
    body.def.omega = number(e, "omega");
    body.def.radius = positive(e, "r");
    bodies_.push_back(std::move(body));
  } else if (name == "rigidbodyspringforce") {
    check_attributes(e, {"i", "pix", "piy", "j", "pjx", "pjy", "k", "l0"}, false);
    SpringDef s;
    s.anchor_i = {number(e, "pix"), number(e, "piy")};
    s.anchor_j = {number(e, "pjx"), number(e, "pjy")};
    s.stiffness = non_negative(e, "k");
    s.rest_length = non_negative(e, "l0");
    spring_ends_.push_back({{e, "i", integer(e, "i")}, {e, "j", integer(e, "j")}});
    scene_.world.springs.push_back(s);
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
  } else if (name == "rigidbodycolor") {
    check_attributes(e, {"body", "r", "g", "b"}, false);
    body_colors_.push_back({{e, "body", integer(e, "body")}, color(e)});
  } else if (name == "rigidbodyspringcolor") {
    check_attributes(e, {"spring", "r", "g", "b"}, false);
    spring_colors_.push_back({{e, "spring", integer(e, "spring")}, color(e)});
  } else {
    warn(e->GetLineNum(), "unknown node <" + std::string(name) + "> ignored");
  }
}

Scene Loader::load(const tinyxml2::XMLDocument& doc) {
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (root == nullptr) fail(1, "<scene>: no root element (empty document)");
  if (std::string_view(root->Name()) != "scene") {
    fail(root->GetLineNum(), "<" + std::string(root->Name()) + ">: root node must be <scene>");
  }
  for (const tinyxml2::XMLElement* e = root->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    element(e);
  }
  const int end_line = root->GetLineNum();
  if (!seen_once_.contains("rigidbodyintegrator"))
    fail(end_line, "<scene>: missing node <rigidbodyintegrator>");
  if (!seen_once_.contains("duration")) fail(end_line, "<scene>: missing node <duration>");

  // Vertices form one global list in file order; bodies and forces may refer ahead.
  const auto vertex_count = static_cast<std::int64_t>(vertex_pos_.size());
  for (BodyRef& body : bodies_) {
    for (const Deferred& v : body.vertices) {
      if (v.value < 0 || v.value >= vertex_count) {
        fail(v.element, v.attr,
             "vertex index " + std::to_string(v.value) + " out of range [0, " +
                 std::to_string(vertex_count - 1) + "]");
      }
      body.def.hull.push_back(vertex_pos_[v.value]);
      body.def.masses.push_back(vertex_mass_[v.value]);
    }
    scene_.world.bodies.push_back(std::move(body.def));
  }
  const auto body_count = static_cast<std::int64_t>(bodies_.size());
  const std::string body_range = "[-1, " + std::to_string(body_count - 1) + "] (-1 = fixed point)";
  for (std::size_t s = 0; s < spring_ends_.size(); ++s) {
    const auto& [i, j] = spring_ends_[s];
    for (const Deferred* end : {&i, &j}) {
      if (end->value < -1 || end->value >= body_count) {
        fail(end->element, end->attr,
             "body index " + std::to_string(end->value) + " out of range " + body_range);
      }
    }
    scene_.world.springs[s].body_i = static_cast<std::int32_t>(i.value);
    scene_.world.springs[s].body_j = static_cast<std::int32_t>(j.value);
  }
  for (std::int32_t b = 0; b < body_count; ++b) scene_.body_colors.push_back(default_body_color(b));
  scene_.spring_colors.assign(spring_ends_.size(), kDefaultSpringColor);
  auto apply_colors = [&](const auto& list, std::vector<Color>& target, const char* what) {
    for (const auto& [ref, c] : list) {
      if (ref.value < 0 || ref.value >= static_cast<std::int64_t>(target.size())) {
        fail(ref.element, ref.attr,
             std::string(what) + " index " + std::to_string(ref.value) + " out of range [0, " +
                 std::to_string(static_cast<std::int64_t>(target.size()) - 1) + "]");
      }
      target[ref.value] = c;
    }
  };
  apply_colors(body_colors_, scene_.body_colors, "body");
  apply_colors(spring_colors_, scene_.spring_colors, "spring");

  // Checks that need whole bodies (e.g. coincident vertices) are the core's.
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const BodyDef& def = scene_.world.bodies[b];
    bool all_same = true;
    for (const Vec2& v : def.hull) all_same = all_same && v == def.hull.front();
    if (all_same)
      fail(bodies_[b].element, "p", "all hull vertices coincide (the body has no moment of inertia)");
  }
  return std::move(scene_);
}

std::string stem_of(const std::string& path) {
  return std::filesystem::path(path).stem().string();
}

}  // namespace

Result<Scene> parse_scene(std::string_view text, const std::string& path) {
  Result<std::string> renamed = rename_repeated_attributes(text);
  if (!renamed) return with_context(path + ":", renamed.error());
  const std::string& rewritten = renamed.value();
  tinyxml2::XMLDocument doc;
  doc.Parse(rewritten.data(), rewritten.size());
  if (doc.Error()) {
    if (doc.ErrorID() == tinyxml2::XML_ERROR_EMPTY_DOCUMENT)
      return Error{path + ":1: empty file (expected a <scene>)"};
    std::string detail = doc.ErrorStr();
    // tinyxml2 prefixes "Error=XML_ERROR_... ErrorID=n (0x..) Line number=n: "; keep its tail.
    // Without a tail (e.g. XML_ERROR_PARSING_TEXT) it only repeats the name and line: drop it.
    const auto colon = detail.find(": ");
    detail = colon == std::string::npos ? std::string() : detail.substr(colon + 2);
    return Error{path + ":" + std::to_string(doc.ErrorLineNum()) + ": not well-formed XML: " +
                 std::string(doc.ErrorName()) + (detail.empty() ? "" : " (" + detail + ")")};
  }
  Loader loader(path);
  Scene scene;
  try {
    scene = loader.load(doc);
  } catch (const SceneError& e) {
    return Error{e.message};
  }
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
