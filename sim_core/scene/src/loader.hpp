// The FOSSSim dialect's element and attribute rules, shared by scenes (scene.cpp) and spawnable
// fragments (fragment.cpp): one reader per element, one rule per attribute, one wording of every
// error ("<file>:<line>: <node> attribute 'a': <rule>"). Internal to the scene module.
#pragma once

#include <tinyxml2.h>

#include <cstdint>
#include <initializer_list>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "rbsim/scene.hpp"

namespace rbsim::scene_detail {

// Thrown only inside the scene module's loaders, caught by their entry points and turned into an
// Error: it keeps the dozens of attribute reads free of error plumbing.
struct LoadError {
  std::string message;
};

// Parses `text` (FOSSSim's repeated attributes renamed first) into `doc`. `what` names the
// source in the empty-document message ("file", "fragment").
Status parse_xml(std::string_view text, const std::string& path, const char* what, std::string& storage,
                 tinyxml2::XMLDocument& doc);

// The one entry of a loader: parses `text` into `doc`, then `loader.load(doc)`, its LoadError an
// Error. `path` names the source in messages; `what` as parse_xml's.
template <class Loader>
auto parse_with(Loader& loader, std::string_view text, const std::string& path, const char* what)
    -> Result<decltype(loader.load(std::declval<const tinyxml2::XMLDocument&>()))> {
  std::string storage;
  tinyxml2::XMLDocument doc;
  if (Status st = parse_xml(text, path, what, storage, doc); !st) return st.error();
  try {
    return loader.load(doc);
  } catch (const LoadError& e) {
    return Error{e.message};
  }
}

// The elements that describe the whole scene, not a body: a fragment refuses them.
inline constexpr std::string_view kSceneWideElements[] = {
    "simtype",           "duration", "maxsimfreq",          "viewport",
    "backgroundcolor",   "scenetag", "rigidbodyintegrator", "rigidbodygravityforce",
    "rigidbodywindforce"};
bool is_scene_wide(std::string_view element);

// An index that can only be checked once the whole document is read.
struct Deferred {
  const tinyxml2::XMLElement* element;
  const char* attr;
  std::int64_t value;
};

struct VertexRead {  // <rigidbodyvertex x y m>
  Vec2 position;
  double mass = 0.0;
};

struct BodyRead {  // <rigidbody p... vx vy omega r>: the hull as vertex indices, still unchecked
  const tinyxml2::XMLElement* element;
  std::vector<Deferred> vertices;
  BodyDef def;  // velocity, omega, radius
};

struct ColorRead {  // <rigidbodycolor body r g b>, <rigidbodyspringcolor spring r g b>
  Deferred index;
  Color color;
};

class Reader {
 public:
  explicit Reader(std::string path) : path_(std::move(path)) {}

  // Messages are one line: control characters in echoed values are shown escaped.
  static std::string one_line(const std::string& s);
  [[noreturn]] void fail(int line, const std::string& what) const;
  [[noreturn]] void fail(const tinyxml2::XMLElement* e, const char* attr, const std::string& rule) const;
  void warn(int line, const std::string& what);

  const char* raw(const tinyxml2::XMLElement* e, const char* attr) const;
  double number(const tinyxml2::XMLElement* e, const char* attr) const;
  double positive(const tinyxml2::XMLElement* e, const char* attr) const;
  double non_negative(const tinyxml2::XMLElement* e, const char* attr) const;
  double unit(const tinyxml2::XMLElement* e, const char* attr) const;
  std::int64_t integer(const tinyxml2::XMLElement* e, const char* attr, const char* value) const;
  std::int64_t integer(const tinyxml2::XMLElement* e, const char* attr) const;
  Color color(const tinyxml2::XMLElement* e) const;

  // A node that may appear only once per document.
  void once(const tinyxml2::XMLElement* e);
  // Warns of unknown attributes; refuses a repeated one (but `p` where repeat_p).
  void check_attributes(const tinyxml2::XMLElement* e, std::initializer_list<const char*> known,
                        bool repeat_p);
  void unknown_node(const tinyxml2::XMLElement* e);
  // The root must be <scene>: `rule` words the refusal of another ("root node must be <scene>").
  const tinyxml2::XMLElement* root(const tinyxml2::XMLDocument& doc, const char* rule) const;

  // One reader per element of the dialect, used by scenes and fragments alike.
  std::string description(const tinyxml2::XMLElement* e);
  VertexRead vertex(const tinyxml2::XMLElement* e);
  BodyRead body(const tinyxml2::XMLElement* e);
  // <rigidbodyspringforce>: anchors, k and l0 (the ends are the caller's: scenes and fragments
  // name them differently); `known` is the element's whole attribute list.
  SpringDef spring(const tinyxml2::XMLElement* e, std::initializer_list<const char*> known);
  ColorRead body_color(const tinyxml2::XMLElement* e);
  ColorRead spring_color(const tinyxml2::XMLElement* e);

  // The hull's vertex indices resolved against the document's vertex list.
  BodyDef resolve_hull(BodyRead body, const std::vector<VertexRead>& vertices) const;
  // Refuses a body whose hull vertices all coincide (it has no moment of inertia).
  void check_not_degenerate(const BodyRead& read, const BodyDef& def) const;
  // Refuses a body index outside [-1, body_count - 1]; `note` follows the range in the message.
  void check_body_index(const Deferred& end, std::int64_t body_count, const std::string& note) const;
  // Puts each colour at its index of `target` (Color or std::optional<Color>), refusing an index
  // out of range; `what` names the index ("body", "spring").
  template <typename Target>
  void apply_colors(const std::vector<ColorRead>& list, std::vector<Target>& target, const char* what) const {
    for (const ColorRead& c : list) {
      if (c.index.value < 0 || c.index.value >= static_cast<std::int64_t>(target.size())) {
        fail(c.index.element, c.index.attr,
             std::string(what) + " index " + std::to_string(c.index.value) + " out of range [0, " +
                 std::to_string(static_cast<std::int64_t>(target.size()) - 1) + "]");
      }
      target[static_cast<std::size_t>(c.index.value)] = c.color;
    }
  }

  bool seen(const char* element) const { return seen_once_.contains(element); }
  std::vector<std::string> take_warnings() { return std::move(warnings_); }
  const std::string& path() const { return path_; }

 private:
  std::string path_;
  std::vector<std::string> warnings_;
  std::map<std::string, int> seen_once_;  // element -> line of its first occurrence
};

}  // namespace rbsim::scene_detail
