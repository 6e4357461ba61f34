// Robustness: truncated and mutated scenes give a Scene or an Error, never a crash or a hang.
#include <gtest/gtest.h>

#include <fstream>
#include <random>
#include <sstream>
#include <string>

#include "rbsim/scene.hpp"

namespace rbsim {
namespace {

const std::string kScenes = std::string(RBSIM_TEST_DATA_DIR) + "/fosssim/scenes";

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// An error must be one line naming the source; a scene must be one the core accepts.
void check(const std::string& text, const std::string& what, int& ok, int& errors) {
  Result<Scene> s = parse_scene(text, "fuzz.xml");
  if (s) {
    ++ok;
    ASSERT_TRUE(World::create(s->world).ok()) << what;
  } else {
    ++errors;
    const std::string& m = s.error().message;
    ASSERT_EQ(m.rfind("fuzz.xml:", 0), 0u) << what << ": " << m;
    ASSERT_EQ(m.find('\n'), std::string::npos) << what << ": " << m;
  }
}

TEST(ParseSceneFuzz, EveryPrefixTruncation) {
  for (const char* name : {"/springtests/test02sym.xml", "/windtests/test00ee.xml"}) {
    const std::string text = read(kScenes + name);
    ASSERT_GT(text.size(), 500u);
    int ok = 0, errors = 0;
    for (std::size_t n = 0; n <= text.size(); ++n)
      check(text.substr(0, n), "prefix " + std::to_string(n), ok, errors);
    EXPECT_GT(errors, 0);
    EXPECT_GE(ok, 1);  // at least the whole file
  }
}

TEST(ParseSceneFuzz, RandomSingleByteMutations) {
  const std::string text = read(kScenes + "/hollistictests/airplane.xml");
  ASSERT_GT(text.size(), 500u);
  std::mt19937_64 rng(0x5eed);
  const std::string interesting = "<>/=\"' \n-+.0123456789eEinfa\x01\xff";
  int ok = 0, errors = 0;
  for (int i = 0; i < 3000; ++i) {
    std::string mutated = text;
    const std::size_t at = rng() % mutated.size();
    const char c = i % 2 ? static_cast<char>(rng() % 256) : interesting[rng() % interesting.size()];
    switch (i % 3) {
      case 0:
        mutated[at] = c;
        break;
      case 1:
        mutated.erase(at, 1);
        break;
      default:
        mutated.insert(at, 1, c);
        break;
    }
    check(mutated, "mutation " + std::to_string(i) + " at byte " + std::to_string(at), ok, errors);
  }
  EXPECT_GT(ok, 100);
  EXPECT_GT(errors, 100);
}

TEST(ParseSceneFuzz, EmbeddedNulAndBinaryGarbage) {
  int ok = 0, errors = 0;
  std::string text = read(kScenes + "/gravitytests/test00ee.xml");
  text.insert(text.size() / 2, 1, '\0');
  check(text, "embedded NUL", ok, errors);
  std::mt19937_64 rng(3);
  for (int i = 0; i < 200; ++i) {
    std::string garbage(rng() % 400, '\0');
    for (char& ch : garbage) ch = static_cast<char>(rng() % 256);
    if (i % 2) garbage = "<scene " + garbage;
    check(garbage, "garbage " + std::to_string(i), ok, errors);
  }
  EXPECT_GT(errors, 150);
}

}  // namespace
}  // namespace rbsim
