// parse_fragment: one spawnable body in the scene dialect, read by load_scene's own rules.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "rbsim/scene.hpp"

namespace rbsim {
namespace {

const std::string kBundled = RBSIM_SCENES_DIR;

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

Fragment parse_ok(const std::string& text, const FragmentLimits& limits = {}) {
  Result<Fragment> f = parse_fragment(text, "frag.xml", limits);
  if (!f) ADD_FAILURE() << "unexpected error: " << f.error().message;
  return f ? std::move(f.value()) : Fragment{};
}

std::string error_of(const std::string& text, const FragmentLimits& limits = {}) {
  Result<Fragment> f = parse_fragment(text, "frag.xml", limits);
  if (f) {
    ADD_FAILURE() << "accepted:\n" << text;
    return {};
  }
  return f.error().message;
}

// Lines 2-4: a triangle (vertices 0..2); line 5: its body; `extra` from line 6.
std::string fragment_with(const std::string& extra, const std::string& body = "") {
  return "<scene>\n"
         "  <rigidbodyvertex x=\"0\" y=\"0\" m=\"1\"/>\n"
         "  <rigidbodyvertex x=\"2\" y=\"0\" m=\"1\"/>\n"
         "  <rigidbodyvertex x=\"0\" y=\"2\" m=\"2\"/>\n" +
         (body.empty()
              ? std::string(
                    "  <rigidbody p=\"0\" p=\"1\" p=\"2\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n")
              : body) +
         extra + "</scene>\n";
}

TEST(ParseFragment, ValidFragmentRoundTripsExactly) {
  const std::string text =
      "<scene>\n"
      "  <description text=\"a wing\"/>\n"
      "  <rigidbodyvertex x=\"-1.25\" y=\"0.1\" m=\"0.3\"/>\n"
      "  <rigidbodyvertex x=\"3e-3\" y=\"-7\" m=\"2\"/>\n"
      "  <rigidbodyvertex x=\"4.5\" y=\" 6 \" m=\"1e-2\"/>\n"
      "  <rigidbody p=\"2\" p=\"0\" p=\"1\" vx=\"0.7\" vy=\"-1.5\" omega=\"3.25\" r=\"0.05\"/>\n"
      "  <rigidbodycolor body=\"0\" r=\"0.5\" g=\"0.25\" b=\"1\"/>\n"
      "  <rigidbodyspringforce i=\"0\" pix=\"0.1\" piy=\"0.2\" j=\"-1\" pjx=\"10\" pjy=\"-20\" k=\"40\" "
      "l0=\"5.35\"/>\n"
      "  <rigidbodyspringforce ibody=\"arm\" pix=\"1\" piy=\"2\" j=\"0\" pjx=\"3\" pjy=\"4\" k=\"0\" "
      "l0=\"0\"/>\n"
      "  <rigidbodyspringcolor spring=\"1\" r=\"0\" g=\"0.75\" b=\"0.125\"/>\n"
      "</scene>\n";
  const Fragment f = parse_ok(text);
  EXPECT_EQ(f.path, "frag.xml");
  EXPECT_EQ(f.description, "a wing");
  EXPECT_TRUE(f.warnings.empty());
  // The hull in p order, positions as written (fragment-local), with their masses.
  ASSERT_EQ(f.body.hull.size(), 3u);
  EXPECT_EQ(f.body.hull[0], Vec2(4.5, 6.0));
  EXPECT_EQ(f.body.hull[1], Vec2(-1.25, 0.1));
  EXPECT_EQ(f.body.hull[2], Vec2(3e-3, -7.0));
  EXPECT_EQ(f.body.masses, (std::vector<double>{1e-2, 0.3, 2.0}));
  EXPECT_EQ(f.body.velocity, Vec2(0.7, -1.5));
  EXPECT_EQ(f.body.omega, 3.25);
  EXPECT_EQ(f.body.radius, 0.05);
  ASSERT_TRUE(f.color.has_value());
  EXPECT_EQ(*f.color, (Color{0.5, 0.25, 1.0}));
  ASSERT_EQ(f.springs.size(), 2u);
  const FragmentSpring& a = f.springs[0];
  EXPECT_EQ(a.end_i.kind, FragmentSpringEnd::Kind::Self);
  EXPECT_EQ(a.end_i.anchor, Vec2(0.1, 0.2));
  EXPECT_TRUE(a.end_i.body.empty());
  EXPECT_EQ(a.end_j.kind, FragmentSpringEnd::Kind::Fixed);
  EXPECT_EQ(a.end_j.anchor, Vec2(10.0, -20.0));
  EXPECT_EQ(a.stiffness, 40.0);
  EXPECT_EQ(a.rest_length, 5.35);
  EXPECT_FALSE(a.color.has_value());
  const FragmentSpring& b = f.springs[1];
  EXPECT_EQ(b.end_i.kind, FragmentSpringEnd::Kind::Named);
  EXPECT_EQ(b.end_i.body, "arm");
  EXPECT_EQ(b.end_i.anchor, Vec2(1.0, 2.0));
  EXPECT_EQ(b.end_j.kind, FragmentSpringEnd::Kind::Self);
  EXPECT_EQ(b.end_j.anchor, Vec2(3.0, 4.0));
  EXPECT_EQ(b.stiffness, 0.0);
  EXPECT_EQ(b.rest_length, 0.0);
  ASSERT_TRUE(b.color.has_value());
  EXPECT_EQ(*b.color, (Color{0.0, 0.75, 0.125}));
}

TEST(ParseFragment, MinimalFragmentHasNoColourSpringsOrDescription) {
  const Fragment f = parse_ok(fragment_with(""));
  EXPECT_TRUE(f.description.empty());
  EXPECT_FALSE(f.color.has_value());
  EXPECT_TRUE(f.springs.empty());
  EXPECT_EQ(f.body.hull.size(), 3u);
  EXPECT_EQ(f.body.masses, (std::vector<double>{1.0, 1.0, 2.0}));
}

TEST(ParseFragment, NamedSpringEnds) {
  const Fragment f =
      parse_ok(fragment_with("  <rigidbodyspringforce ibody=\"base link\" pix=\"-1\" piy=\"0.5\" "
                             "jbody=\"body_3\" pjx=\"2\" pjy=\"0\" "
                             "k=\"7\" l0=\"1\"/>\n"
                             "  <rigidbodyspringforce i=\"-1\" pix=\"0\" piy=\"0\" jbody=\"arm\" "
                             "pjx=\"0.25\" pjy=\"0\" k=\"1\" l0=\"0\"/>\n"));
  ASSERT_EQ(f.springs.size(), 2u);
  EXPECT_EQ(f.springs[0].end_i.kind, FragmentSpringEnd::Kind::Named);
  EXPECT_EQ(f.springs[0].end_i.body, "base link");  // as written: the running world resolves it
  EXPECT_EQ(f.springs[0].end_i.anchor, Vec2(-1.0, 0.5));
  EXPECT_EQ(f.springs[0].end_j.kind, FragmentSpringEnd::Kind::Named);
  EXPECT_EQ(f.springs[0].end_j.body, "body_3");
  EXPECT_EQ(f.springs[0].end_j.anchor, Vec2(2.0, 0.0));
  EXPECT_EQ(f.springs[1].end_i.kind, FragmentSpringEnd::Kind::Fixed);
  EXPECT_EQ(f.springs[1].end_j.kind, FragmentSpringEnd::Kind::Named);
  EXPECT_EQ(f.springs[1].end_j.body, "arm");
  EXPECT_EQ(f.springs[1].end_j.anchor, Vec2(0.25, 0.0));
  EXPECT_TRUE(f.warnings.empty()) << f.warnings.front();
}

TEST(ParseFragment, UnknownNodesAndAttributesAreWarningsAsInScenes) {
  const Fragment f = parse_ok(fragment_with(
      "  <particle x=\"1\"/>\n  <rigidbodycolor body=\"0\" r=\"0\" g=\"0\" b=\"0\" a=\"1\"/>\n"));
  ASSERT_EQ(f.warnings.size(), 2u);
  EXPECT_EQ(f.warnings[0], "frag.xml:6: warning: unknown node <particle> ignored");
  EXPECT_EQ(f.warnings[1], "frag.xml:7: warning: <rigidbodycolor> unknown attribute 'a' ignored");
}

// Every refusal: the whole one-line message, file and line included.
struct BadFragment {
  const char* name;
  std::string text;
  std::string expected;
};
void PrintTo(const BadFragment& b, std::ostream* os) {
  *os << b.name;
}

const char* const kSpring = "pix=\"0\" piy=\"0\" pjx=\"0\" pjy=\"0\" k=\"1\" l0=\"1\"";
std::string spring(const std::string& ends) {
  return "  <rigidbodyspringforce " + ends + " " + kSpring + "/>\n";
}

std::vector<BadFragment> bad_fragments() {
  const std::string kIndexNote =
      "(-1 = fixed point, 0 = the fragment's body; a body of the running world is named with ";
  return {
      {"wrong_root", "<robot>\n</robot>\n", "frag.xml:1: <robot>: a fragment's root must be <scene>"},
      {"wrong_root_later_line", "<?xml version=\"1.0\"?>\n\n<sdf/>\n",
       "frag.xml:3: <sdf>: a fragment's root must be <scene>"},
      {"empty", "  \n", "frag.xml:1: empty fragment (expected a <scene>)"},
      {"not_xml", "<scene>\n<rigidbodyvertex x=\"1\"\n",
       "frag.xml:2: not well-formed XML: XML_ERROR_PARSING_ELEMENT (XMLElement name=rigidbodyvertex)"},
      // tinyxml2 echoes the declaration's text, newline included: the message stays one line
      {"xml_declaration_spanning_lines", "<scene>\n<?xml a\nb?>\n</scene>\n",
       "frag.xml:2: not well-formed XML: XML_ERROR_PARSING_DECLARATION (XMLDeclaration value=xml a\\nb)"},
      {"no_body", "<scene>\n  <rigidbodyvertex x=\"0\" y=\"0\" m=\"1\"/>\n</scene>\n",
       "frag.xml:1: <scene>: a fragment describes exactly one body (no <rigidbody> given)"},
      {"two_bodies",
       fragment_with("  <rigidbody p=\"0\" p=\"1\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0.1\"/>\n"),
       "frag.xml:6: <rigidbody>: a fragment describes exactly one body (the first <rigidbody> at line 5)"},
      {"vertex_missing_y", fragment_with("  <rigidbodyvertex x=\"1\" m=\"1\"/>\n"),
       "frag.xml:6: <rigidbodyvertex> attribute 'y': required attribute is missing"},
      {"vertex_mass_zero", fragment_with("  <rigidbodyvertex x=\"1\" y=\"1\" m=\"0\"/>\n"),
       "frag.xml:6: <rigidbodyvertex> attribute 'm': must be > 0 (got 0)"},
      {"vertex_nan", fragment_with("  <rigidbodyvertex x=\"nan\" y=\"1\" m=\"1\"/>\n"),
       "frag.xml:6: <rigidbodyvertex> attribute 'x': must be a finite number (got \"nan\")"},
      {"vertex_index_high",
       fragment_with("", "  <rigidbody p=\"0\" p=\"3\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"1\"/>\n"),
       "frag.xml:5: <rigidbody> attribute 'p': vertex index 3 out of range [0, 2]"},
      {"vertex_not_used",
       fragment_with("", "  <rigidbody p=\"0\" p=\"2\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"1\"/>\n"),
       "frag.xml:3: <rigidbodyvertex>: vertex 1 is not on the hull of the fragment's <rigidbody> (line 5)"},
      {"one_hull_vertex", fragment_with("", "  <rigidbody p=\"0\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"1\"/>\n"),
       "frag.xml:5: <rigidbody> attribute 'p': a rigid body needs at least 2 hull vertices (got 1)"},
      {"radius_zero",
       fragment_with("", "  <rigidbody p=\"0\" p=\"1\" p=\"2\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"0\"/>\n"),
       "frag.xml:5: <rigidbody> attribute 'r': must be > 0 (got 0)"},
      {"vertices_coincide",
       "<scene>\n  <rigidbodyvertex x=\"1\" y=\"1\" m=\"1\"/>\n  <rigidbodyvertex x=\"1\" y=\"1\" m=\"2\"/>\n"
       "  <rigidbody p=\"0\" p=\"1\" vx=\"0\" vy=\"0\" omega=\"0\" r=\"1\"/>\n</scene>\n",
       "frag.xml:4: <rigidbody> attribute 'p': all hull vertices coincide (the body has no moment of "
       "inertia)"},
      {"duplicate_attribute",
       fragment_with("  <rigidbodycolor body=\"0\" r=\"0\" r=\"1\" g=\"0\" b=\"0\"/>\n"),
       "frag.xml:6: <rigidbodycolor> attribute 'r': attribute given more than once"},
      {"description_twice", fragment_with("  <description text=\"a\"/>\n  <description text=\"b\"/>\n"),
       "frag.xml:7: <description>: node may appear only once (first at line 6)"},
      {"spring_i_and_ibody", fragment_with(spring("i=\"0\" ibody=\"arm\" j=\"-1\"")),
       "frag.xml:6: <rigidbodyspringforce> attribute 'ibody': give either 'i' or 'ibody', not both"},
      {"spring_j_and_jbody", fragment_with(spring("i=\"0\" j=\"-1\" jbody=\"arm\"")),
       "frag.xml:6: <rigidbodyspringforce> attribute 'jbody': give either 'j' or 'jbody', not both"},
      {"spring_empty_name", fragment_with(spring("ibody=\"\" j=\"0\"")),
       "frag.xml:6: <rigidbodyspringforce> attribute 'ibody': must name a body of the running world (got "
       "\"\")"},
      {"spring_blank_name", fragment_with(spring("i=\"0\" jbody=\" \t\"")),
       "frag.xml:6: <rigidbodyspringforce> attribute 'jbody': must name a body of the running world (got \" "
       "\\t\")"},
      {"spring_no_i", fragment_with(spring("j=\"0\"")),
       "frag.xml:6: <rigidbodyspringforce> attribute 'i': required attribute is missing (or name a body of "
       "the "
       "running world with 'ibody')"},
      {"spring_i_one", fragment_with(spring("i=\"1\" j=\"0\"")),
       "frag.xml:6: <rigidbodyspringforce> attribute 'i': body index 1 out of range [-1, 0] " + kIndexNote +
           "'ibody')"},
      {"spring_j_minus_two", fragment_with(spring("i=\"0\" j=\"-2\"")),
       "frag.xml:6: <rigidbodyspringforce> attribute 'j': body index -2 out of range [-1, 0] " + kIndexNote +
           "'jbody')"},
      {"spring_j_not_integer", fragment_with(spring("i=\"0\" j=\"0.5\"")),
       "frag.xml:6: <rigidbodyspringforce> attribute 'j': must be an integer (got \"0.5\")"},
      {"spring_k_negative",
       fragment_with("  <rigidbodyspringforce i=\"0\" j=\"-1\" pix=\"0\" piy=\"0\" pjx=\"0\" pjy=\"0\" "
                     "k=\"-1\" l0=\"0\"/>\n"),
       "frag.xml:6: <rigidbodyspringforce> attribute 'k': must be >= 0 (got -1)"},
      {"body_colour_not_zero", fragment_with("  <rigidbodycolor body=\"1\" r=\"0\" g=\"0\" b=\"0\"/>\n"),
       "frag.xml:6: <rigidbodycolor> attribute 'body': body index 1 out of range [0, 0]"},
      {"body_colour_component", fragment_with("  <rigidbodycolor body=\"0\" r=\"0\" g=\"1.5\" b=\"0\"/>\n"),
       "frag.xml:6: <rigidbodycolor> attribute 'g': colour component must be in [0, 1] (got 1.5)"},
      {"spring_colour_index",
       fragment_with(spring("i=\"0\" j=\"-1\"") +
                     "  <rigidbodyspringcolor spring=\"1\" r=\"0\" g=\"0\" b=\"0\"/>\n"),
       "frag.xml:7: <rigidbodyspringcolor> attribute 'spring': spring index 1 out of range [0, 0]"},
      {"spring_colour_without_springs",
       fragment_with("  <rigidbodyspringcolor spring=\"0\" r=\"0\" g=\"0\" b=\"0\"/>\n"),
       "frag.xml:6: <rigidbodyspringcolor> attribute 'spring': spring index 0 out of range [0, -1]"},
  };
}

class ParseFragmentBad : public ::testing::TestWithParam<BadFragment> {};

TEST_P(ParseFragmentBad, GivesTheDocumentedOneLineError) {
  EXPECT_EQ(error_of(GetParam().text), GetParam().expected);
}

INSTANTIATE_TEST_SUITE_P(Table, ParseFragmentBad, ::testing::ValuesIn(bad_fragments()),
                         [](const auto& tp) { return std::string(tp.param.name); });

TEST(ParseFragment, RefusesEverySceneWideElementAtItsLine) {
  const char* const elements[] = {"<simtype type=\"rigid-body\"/>",
                                  "<duration time=\"1\"/>",
                                  "<maxsimfreq max=\"100\"/>",
                                  "<viewport cx=\"0\" cy=\"0\" size=\"1\"/>",
                                  "<backgroundcolor r=\"1\" g=\"1\" b=\"1\"/>",
                                  "<scenetag tag=\"x\"/>",
                                  "<rigidbodyintegrator type=\"symplectic-euler\" dt=\"0.01\"/>",
                                  "<rigidbodygravityforce fx=\"0\" fy=\"-9.81\"/>",
                                  "<rigidbodywindforce beta=\"1\" fx=\"1\" fy=\"0\" pointsperedge=\"4\"/>"};
  for (const std::string element : elements) {
    SCOPED_TRACE(element);
    const std::string name = element.substr(1, element.find(' ') - 1);
    EXPECT_EQ(error_of(fragment_with("\n  " + element + "\n")),
              "frag.xml:7: <" + name + ">: not allowed in a spawnable fragment (a scene-wide element)");
    // ... also before the body, and even when malformed: refused by name, not by its attributes
    EXPECT_EQ(error_of("<scene>\n<" + name + " bogus=\"?\"/>\n</scene>\n"),
              "frag.xml:2: <" + name + ">: not allowed in a spawnable fragment (a scene-wide element)");
  }
}

// The same mistake inside a scene and inside a fragment is worded alike: one rule, one reader.
TEST(ParseFragment, SharesLoadScenesAttributeRulesAndWording) {
  const std::string bad_vertex = "  <rigidbodyvertex x=\"1e999\" y=\"0\" m=\"1\"/>\n";
  const std::string scene_text =
      "<scene>\n<duration time=\"1\"/>\n<rigidbodyintegrator type=\"explicit-euler\" "
      "dt=\"0.1\"/>\n<rigidbodyvertex x=\"0\" y=\"0\" m=\"1\"/>\n" +
      bad_vertex + "</scene>\n";
  const std::string fragment_text =
      "<scene>\n\n\n<rigidbodyvertex x=\"0\" y=\"0\" m=\"1\"/>\n" + bad_vertex + "</scene>\n";
  Result<Scene> s = parse_scene(scene_text, "frag.xml");
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(error_of(fragment_text), s.error().message);
  EXPECT_EQ(s.error().message,
            "frag.xml:5: <rigidbodyvertex> attribute 'x': must be a finite number (got \"1e999\")");
}

TEST(ParseFragment, LimitOnBytesIsCheckedBeforeParsing) {
  const std::string text = fragment_with("");
  FragmentLimits limits;
  limits.max_bytes = text.size();
  EXPECT_EQ(parse_ok(text, limits).body.hull.size(), 3u);  // exactly at the limit
  limits.max_bytes = text.size() - 1;
  EXPECT_EQ(error_of(text, limits), "frag.xml: " + std::to_string(text.size()) +
                                        " bytes, over the limit of " + std::to_string(text.size() - 1) +
                                        " for a fragment");
  // not parsed: even garbage is refused by its size alone
  EXPECT_EQ(error_of(std::string(limits.max_bytes + 1, '<'), limits),
            "frag.xml: " + std::to_string(text.size()) + " bytes, over the limit of " +
                std::to_string(text.size() - 1) + " for a fragment");
  // the default: 1 MiB
  const std::string big = fragment_with(std::string((1 << 20) - text.size() + 1, ' '));
  EXPECT_EQ(error_of(big), "frag.xml: 1048577 bytes, over the limit of 1048576 for a fragment");
  EXPECT_TRUE(parse_fragment(big.substr(0, big.size() - 10) + "</scene>\n", "frag.xml").ok());
}

TEST(ParseFragment, LimitOnVerticesNamesTheFirstOneOver) {
  FragmentLimits limits;
  limits.max_vertices = 3;
  EXPECT_EQ(parse_ok(fragment_with(""), limits).body.hull.size(), 3u);
  limits.max_vertices = 2;
  EXPECT_EQ(error_of(fragment_with(""), limits),
            "frag.xml:4: <rigidbodyvertex>: over the limit of 2 vertices for a fragment");
  limits.max_vertices = 0;
  EXPECT_EQ(error_of(fragment_with(""), limits),
            "frag.xml:2: <rigidbodyvertex>: over the limit of 0 vertices for a fragment");
  // the default: 10000
  std::string many = "<scene>\n";
  std::string body = "<rigidbody";
  for (int v = 0; v < 10001; ++v) {
    many += "<rigidbodyvertex x=\"" + std::to_string(v) + "\" y=\"0\" m=\"1\"/>\n";
    if (v < 4000) body += " p=\"" + std::to_string(v) + "\"";
  }
  EXPECT_EQ(error_of(many + body + " vx=\"0\" vy=\"0\" omega=\"0\" r=\"1\"/>\n</scene>\n"),
            "frag.xml:10002: <rigidbodyvertex>: over the limit of 10000 vertices for a fragment");
}

TEST(ParseFragment, LimitOnSpringsNamesTheFirstOneOver) {
  std::string springs;
  for (int s = 0; s < 3; ++s) springs += spring("i=\"0\" j=\"-1\"");
  FragmentLimits limits;
  limits.max_springs = 3;
  EXPECT_EQ(parse_ok(fragment_with(springs), limits).springs.size(), 3u);
  limits.max_springs = 1;
  EXPECT_EQ(error_of(fragment_with(springs), limits),
            "frag.xml:7: <rigidbodyspringforce>: over the limit of 1 springs for a fragment");
  // the default: 1000
  std::string many;
  for (int s = 0; s < 1001; ++s) many += spring("i=\"0\" jbody=\"b" + std::to_string(s) + "\"");
  EXPECT_EQ(error_of(fragment_with(many)),
            "frag.xml:1006: <rigidbodyspringforce>: over the limit of 1000 springs for a fragment");
}

void expect_same_body(const BodyDef& a, const BodyDef& b) {
  EXPECT_EQ(a.hull, b.hull);
  EXPECT_EQ(a.masses, b.masses);
  EXPECT_EQ(a.velocity, b.velocity);
  EXPECT_EQ(a.omega, b.omega);
  EXPECT_EQ(a.radius, b.radius);
}

// scenes/airplane.xml without its scene-wide lines is a fragment: the same body, the same spring.
TEST(ParseFragment, BundledSceneBodyGivesTheSameBodyDef) {
  const std::string path = kBundled + "/airplane.xml";
  Result<Scene> scene = load_scene(path);
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_EQ(scene->world.bodies.size(), 1u);
  std::istringstream in(read(path));
  std::string text, line;
  while (std::getline(in, line)) {
    bool wide = false;
    for (const char* e : {"<simtype", "<duration", "<maxsimfreq", "<viewport", "<rigidbodyintegrator",
                          "<rigidbodygravityforce", "<rigidbodywindforce"}) {
      wide = wide || line.find(e) != std::string::npos;
    }
    if (!wide) text += line + "\n";
  }
  const Fragment f = parse_ok(text);
  EXPECT_EQ(f.description, scene->description);
  expect_same_body(f.body, scene->world.bodies[0]);
  ASSERT_EQ(f.springs.size(), 1u);
  const SpringDef& s = scene->world.springs[0];
  ASSERT_EQ(s.body_i, kFixed);
  ASSERT_EQ(s.body_j, 0);
  EXPECT_EQ(f.springs[0].end_i.kind, FragmentSpringEnd::Kind::Fixed);
  EXPECT_EQ(f.springs[0].end_i.anchor, s.anchor_i);
  EXPECT_EQ(f.springs[0].end_j.kind, FragmentSpringEnd::Kind::Self);
  EXPECT_EQ(f.springs[0].end_j.anchor, s.anchor_j);
  EXPECT_EQ(f.springs[0].stiffness, s.stiffness);
  EXPECT_EQ(f.springs[0].rest_length, s.rest_length);
}

// The third link of scenes/chain.xml, its vertices renumbered from 0, hung from the second by name.
TEST(ParseFragment, BundledChainLinkGivesTheSameBodyDef) {
  Result<Scene> scene = load_scene(kBundled + "/chain.xml");
  ASSERT_TRUE(scene) << scene.error().message;
  ASSERT_GE(scene->world.bodies.size(), 3u);
  const Fragment f = parse_ok(
      "<scene>\n"
      "  <rigidbodyvertex x=\"2\" y=\"0\" m=\"1\"/>\n"
      "  <rigidbodyvertex x=\"3\" y=\"0\" m=\"1\"/>\n"
      "  <rigidbody p=\"0\" p=\"1\" vx=\"0.0\" vy=\"0.0\" omega=\"0.0\" r=\"0.1\"/>\n"
      "  <rigidbodyspringforce ibody=\"link 1\" pix=\"0.5\" piy=\"0.0\" j=\"0\" pjx=\"-0.5\" pjy=\"0.0\" "
      "k=\"1900000.0\" l0=\"0.0\"/>\n"
      "</scene>\n");
  expect_same_body(f.body, scene->world.bodies[2]);
  const SpringDef& s = scene->world.springs[2];  // i="1" j="2"
  ASSERT_EQ(f.springs.size(), 1u);
  EXPECT_EQ(f.springs[0].end_i.anchor, s.anchor_i);
  EXPECT_EQ(f.springs[0].end_j.anchor, s.anchor_j);
  EXPECT_EQ(f.springs[0].stiffness, s.stiffness);
}

// Network input: truncations, mutations and garbage give a Fragment or a one-line error naming the source.
TEST(ParseFragment, NeverCrashesOnTruncatedMutatedOrBinaryInput) {
  const std::string text = fragment_with(spring("i=\"0\" jbody=\"arm\"") +
                                         "  <rigidbodyspringcolor spring=\"0\" r=\"0\" g=\"0.5\" b=\"1\"/>\n"
                                         "  <description text=\"d\"/>\n");
  int ok = 0, errors = 0;
  auto check = [&](const std::string& input, const std::string& what) {
    Result<Fragment> f = parse_fragment(input, "net.xml");
    if (f) {
      ++ok;
      EXPECT_GE(f->body.hull.size(), 2u) << what;
    } else {
      ++errors;
      const std::string& m = f.error().message;
      EXPECT_EQ(m.rfind("net.xml", 0), 0u) << what << ": " << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << what << ": " << m;
    }
  };
  for (std::size_t n = 0; n <= text.size(); ++n) check(text.substr(0, n), "prefix " + std::to_string(n));
  std::mt19937_64 rng(0xf4a6);
  const std::string interesting = "<>/=\"' \n-+.0123456789eEinfa\x01\xff";
  for (int i = 0; i < 3000; ++i) {
    std::string mutated = text;
    const std::size_t at = rng() % mutated.size();
    const char c = i % 2 ? static_cast<char>(rng() % 256) : interesting[rng() % interesting.size()];
    if (i % 3 == 0) {
      mutated[at] = c;
    } else if (i % 3 == 1) {
      mutated.erase(at, 1);
    } else {
      mutated.insert(at, 1, c);
    }
    check(mutated, "mutation " + std::to_string(i));
  }
  for (int i = 0; i < 200; ++i) {
    std::string garbage(rng() % 400, '\0');
    for (char& ch : garbage) ch = static_cast<char>(rng() % 256);
    check(i % 2 ? "<scene " + garbage : garbage, "garbage " + std::to_string(i));
  }
  EXPECT_GT(ok, 100);
  EXPECT_GT(errors, 1000);
}

}  // namespace
}  // namespace rbsim
