// Spawnable fragments (rbsim/scene.hpp's parse_fragment): one body in the scene dialect, read by the
// scene loader's own element readers (loader.hpp); only what a fragment adds or refuses is here.
#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "loader.hpp"
#include "rbsim/scene.hpp"

namespace rbsim {

namespace {

using scene_detail::BodyRead;
using scene_detail::ColorRead;
using scene_detail::Deferred;
using scene_detail::VertexRead;

bool blank(std::string_view s) {
  return s.find_first_not_of(" \t\r\n") == std::string_view::npos;
}

class FragmentLoader : public scene_detail::Reader {
 public:
  FragmentLoader(std::string path, const FragmentLimits& limits) : Reader(std::move(path)), limits_(limits) {}

  Fragment load(const tinyxml2::XMLDocument& doc);

 private:
  void element(const tinyxml2::XMLElement* e);
  FragmentSpring spring_force(const tinyxml2::XMLElement* e);
  FragmentSpringEnd end(const tinyxml2::XMLElement* e, const char* index_attr, const char* name_attr,
                        Vec2 anchor) const;
  void check_every_vertex_used() const;

  FragmentLimits limits_;
  Fragment fragment_;
  std::vector<VertexRead> vertices_;
  std::vector<const tinyxml2::XMLElement*> vertex_elements_;
  std::optional<BodyRead> body_;
  std::vector<ColorRead> body_colors_, spring_colors_;
};

void FragmentLoader::element(const tinyxml2::XMLElement* e) {
  const std::string_view name = e->Name();
  const int line = e->GetLineNum();
  if (scene_detail::is_scene_wide(name)) {
    fail(line, "<" + std::string(name) + ">: not allowed in a spawnable fragment (a scene-wide element)");
  } else if (name == "description") {
    fragment_.description = description(e);
  } else if (name == "rigidbodyvertex") {
    if (vertices_.size() >= static_cast<std::size_t>(std::max(limits_.max_vertices, 0)))
      fail(line, "<rigidbodyvertex>: over the limit of " + std::to_string(limits_.max_vertices) +
                     " vertices for a fragment");
    vertices_.push_back(vertex(e));
    vertex_elements_.push_back(e);
  } else if (name == "rigidbody") {
    if (body_)
      fail(line, "<rigidbody>: a fragment describes exactly one body (the first <rigidbody> at line " +
                     std::to_string(body_->element->GetLineNum()) + ")");
    body_ = body(e);
  } else if (name == "rigidbodyspringforce") {
    if (fragment_.springs.size() >= static_cast<std::size_t>(std::max(limits_.max_springs, 0)))
      fail(line, "<rigidbodyspringforce>: over the limit of " + std::to_string(limits_.max_springs) +
                     " springs for a fragment");
    fragment_.springs.push_back(spring_force(e));
  } else if (name == "rigidbodycolor") {
    body_colors_.push_back(body_color(e));
  } else if (name == "rigidbodyspringcolor") {
    spring_colors_.push_back(spring_color(e));
  } else {
    unknown_node(e);
  }
}

FragmentSpring FragmentLoader::spring_force(const tinyxml2::XMLElement* e) {
  const SpringDef s = spring(e, {"i", "ibody", "pix", "piy", "j", "jbody", "pjx", "pjy", "k", "l0"});
  FragmentSpring out;
  out.end_i = end(e, "i", "ibody", s.anchor_i);
  out.end_j = end(e, "j", "jbody", s.anchor_j);
  out.stiffness = s.stiffness;
  out.rest_length = s.rest_length;
  return out;
}

// One end: `i` (0 = this fragment's body, -1 = fixed) or `ibody` (a body of the running world).
FragmentSpringEnd FragmentLoader::end(const tinyxml2::XMLElement* e, const char* index_attr,
                                      const char* name_attr, Vec2 anchor) const {
  const char* index = e->Attribute(index_attr);
  const char* name = e->Attribute(name_attr);
  if (index != nullptr && name != nullptr)
    fail(e, name_attr, std::string("give either '") + index_attr + "' or '" + name_attr + "', not both");
  if (name != nullptr) {
    if (blank(name))
      fail(e, name_attr, "must name a body of the running world (got \"" + std::string(name) + "\")");
    return {FragmentSpringEnd::Kind::Named, name, anchor};
  }
  if (index == nullptr)
    fail(e, index_attr,
         std::string("required attribute is missing (or name a body of the running world with '") +
             name_attr + "')");
  const Deferred ref{e, index_attr, integer(e, index_attr)};
  check_body_index(
      ref, 1,
      std::string("(-1 = fixed point, 0 = the fragment's body; a body of the running world is named "
                  "with '") +
          name_attr + "')");
  return {ref.value == 0 ? FragmentSpringEnd::Kind::Self : FragmentSpringEnd::Kind::Fixed, {}, anchor};
}

// A fragment's vertices are its one body's: a vertex off the hull is a mistake, not a spare.
void FragmentLoader::check_every_vertex_used() const {
  std::vector<bool> used(vertices_.size(), false);
  for (const Deferred& v : body_->vertices) used[static_cast<std::size_t>(v.value)] = true;
  for (std::size_t k = 0; k < used.size(); ++k) {
    if (!used[k])
      fail(vertex_elements_[k]->GetLineNum(), "<rigidbodyvertex>: vertex " + std::to_string(k) +
                                                  " is not on the hull of the fragment's <rigidbody> (line " +
                                                  std::to_string(body_->element->GetLineNum()) + ")");
  }
}

Fragment FragmentLoader::load(const tinyxml2::XMLDocument& doc) {
  const tinyxml2::XMLElement* root = Reader::root(doc, "a fragment's root must be <scene>");
  for (const tinyxml2::XMLElement* e = root->FirstChildElement(); e != nullptr; e = e->NextSiblingElement()) {
    element(e);
  }
  if (!body_)
    fail(root->GetLineNum(), "<scene>: a fragment describes exactly one body (no <rigidbody> given)");
  fragment_.body = resolve_hull(*body_, vertices_);
  check_every_vertex_used();
  std::vector<std::optional<Color>> body_color(1), spring_colors(fragment_.springs.size());
  apply_colors(body_colors_, body_color, "body");
  apply_colors(spring_colors_, spring_colors, "spring");
  fragment_.color = body_color.front();
  for (std::size_t s = 0; s < spring_colors.size(); ++s) fragment_.springs[s].color = spring_colors[s];
  check_not_degenerate(*body_, fragment_.body);
  fragment_.warnings = take_warnings();
  return std::move(fragment_);
}

// The fragment as a world of its own (named ends fixed) for the core's validation.
WorldDef backstop_world(const Fragment& f) {
  WorldDef def;
  def.bodies.push_back(f.body);
  for (const FragmentSpring& s : f.springs) {
    SpringDef d;
    d.body_i = s.end_i.kind == FragmentSpringEnd::Kind::Self ? 0 : kFixed;
    d.body_j = s.end_j.kind == FragmentSpringEnd::Kind::Self ? 0 : kFixed;
    d.anchor_i = s.end_i.anchor;
    d.anchor_j = s.end_j.anchor;
    d.stiffness = s.stiffness;
    d.rest_length = s.rest_length;
    def.springs.push_back(d);
  }
  return def;
}

}  // namespace

Result<Fragment> parse_fragment(std::string_view text, const std::string& path,
                                const FragmentLimits& limits) {
  if (text.size() > limits.max_bytes) {
    return Error{path + ": " + std::to_string(text.size()) + " bytes, over the limit of " +
                 std::to_string(limits.max_bytes) + " for a fragment"};
  }
  FragmentLoader loader(path, limits);
  Result<Fragment> loaded = scene_detail::parse_with(loader, text, path, "fragment");
  if (!loaded) return loaded.error();
  Fragment fragment = std::move(loaded.value());
  fragment.path = path;
  // Backstop: anything the loader let through must also satisfy the core's own validation.
  if (Result<World> w = World::create(backstop_world(fragment)); !w)
    return with_context(path + ": ", w.error());
  return fragment;
}

}  // namespace rbsim
