// The one topic selector (msgs::select_topics, selects_topic, unknown_topic): names in every form,
// the type's suffix, regular expressions, exclusions, and the one wording of an unknown name.
#include <gtest/gtest.h>

#include <string>
#include <utility>
#include <vector>

#include "rbsim/msgs.hpp"

namespace rbsim::msgs {
namespace {

const TopicSpec& spec(TopicId id) {
  return topic(id);
}

// What a merged recording of two nodes might hold, plus a topic of another type.
std::vector<TopicCandidate> recorded() {
  return {{"/a/body_states", &spec(TopicId::BodyStates)},
          {"/b/body_states", &spec(TopicId::BodyStates)},
          {"/clock", &spec(TopicId::Clock)},
          {"/remapped/states", &spec(TopicId::BodyStates)},
          {"/diagnostics", nullptr}};
}

// A filter, every field given (the aggregate's missing fields would be a warning).
TopicFilter filter(std::vector<std::string> topics, std::string regex = "",
                   std::vector<std::string> exclude = {}, std::string exclude_regex = "") {
  return TopicFilter{std::move(topics), std::move(regex), std::move(exclude), std::move(exclude_regex)};
}

std::vector<std::size_t> chosen(const TopicFilter& filter, const std::vector<TopicCandidate>& candidates) {
  Result<std::vector<std::size_t>> r = select_topics(filter, candidates);
  EXPECT_TRUE(r.ok()) << r.error().message;
  return r.ok() ? r.value() : std::vector<std::size_t>{};
}

TEST(TopicSelector, ANameSelectsByWholeNameTrailingPartsOrItsTypesSuffix) {
  const TopicCandidate states{"/rbsim/body_states", &spec(TopicId::BodyStates)};
  EXPECT_TRUE(selects_topic("/rbsim/body_states", states));
  EXPECT_TRUE(selects_topic("rbsim/body_states", states));
  EXPECT_TRUE(selects_topic("body_states", states));
  EXPECT_FALSE(selects_topic("states", states));
  EXPECT_FALSE(selects_topic("/body_states", states));
  EXPECT_FALSE(selects_topic("", states));
  // A channel of our type recorded under another name answers to its type's suffix too.
  EXPECT_TRUE(selects_topic("body_states", {"/remapped/states", &spec(TopicId::BodyStates)}));
  EXPECT_FALSE(selects_topic("body_states", {"/remapped/states", nullptr}));
  EXPECT_TRUE(selects_topic("tf", {"/tf", &spec(TopicId::Tf)}));
}

TEST(TopicSelector, KeepsWhatIsNamedOrMatchedMinusWhatIsExcluded) {
  const std::vector<TopicCandidate> c = recorded();
  EXPECT_EQ(chosen(filter({}), c), (std::vector<std::size_t>{0, 1, 2, 3, 4}));  // nothing to keep: all
  EXPECT_EQ(chosen(filter({"body_states"}), c), (std::vector<std::size_t>{0, 1, 3}));
  EXPECT_EQ(chosen(filter({"/a/body_states", "clock"}), c), (std::vector<std::size_t>{0, 2}));
  EXPECT_EQ(chosen(filter({"", "clock", ""}), c), (std::vector<std::size_t>{2}));  // empty names skipped
  EXPECT_EQ(chosen(filter({""}), c), (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(chosen(filter({}, "/[ab]/.*"), c), (std::vector<std::size_t>{0, 1}));  // the whole name
  EXPECT_EQ(chosen(filter({}, "body"), c), (std::vector<std::size_t>{}));
  EXPECT_EQ(chosen(filter({"clock"}, ".*states", {"/b/body_states"}), c),
            (std::vector<std::size_t>{0, 2, 3}));
  EXPECT_EQ(chosen(filter({}, "", {"body_states"}, "/d.*"), c), (std::vector<std::size_t>{2}));
}

TEST(TopicSelector, AnUnknownNameIsOneErrorListingTheTopicsSortedOnce) {
  std::vector<TopicCandidate> c = recorded();
  c.push_back({"/clock", &spec(TopicId::Clock)});  // a second channel on a topic: listed once
  for (const TopicFilter& bad : {filter({"clock", "nope"}), filter({}, "", {"nope"})}) {
    Result<std::vector<std::size_t>> r = select_topics(bad, c);
    ASSERT_FALSE(r.ok());
    EXPECT_EQ(r.error().message,
              "unknown topic \"nope\" (topics: /a/body_states, /b/body_states, /clock, /diagnostics, "
              "/remapped/states)");
    EXPECT_EQ(r.error().code, ErrorCode::Failed);
  }
  EXPECT_EQ(unknown_topic("x", {}).message, "unknown topic \"x\" (topics: none)");
  Result<std::vector<std::size_t>> regex = select_topics(filter({}, "("), c);
  ASSERT_FALSE(regex.ok());
  EXPECT_EQ(regex.error().message.rfind("--regex \"(\": not a regular expression (", 0), 0u)
      << regex.error().message;
  EXPECT_EQ(regex.error().code, ErrorCode::InvalidArgument);
  EXPECT_FALSE(select_topics(filter({}, "", {}, "["), c).ok());
}

TEST(TopicSelector, OurTopicsAsCandidatesAndParseTopicSetAgree) {
  const std::vector<TopicCandidate> all = topic_candidates("robots", /*events=*/true);
  ASSERT_EQ(all.size(), topics().size());
  EXPECT_EQ(all[0].name, "/robots/scene");
  EXPECT_EQ(all.back().spec->id, TopicId::Commands);
  const std::vector<TopicCandidate> sinks = topic_candidates("robots", /*events=*/false);
  EXPECT_EQ(sinks.size(), topics().size() - 1);  // no event topic
  // parse_topic_set is the selector over the second list: the same names, the same error.
  for (const char* name : {"body_states", "/robots/body_states", "robots/body_states", "/tf", "tf"}) {
    const Result<TopicSet> set = parse_topic_set(name, "robots");
    ASSERT_TRUE(set.ok()) << name;
    const std::vector<std::size_t> picked = chosen(filter({name}), sinks);
    ASSERT_EQ(picked.size(), 1u) << name;
    EXPECT_TRUE(set.value().test(static_cast<std::size_t>(sinks[picked[0]].spec->id))) << name;
  }
  const Result<TopicSet> bad = parse_topic_set("nope", "robots");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message, unknown_topic("nope", sinks).message);
  EXPECT_EQ(bad.error().message,
            "unknown topic \"nope\" (topics: /clock, /robots/body_states, /robots/energy, /robots/markers, "
            "/robots/poses, /robots/scene, /robots/spring_states, /robots/springs, /tf)");
  EXPECT_FALSE(parse_topic_set("commands", "robots").ok());  // no sink's --topics selects it
}

}  // namespace
}  // namespace rbsim::msgs
