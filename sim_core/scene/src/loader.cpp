// The dialect's element and attribute rules (loader.hpp), shared by scenes and fragments.
#include "loader.hpp"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>

#include "xml_dialect.hpp"

namespace rbsim::scene_detail {

namespace {

std::string_view trim(std::string_view s) {
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
  while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
  return s;
}

}  // namespace

Status parse_xml(std::string_view text, const std::string& path, const char* what, std::string& storage,
                 tinyxml2::XMLDocument& doc) {
  Result<std::string> renamed = rename_repeated_attributes(text);
  if (!renamed) return with_context(path + ":", renamed.error());
  storage = std::move(renamed.value());
  doc.Parse(storage.data(), storage.size());
  if (!doc.Error()) return Ok{};
  if (doc.ErrorID() == tinyxml2::XML_ERROR_EMPTY_DOCUMENT)
    return Error{path + ":1: empty " + what + " (expected a <scene>)"};
  std::string detail = doc.ErrorStr();
  // tinyxml2 prefixes "Error=XML_ERROR_... ErrorID=n (0x..) Line number=n: "; keep its tail.
  // Without a tail (e.g. XML_ERROR_PARSING_TEXT) it only repeats the name and line: drop it. The
  // tail may echo text spanning lines (a declaration's value): shown escaped, the message is one line.
  const auto colon = detail.find(": ");
  detail = colon == std::string::npos ? std::string() : Reader::one_line(detail.substr(colon + 2));
  return Error{path + ":" + std::to_string(doc.ErrorLineNum()) + ": not well-formed XML: " +
               std::string(doc.ErrorName()) + (detail.empty() ? "" : " (" + detail + ")")};
}

bool is_scene_wide(std::string_view element) {
  return std::find(std::begin(kSceneWideElements), std::end(kSceneWideElements), element) !=
         std::end(kSceneWideElements);
}

std::string Reader::one_line(const std::string& s) {
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

void Reader::fail(int line, const std::string& what) const {
  throw LoadError{path_ + ":" + std::to_string(line) + ": " + one_line(what)};
}

void Reader::fail(const tinyxml2::XMLElement* e, const char* attr, const std::string& rule) const {
  fail(e->GetLineNum(), "<" + std::string(e->Name()) + "> attribute '" + attr + "': " + rule);
}

void Reader::warn(int line, const std::string& what) {
  warnings_.push_back(path_ + ":" + std::to_string(line) + ": warning: " + what);
}

const char* Reader::raw(const tinyxml2::XMLElement* e, const char* attr) const {
  const char* v = e->Attribute(attr);
  if (v == nullptr) fail(e, attr, "required attribute is missing");
  return v;
}

double Reader::number(const tinyxml2::XMLElement* e, const char* attr) const {
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

double Reader::positive(const tinyxml2::XMLElement* e, const char* attr) const {
  const double v = number(e, attr);
  if (!(v > 0)) fail(e, attr, "must be > 0 (got " + std::string(raw(e, attr)) + ")");
  return v;
}

double Reader::non_negative(const tinyxml2::XMLElement* e, const char* attr) const {
  const double v = number(e, attr);
  if (!(v >= 0)) fail(e, attr, "must be >= 0 (got " + std::string(raw(e, attr)) + ")");
  return v;
}

double Reader::unit(const tinyxml2::XMLElement* e, const char* attr) const {
  const double v = number(e, attr);
  if (!(v >= 0 && v <= 1))
    fail(e, attr, "colour component must be in [0, 1] (got " + std::string(raw(e, attr)) + ")");
  return v;
}

std::int64_t Reader::integer(const tinyxml2::XMLElement* e, const char* attr, const char* value) const {
  const std::string_view s = trim(value);
  std::int64_t v = 0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || end != s.data() + s.size() || ec != std::errc()) {
    fail(e, attr, "must be an integer (got \"" + std::string(value) + "\")");
  }
  return v;
}

std::int64_t Reader::integer(const tinyxml2::XMLElement* e, const char* attr) const {
  return integer(e, attr, raw(e, attr));
}

Color Reader::color(const tinyxml2::XMLElement* e) const {
  return {unit(e, "r"), unit(e, "g"), unit(e, "b")};
}

void Reader::once(const tinyxml2::XMLElement* e) {
  auto [it, fresh] = seen_once_.try_emplace(e->Name(), e->GetLineNum());
  if (!fresh)
    fail(e->GetLineNum(), "<" + std::string(e->Name()) + ">: node may appear only once (first at line " +
                              std::to_string(it->second) + ")");
}

void Reader::check_attributes(const tinyxml2::XMLElement* e, std::initializer_list<const char*> known,
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

void Reader::unknown_node(const tinyxml2::XMLElement* e) {
  warn(e->GetLineNum(), "unknown node <" + std::string(e->Name()) + "> ignored");
}

const tinyxml2::XMLElement* Reader::root(const tinyxml2::XMLDocument& doc, const char* rule) const {
  const tinyxml2::XMLElement* root = doc.RootElement();
  if (root == nullptr) fail(1, "<scene>: no root element (empty document)");
  if (std::string_view(root->Name()) != "scene")
    fail(root->GetLineNum(), "<" + std::string(root->Name()) + ">: " + rule);
  return root;
}

std::string Reader::description(const tinyxml2::XMLElement* e) {
  once(e);
  check_attributes(e, {"text"}, false);
  return raw(e, "text");
}

VertexRead Reader::vertex(const tinyxml2::XMLElement* e) {
  check_attributes(e, {"x", "y", "m"}, false);
  VertexRead v;
  v.position = {number(e, "x"), number(e, "y")};
  v.mass = positive(e, "m");
  return v;
}

BodyRead Reader::body(const tinyxml2::XMLElement* e) {
  check_attributes(e, {"p", "vx", "vy", "omega", "r"}, true);
  BodyRead body{e, {}, {}};
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
  return body;
}

SpringDef Reader::spring(const tinyxml2::XMLElement* e, std::initializer_list<const char*> known) {
  check_attributes(e, known, false);
  SpringDef s;
  s.anchor_i = {number(e, "pix"), number(e, "piy")};
  s.anchor_j = {number(e, "pjx"), number(e, "pjy")};
  s.stiffness = non_negative(e, "k");
  s.rest_length = non_negative(e, "l0");
  return s;
}

ColorRead Reader::body_color(const tinyxml2::XMLElement* e) {
  check_attributes(e, {"body", "r", "g", "b"}, false);
  return {{e, "body", integer(e, "body")}, color(e)};
}

ColorRead Reader::spring_color(const tinyxml2::XMLElement* e) {
  check_attributes(e, {"spring", "r", "g", "b"}, false);
  return {{e, "spring", integer(e, "spring")}, color(e)};
}

BodyDef Reader::resolve_hull(BodyRead body, const std::vector<VertexRead>& vertices) const {
  const auto vertex_count = static_cast<std::int64_t>(vertices.size());
  for (const Deferred& v : body.vertices) {
    if (v.value < 0 || v.value >= vertex_count) {
      fail(v.element, v.attr,
           "vertex index " + std::to_string(v.value) + " out of range [0, " +
               std::to_string(vertex_count - 1) + "]");
    }
    body.def.hull.push_back(vertices[static_cast<std::size_t>(v.value)].position);
    body.def.masses.push_back(vertices[static_cast<std::size_t>(v.value)].mass);
  }
  return std::move(body.def);
}

void Reader::check_not_degenerate(const BodyRead& read, const BodyDef& def) const {
  bool all_same = true;
  for (const Vec2& v : def.hull) all_same = all_same && v == def.hull.front();
  if (all_same) fail(read.element, "p", "all hull vertices coincide (the body has no moment of inertia)");
}

void Reader::check_body_index(const Deferred& end, std::int64_t body_count, const std::string& note) const {
  if (end.value < -1 || end.value >= body_count) {
    fail(end.element, end.attr,
         "body index " + std::to_string(end.value) + " out of range [-1, " + std::to_string(body_count - 1) +
             "] " + note);
  }
}

}  // namespace rbsim::scene_detail
