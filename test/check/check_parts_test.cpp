// The comparer's pieces one by one, through its internal headers (tools/check/src): the layout of
// a schema, the lockstep walk of two messages, the step runs and the report's sentences.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "compare_values.hpp"
#include "layout.hpp"
#include "rbsim/cdr_builder.hpp"
#include "rbsim/check.hpp"
#include "rbsim/msgs.hpp"
#include "sentences.hpp"
#include "steps.hpp"

namespace {

using rbsim::check::Layout;
using rbsim::check::StepRuns;
using rbsim::check::StepTrack;
using rbsim::msgs::Scalar;

// step, t, items.length, items[].x, items[].id, name, v[]
constexpr const char* kType = "test_msgs/msg/T";
constexpr const char* kSchema =
    "uint64 step\nfloat64 t\nInner[] items\nstring name\nfloat64[2] v\n"
    "================================================================================\n"
    "MSG: test_msgs/Inner\nfloat64 x\nint32 id\n";
enum Group : std::uint32_t { kStep, kT, kItemsLength, kX, kId, kName, kV, kGroups };

using rbsim::test::Cdr;

struct Item {
  double x;
  std::int32_t id;
};
rbsim::msgs::Bytes message(std::uint64_t step, const std::vector<Item>& items,
                           const std::string& name = "n") {
  Cdr c;
  c.put(step).put(0.5).put(static_cast<std::uint32_t>(items.size()));
  for (const Item& i : items) c.put(i.x).put(i.id);
  c.str(name).put(1.0).put(2.0);
  return c.bytes;
}

Layout layout() {
  auto l = Layout::create(kType, kSchema);
  EXPECT_TRUE(l.ok()) << l.error().message;
  return std::move(l.value());
}

std::vector<Scalar> decode(const rbsim::msgs::Bytes& cdr) {
  auto d = rbsim::msgs::MessageDecoder::create(kType, kSchema);
  EXPECT_TRUE(d.ok());
  std::vector<Scalar> s;
  EXPECT_TRUE(d->decode(cdr, s).ok());
  return s;
}

TEST(CheckLayout, ExpandsTheSchemaIntoFieldGroups) {
  const Layout l = layout();
  std::vector<std::string> paths;
  for (const auto& g : l.groups()) paths.push_back(g.path);
  EXPECT_EQ(paths, (std::vector<std::string>{"step", "t", "items.length", "items[].x", "items[].id", "name",
                                             "v[]"}));
  EXPECT_EQ(l.groups()[kItemsLength].kind, Scalar::Kind::Length);
  EXPECT_EQ(l.groups()[kName].kind, Scalar::Kind::String);
  EXPECT_TRUE(l.has_step());
  ASSERT_EQ(l.root().size(), 5u);
  const Layout::Field& items = l.root()[2];
  ASSERT_TRUE(items.flat);  // float64 then int32: 12 bytes from offset 0, 16 from offset 4 (padding)
  EXPECT_EQ(items.flat_size[0], 12u);
  EXPECT_EQ(items.flat_size[4], 16u);
  EXPECT_TRUE(l.same_fields(layout()));
  EXPECT_FALSE(Layout::create(kType, "uint64 step\nMissing m\n").ok());
}

TEST(CheckLayout, MapsEveryScalarOfAMessageToItsGroup) {
  const Layout l = layout();
  rbsim::check::Plan plan;
  const std::vector<Scalar> s = decode(message(7, {{1.0, 1}, {2.0, 2}}));
  ASSERT_TRUE(l.map(s, plan));
  EXPECT_EQ(plan.group,
            (std::vector<std::uint32_t>{kStep, kT, kItemsLength, kX, kId, kX, kId, kName, kV, kV}));
  EXPECT_EQ(plan.step, 0);
  ASSERT_EQ(plan.lengths.size(), 1u);
  EXPECT_EQ(plan.lengths[0], (std::pair<std::uint32_t, std::uint64_t>{2, 2}));
  EXPECT_TRUE(plan.fits(s));
  EXPECT_FALSE(plan.fits(decode(message(7, {{1.0, 1}}))));
  EXPECT_FALSE(l.map(std::span(s).first(5), plan));  // cut short: does not fit the schema
}

TEST(CheckLayout, PairsTheValuesTwoMessagesHaveInCommon) {
  const Layout l = layout();
  const std::vector<Scalar> a = decode(message(7, {{1.0, 1}, {2.0, 2}}));
  const std::vector<Scalar> b = decode(message(7, {{1.0, 1}, {2.0, 2}, {3.0, 3}}));
  std::vector<rbsim::check::Pair> pairs;
  ASSERT_TRUE(l.pair(a, b, pairs));
  // step, t, the two lengths, two common elements (x, id each), name, v[0], v[1]; b's third
  // element is left out.
  ASSERT_EQ(pairs.size(), 10u);
  EXPECT_EQ(pairs[2].group, kItemsLength);
  EXPECT_EQ(pairs[7].group, kName);
  EXPECT_EQ(pairs[7].a, 7u);
  EXPECT_EQ(pairs[7].b, 9u);
  EXPECT_EQ(pairs[9].a, a.size() - 1);
  EXPECT_EQ(pairs[9].b, b.size() - 1);
}

TEST(CheckLayout, CountsTheValuesOfAMessageWithoutDecodingIt) {
  const Layout l = layout();
  const rbsim::msgs::Bytes m = message(7, {{1.0, 1}, {2.0, 2}, {3.0, 3}}, "name");
  std::vector<std::uint64_t> counts;
  ASSERT_TRUE(l.count(m, counts));
  EXPECT_EQ(counts, (std::vector<std::uint64_t>{1, 1, 1, 3, 3, 1, 2}));
  ASSERT_TRUE(l.count(m, counts));  // adds up
  EXPECT_EQ(counts[kX], 6u);
  for (std::size_t n = 0; n < m.size(); ++n) {
    EXPECT_FALSE(l.count(std::span(m).first(n), counts)) << "prefix " << n;
  }
}

// The lockstep walk of a run message and a golden message, with the options' tolerance.
struct Walked {
  rbsim::check::WalkResult result;
  rbsim::check::Tally tally;
  std::uint64_t diverging = 0;
};
Walked walk(const rbsim::msgs::Bytes& run, const rbsim::msgs::Bytes& golden, double atol = 0.0) {
  rbsim::check::CheckOptions options;
  options.atol = atol;
  rbsim::check::Values values(options);
  const Layout l = layout();
  auto decoder = rbsim::msgs::MessageDecoder::create(kType, kSchema);
  EXPECT_TRUE(decoder.ok());
  Walked w;
  w.tally.stats.resize(kGroups + 1);
  values.begin_message();
  w.result = rbsim::check::lockstep(values, l, w.tally, "/t", decoder.value(), run, golden);
  values.at_step(42);
  w.diverging = values.diverging_values;
  return w;
}

TEST(CheckLockstep, EqualMessagesMatchEveryValue) {
  const rbsim::msgs::Bytes m = message(7, {{1.0, 1}, {2.0, 2}});
  const Walked w = walk(m, m);
  EXPECT_EQ(w.result.walk, rbsim::check::Walk::Ok);
  EXPECT_EQ(w.result.index, 10u);  // every scalar the decoder gives
  EXPECT_EQ(w.result.first_bad, UINT64_MAX);
  EXPECT_TRUE(w.result.has_step);
  EXPECT_EQ(w.result.step, 7u);
  EXPECT_EQ(w.diverging, 0u);
  EXPECT_EQ(w.tally.stats[kX].values, 2u);
  EXPECT_EQ(w.tally.stats[kV].values, 2u);
  EXPECT_EQ(w.tally.stats[kName].values, 1u);
  EXPECT_EQ(w.tally.stats[kX].max_abs, 0.0);
}

TEST(CheckLockstep, AValueWithinTheToleranceIsRecordedNotADivergence) {
  const Walked w = walk(message(7, {{1.0, 1}, {2.0001, 2}}), message(7, {{1.0, 1}, {2.0, 2}}), 1e-3);
  EXPECT_EQ(w.result.walk, rbsim::check::Walk::Ok);
  EXPECT_EQ(w.result.first_bad, UINT64_MAX);
  EXPECT_EQ(w.diverging, 0u);
  EXPECT_NEAR(w.tally.stats[kX].max_abs, 1e-4, 1e-12);
  EXPECT_EQ(w.tally.stats[kX].over, 0u);
  EXPECT_EQ(w.tally.stats[kX].step_at_max, 42u);  // the step, once known after the walk
}

TEST(CheckLockstep, AValueOutsideTheToleranceIsTheFirstDivergence) {
  const Walked w =
      walk(message(7, {{1.0, 1}, {2.5, 2}}, "run"), message(7, {{1.0, 1}, {2.0, 2}}, "run"), 1e-3);
  EXPECT_EQ(w.result.walk, rbsim::check::Walk::Ok);
  EXPECT_EQ(w.result.first_bad, 5u);  // step, t, length, x, id, then items[1].x
  EXPECT_EQ(w.result.bad_a.f, 2.5);
  EXPECT_EQ(w.result.bad_b.f, 2.0);
  EXPECT_EQ(rbsim::check::difference(w.result.bad_a, w.result.bad_b), "0.5");
  EXPECT_EQ(w.diverging, 1u);
  EXPECT_EQ(w.tally.stats[kX].over, 1u);
  EXPECT_EQ(w.tally.stats[kX].max_abs, 0.5);
}

TEST(CheckLockstep, IntegersAndStringsCompareExactly) {
  const Walked w = walk(message(7, {{1.0, 9}}, "mine"), message(7, {{1.0, 1}}, "gold"), 1.0);
  EXPECT_EQ(w.result.first_bad, 4u);  // items[0].id
  EXPECT_EQ(rbsim::check::difference(w.result.bad_a, w.result.bad_b), "8");
  EXPECT_EQ(w.diverging, 2u);  // the id and the name
  EXPECT_EQ(w.tally.stats[kName].over, 1u);
}

TEST(CheckLockstep, StopsAtDifferingSequenceLengthsAndAtBadData) {
  const Walked w = walk(message(7, {{1.0, 1}}), message(7, {{1.0, 1}, {2.0, 2}}));
  EXPECT_EQ(w.result.walk, rbsim::check::Walk::Mismatch);
  EXPECT_EQ(w.result.index, 2u);  // step and t compared; the lengths are left to the decoded pairing
  const rbsim::msgs::Bytes m = message(7, {{1.0, 1}});
  EXPECT_EQ(walk(std::vector(m.begin(), m.end() - 9), m).result.walk, rbsim::check::Walk::Malformed);
  rbsim::msgs::Bytes big_endian = m;
  big_endian[1] = std::byte{0};
  EXPECT_EQ(walk(big_endian, m).result.walk, rbsim::check::Walk::Malformed);
}

TEST(CheckLockstep, SurvivesEveryTruncationAndMutation) {
  const rbsim::msgs::Bytes good = message(7, {{1.0, 1}, {2.0, 2}, {3.0, 3}}, "name");
  for (std::size_t n = 0; n < good.size(); ++n) {
    const rbsim::msgs::Bytes cut(good.begin(), good.begin() + static_cast<std::ptrdiff_t>(n));
    EXPECT_NE(walk(cut, good).result.walk, rbsim::check::Walk::Ok) << "prefix " << n;
    EXPECT_NE(walk(good, cut).result.walk, rbsim::check::Walk::Ok) << "prefix " << n;
  }
  std::mt19937 rng(2024);
  for (int trial = 0; trial < 2000; ++trial) {
    rbsim::msgs::Bytes bad = good;
    bad[rng() % bad.size()] = static_cast<std::byte>(rng() & 0xFF);
    (void)walk(bad, good);  // any outcome; it must stay inside the data (the sanitizer stage checks)
    (void)walk(good, bad);
  }
}

TEST(CheckSteps, RunsOfStepsReadAsRanges) {
  StepRuns all;
  for (std::uint64_t s = 0; s < 1000; ++s) all.add(s);
  EXPECT_EQ(rbsim::check::step_runs_text(all), "0..999");
  StepRuns strided;
  for (std::uint64_t s = 5; s < 1000; s += 10) strided.add(s);
  EXPECT_EQ(rbsim::check::step_runs_text(strided), "5, 15, ..., 995");
  StepRuns three;
  for (std::uint64_t s : {5, 15, 25, 40}) three.add(s);
  EXPECT_EQ(rbsim::check::step_runs_text(three), "5, 15, 25, 40");
  StepRuns scattered;
  for (std::uint64_t s : {70, 60, 50, 40, 30, 20, 10}) scattered.add(s);
  EXPECT_EQ(rbsim::check::step_runs_text(scattered), "70, 60, 50, 40, 30, 20 and more");
  EXPECT_EQ(scattered.count, 7u);
}

TEST(CheckSteps, TracksKeepTheSmallestStride) {
  StepTrack t;
  for (std::uint64_t s : {0, 10, 20, 25, 35}) t.add(s);
  EXPECT_EQ(t.first, 0u);
  EXPECT_EQ(t.last, 35u);
  EXPECT_EQ(t.stride, 5u);
  EXPECT_EQ(t.messages, 5u);
}

TEST(CheckSentences, OnlySummaryNamesTheLikelyCause) {
  StepTrack run, golden;
  for (std::uint64_t s = 1000; s < 2000; ++s) run.add(s);
  for (std::uint64_t s = 0; s < 2000; ++s) golden.add(s);
  StepRuns lacks;
  for (std::uint64_t s = 0; s < 1000; ++s) lacks.add(s);
  EXPECT_EQ(rbsim::check::only_summary(lacks, true, run, golden),
            "run lacks steps 0..999 (1,000 messages: recorder joined late?)");

  StepTrack every5, every10;
  for (std::uint64_t s = 0; s <= 100; s += 5) every5.add(s);
  for (std::uint64_t s = 0; s <= 100; s += 10) every10.add(s);
  StepRuns extra;
  for (std::uint64_t s = 5; s <= 95; s += 10) extra.add(s);
  EXPECT_EQ(rbsim::check::only_summary(extra, false, every5, every10),
            "run has extra steps 5, 15, ..., 95 (10 messages: golden recorded every 10th step, run every 5th "
            "(--record-every))");

  StepTrack none;
  StepRuns one;
  one.add(3);
  EXPECT_EQ(rbsim::check::only_summary(one, false, golden, none),
            "run has extra steps 3 (1 message: the golden has none)");
}

TEST(CheckSentences, NumbersAndValues) {
  EXPECT_EQ(rbsim::check::ordinal(1), "1st");
  EXPECT_EQ(rbsim::check::ordinal(2), "2nd");
  EXPECT_EQ(rbsim::check::ordinal(3), "3rd");
  EXPECT_EQ(rbsim::check::ordinal(11), "11th");
  EXPECT_EQ(rbsim::check::ordinal(12), "12th");
  EXPECT_EQ(rbsim::check::ordinal(22), "22nd");
  EXPECT_EQ(rbsim::check::ordinal(113), "113th");
  Scalar f;
  f.kind = Scalar::Kind::Float;
  f.f = 0.1;
  EXPECT_EQ(rbsim::check::value_text(f), "0.1");
  EXPECT_EQ(rbsim::check::quoted(""), "(none)");
  EXPECT_EQ(rbsim::check::quoted("chain"), "'chain'");
  EXPECT_STREQ(rbsim::check::to_string(Scalar::Kind::Length), "length");
}

TEST(CheckSentences, TopicAndMessageDifferences) {
  using namespace rbsim::check;
  EXPECT_EQ(topic_only_in("golden", 12), "topic only in the golden (12 messages)");
  EXPECT_EQ(schema_differs("a/msg/B", ""), "schema differs: golden 'a/msg/B', run (none)");
  EXPECT_EQ(encoding_differs("cdr", "ros2msg", "json", "jsonschema"),
            "encoding differs: golden cdr/ros2msg, run json/jsonschema");
  EXPECT_EQ(fields_differ("a/msg/B"), "schema a/msg/B defines different fields in the two files");
  EXPECT_EQ(messages_left_over(true, 9, 10),
            "message missing from the run: the golden has 10 messages on this topic, the run 9");
  EXPECT_EQ(messages_left_over(false, 11, 10),
            "extra message in the run: the run has 11 messages on this topic, the golden 10");

  EXPECT_EQ(topic_difference("/t", schema_differs("a", "b")).line(),
            "topic /t: schema differs: golden 'a', run 'b'");
  EXPECT_EQ(topic_difference("", "whole file").line(), "whole file");
  FirstDifference missing = message_difference("/t", true, 5, message_in_one_file(true));
  EXPECT_EQ(missing.line(), "topic /t, step 5: message missing from the run");
  add_detail(missing, "run lacks steps 5..9 (5 messages)");
  EXPECT_EQ(missing.line(),
            "topic /t, step 5: message missing from the run: run lacks steps 5..9 (5 messages)");
  EXPECT_EQ(message_difference("/t", false, 3, message_in_one_file(false)).line(),
            "topic /t, message 3: extra message in the run");
  EXPECT_EQ(bytes_difference("/j", 2, 10, 12).line(),
            "topic /j, message 2, field (message bytes): expected 10 bytes, actual 12 bytes, difference "
            "bytes differ");
  EXPECT_EQ(log_time_difference("/t", true, 4, 1000, 1500).line(),
            "topic /t, step 4, field (log_time): expected 1000 ns, actual 1500 ns, difference 500 ns");
  const FirstDifference value{"/t", true, 200, "bodies[3].x", "1.5", "1.25", "-0.25"};
  EXPECT_EQ(value.line(),
            "topic /t, step 200, field bodies[3].x: expected 1.5, actual 1.25, difference -0.25");
  EXPECT_EQ(header_difference("library", "rbsim 1", "rbsim 2").line(),
            "MCAP header, library: expected \"rbsim 1\", actual \"rbsim 2\"");
}

TEST(CheckSentences, SceneDifferenceNamesTheStructureThatDiffers) {
  rbsim::msgs::SceneMessage golden, run;
  golden.name = "chain";
  run.name = "chain";
  golden.bodies.resize(2);
  run.bodies.resize(2);
  golden.springs.resize(1);
  run.springs.resize(1);
  golden.springs[0].body_i = 0;
  golden.springs[0].body_j = 1;
  run.springs[0].body_i = 0;
  run.springs[0].body_j = 1;
  EXPECT_EQ(rbsim::check::scene_difference(golden, run), "");
  run.springs[0].body_j = rbsim::kFixed;
  EXPECT_EQ(rbsim::check::scene_difference(golden, run),
            "spring 0 joins bodies 0-1 in the golden, 0-fixed in the run");
  run.bodies[1].hull.resize(3);
  EXPECT_EQ(rbsim::check::scene_difference(golden, run), "hull vertices of body 1: golden 0, run 3");
  run.bodies.resize(3);
  const std::string why = rbsim::check::scene_difference(golden, run);
  EXPECT_EQ(why, "bodies: golden 2, run 3");
  run.name = "";
  EXPECT_EQ(
      rbsim::check::different_scenes(golden, run, why),
      "the run and the golden record different scenes (golden 'chain', run (none)): bodies: golden 2, run 3");
}

}  // namespace
