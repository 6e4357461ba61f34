// Every way a scene can be wrong gives one located line: "file:line: <node> attribute 'a': rule".
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "bad_scenes.hpp"
#include "rbsim/scene.hpp"

namespace rbsim {
namespace {

namespace fs = std::filesystem;
const std::string kBad = std::string(RBSIM_TEST_DATA_DIR) + "/bad_scenes";

class LoadSceneBad : public ::testing::TestWithParam<test::BadScene> {};
class ParseSceneBadFile : public ::testing::TestWithParam<test::BadScene> {};

TEST_P(LoadSceneBad, GivesTheDocumentedOneLineError) {
  const test::BadScene& bad = GetParam();
  const std::string path = kBad + "/" + bad.file;
  Result<Scene> s = load_scene(path);
  ASSERT_FALSE(s.ok()) << path << " loaded";
  const std::string mismatch = bad.mismatch(path, s.error().message);
  EXPECT_TRUE(mismatch.empty()) << mismatch << "\n  got: " << s.error().message;
}

// The same text through parse_scene under another name: the name is what the message shows.
TEST_P(ParseSceneBadFile, ReportsTheGivenName) {
  const test::BadScene& bad = GetParam();
  const std::string path = kBad + "/" + bad.file;
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  Result<Scene> s = parse_scene(text.str(), "renamed.xml");
  ASSERT_FALSE(s.ok());
  const std::string mismatch = bad.mismatch("renamed.xml", s.error().message);
  EXPECT_TRUE(mismatch.empty()) << mismatch << "\n  got: " << s.error().message;
}

std::vector<test::BadScene> manifest() {
  return test::read_bad_scene_manifest(kBad);
}
std::vector<test::BadScene> manifest_files() {  // the rows that have text (not the directory)
  std::vector<test::BadScene> out;
  for (const auto& b : manifest()) {
    if (!fs::is_directory(kBad + "/" + b.file)) out.push_back(b);
  }
  return out;
}
std::string case_name(const ::testing::TestParamInfo<test::BadScene>& tp) {
  return tp.param.file.substr(0, tp.param.file.find('.'));
}

INSTANTIATE_TEST_SUITE_P(Manifest, LoadSceneBad, ::testing::ValuesIn(manifest()), case_name);
INSTANTIATE_TEST_SUITE_P(Manifest, ParseSceneBadFile, ::testing::ValuesIn(manifest_files()), case_name);

TEST(LoadSceneBadManifest, ListsEveryFileAndCoversEveryRule) {
  const auto rows = manifest();
  ASSERT_GE(rows.size(), 40u);
  std::set<std::string> listed;
  for (const auto& r : rows) listed.insert(r.file);
  EXPECT_EQ(listed.size(), rows.size()) << "duplicate rows";
  for (const auto& e : fs::directory_iterator(kBad)) {
    if (e.path().extension() == ".xml") {
      EXPECT_TRUE(listed.contains(e.path().filename().string())) << e.path();
    }
  }
  for (const auto& f : listed) EXPECT_TRUE(fs::exists(kBad + "/" + f)) << f;
  // the rules of the brief, each with at least one scene
  for (const char* rule :
       {"empty file", "not well-formed XML", "required attribute is missing", "must be a number",
        "must be a finite number", "must be > 0", "must be >= 0", "unknown integrator", "unknown simtype",
        "vertex index", "at least 2 hull vertices", "body index -2", "spring index",
        "must be an integer in [2", "colour component", "is a directory"}) {
    bool found = false;
    for (const auto& r : rows) found = found || r.message.find(rule) != std::string::npos;
    EXPECT_TRUE(found) << rule;
  }
}

// The bad scenes are one edit away from this template, which must itself be valid.
TEST(LoadSceneBadManifest, TemplateIsValid) {
  Result<Scene> s = load_scene(kBad + "/valid.xml.template");
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_EQ(s->world.bodies.size(), 1u);
  EXPECT_EQ(s->world.springs.size(), 1u);
  EXPECT_EQ(s->world.springs[0].body_j, kFixed);  // -1 is allowed
  EXPECT_EQ(s->world.winds.size(), 1u);
  EXPECT_EQ(s->body_colors[0].b, 0.3);
  EXPECT_EQ(s->spring_colors[0].r, 0.5);
}

TEST(LoadScene, MissingFileIsAClearError) {
  const std::string path = kBad + "/no_such_scene.xml";
  Result<Scene> s = load_scene(path);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message, path + ": cannot open scene file: No such file or directory");
}

TEST(LoadScene, DirectoryIsAClearError) {
  Result<Scene> s = load_scene(kBad);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message, kBad + ": is a directory, not a scene file");
}

// Inline cases that need no file.
struct InlineBad {
  const char* name;
  const char* text;
  const char* expected;  // whole message
};
void PrintTo(const InlineBad& b, std::ostream* os) {
  *os << b.name;
}

class ParseSceneBad : public ::testing::TestWithParam<InlineBad> {};

TEST_P(ParseSceneBad, GivesTheDocumentedOneLineError) {
  Result<Scene> s = parse_scene(GetParam().text, "inline.xml");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message, GetParam().expected);
}

#define HEAD                                                                               \
  "<scene>\n<simtype type=\"rigid-body\"/>\n<duration time=\"1\"/>\n<rigidbodyintegrator " \
  "type=\"symplectic-euler\" dt=\"0.1\"/>\n"
const InlineBad kInline[] = {
    {"only_whitespace", "  \n\n ", "inline.xml:1: empty file (expected a <scene>)"},
    {"vertex_missing_y", HEAD "<rigidbodyvertex x=\"1\" m=\"1\"/>\n</scene>",
     "inline.xml:5: <rigidbodyvertex> attribute 'y': required attribute is missing"},
    {"empty_number", HEAD "<rigidbodyvertex x=\"\" y=\"0\" m=\"1\"/>\n</scene>",
     "inline.xml:5: <rigidbodyvertex> attribute 'x': must be a number (got \"\")"},
    {"negative_infinity", HEAD "<rigidbodyvertex x=\"-inf\" y=\"0\" m=\"1\"/>\n</scene>",
     "inline.xml:5: <rigidbodyvertex> attribute 'x': must be a finite number (got \"-inf\")"},
    {"hex_float_is_not_a_scene_number", HEAD "<rigidbodyvertex x=\"0x10\" y=\"0\" m=\"1\"/>\n</scene>",
     "inline.xml:5: <rigidbodyvertex> attribute 'x': must be a number (got \"0x10\")"},
    {"spring_index_not_integer",
     HEAD "<rigidbodyspringforce i=\"a\" pix=\"0\" piy=\"0\" j=\"-1\" pjx=\"0\" pjy=\"0\" k=\"1\" "
          "l0=\"1\"/>\n</scene>",
     "inline.xml:5: <rigidbodyspringforce> attribute 'i': must be an integer (got \"a\")"},
    {"spring_without_bodies",
     HEAD "<rigidbodyspringforce i=\"-1\" pix=\"0\" piy=\"0\" j=\"0\" pjx=\"0\" pjy=\"0\" k=\"1\" "
          "l0=\"1\"/>\n</scene>",
     "inline.xml:5: <rigidbodyspringforce> attribute 'j': body index 0 out of range [-1, -1] (-1 = fixed "
     "point)"},
    {"colour_without_bodies", HEAD "<rigidbodycolor body=\"0\" r=\"0\" g=\"0\" b=\"0\"/>\n</scene>",
     "inline.xml:5: <rigidbodycolor> attribute 'body': body index 0 out of range [0, -1]"},
    {"background_colour", HEAD "<backgroundcolor r=\"0\" g=\"2\" b=\"0\"/>\n</scene>",
     "inline.xml:5: <backgroundcolor> attribute 'g': colour component must be in [0, 1] (got 2)"},
    {"viewport_size", HEAD "<viewport cx=\"0\" cy=\"0\" size=\"0\"/>\n</scene>",
     "inline.xml:5: <viewport> attribute 'size': must be > 0 (got 0)"},
    {"huge_points_per_edge",
     HEAD
     "<rigidbodywindforce beta=\"1\" fx=\"0\" fy=\"0\" pointsperedge=\"99999999999999999999\"/>\n</scene>",
     "inline.xml:5: <rigidbodywindforce> attribute 'pointsperedge': must be an integer (got "
     "\"99999999999999999999\")"},
    // a value may span lines; the message must still be one line
    {"value_spanning_lines", HEAD "<rigidbodyvertex x=\"1\n2\" y=\"0\" m=\"1\"/>\n</scene>",
     "inline.xml:5: <rigidbodyvertex> attribute 'x': must be a number (got \"1\\n2\")"},
    {"negative_value_after_newline", HEAD "<rigidbodyvertex x=\"1\" y=\"0\" m=\"\n\t-1\"/>\n</scene>",
     "inline.xml:5: <rigidbodyvertex> attribute 'm': must be > 0 (got \\n\\t-1)"},
    {"xml_declaration_spanning_lines", "<scene>\n<?xml a\nb?>\n</scene>",
     "inline.xml:2: not well-formed XML: XML_ERROR_PARSING_DECLARATION (XMLDeclaration value=xml a\\nb)"},
    {"simtype_twice", "<scene>\n<simtype type=\"rigid-body\"/>\n<simtype type=\"rigid-body\"/>\n</scene>",
     "inline.xml:3: <simtype>: node may appear only once (first at line 2)"},
};
#undef HEAD

INSTANTIATE_TEST_SUITE_P(Table, ParseSceneBad, ::testing::ValuesIn(kInline),
                         [](const auto& tp) { return std::string(tp.param.name); });

}  // namespace
}  // namespace rbsim
