// recordings::Recording, the one recording reader: typed steps from a recording made in-process, and
// recordings written message by message in the orders a live (DDS) recorder can produce.
#include "rbsim/recording.hpp"

#include <gtest/gtest.h>

#include <map>

#include "rbsim/scene.hpp"
#include "rbsim/subprocess.hpp"
#include "recordings_test_util.hpp"

namespace rbsim::test {
namespace {

namespace fs = std::filesystem;
using msgs::TopicId;

// One encoded message to write: topic, step it belongs to, log time.
struct Planned {
  TopicId topic;
  std::int64_t step;
  mcap::Timestamp log_time;
};

// Runs scenes/cantilever.xml (gravity and springs) and writes the planned messages, in the order
// given, under namespace `ns`; every message carries the world's state at its step. Without
// `summary_channels` the summary repeats no Schema or Channel record.
void write_recording(const fs::path& out, const std::vector<Planned>& plan, const std::string& ns = "rbsim",
                     const std::vector<TopicId>& topics = {TopicId::SceneDescription, TopicId::BodyStates,
                                                           TopicId::SpringStates, TopicId::Energy},
                     bool summary_channels = true) {
  Result<Scene> scene = load_scene(source_path("scenes/cantilever.xml"));
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  std::int64_t last = 0;
  for (const Planned& p : plan) last = std::max(last, p.step);
  // The encoded message of every topic at every step up to the last.
  std::map<std::pair<TopicId, std::int64_t>, msgs::Bytes> encoded;
  {
    Result<World> world = World::create(scene.value().world);
    ASSERT_TRUE(world.ok());
    const msgs::Encoder encoder(scene.value());
    while (true) {
      for (TopicId id : topics) encoder.encode(id, world.value(), encoded[{id, world.value().step_index()}]);
      if (world.value().step_index() >= last) break;
      world.value().step();
    }
  }
  mcap::Writer writer;
  mcap::WriterOptions wo = recordings::writer_options(mcap::Compression::None);
  wo.repeat_schemas = wo.repeat_channels = summary_channels;
  ASSERT_TRUE(writer.open(out.string(), wo).ok());
  std::map<TopicId, std::uint16_t> channel;
  for (TopicId id : topics) {
    auto c = recordings::add_topic(writer, msgs::topic(id), ns);
    ASSERT_TRUE(c.ok());
    channel[id] = c.value();
  }
  std::uint32_t sequence = 0;
  for (const Planned& p : plan) {
    const msgs::Bytes& b = encoded.at({p.topic, p.step});
    ASSERT_TRUE(writer.write_message(channel.at(p.topic), sequence++, p.log_time, p.log_time, b).ok());
  }
  ASSERT_TRUE(writer.close().ok());
}

struct Seen {
  std::uint64_t step;
  bool states, springs, energy;
};

std::vector<Seen> read_all(recordings::Recording& r) {
  std::vector<Seen> seen;
  const Status st = r.read_steps([&](const recordings::RecordedStep& s) -> Status {
    seen.push_back({s.step, s.body_states != nullptr, s.spring_states != nullptr, s.energy != nullptr});
    EXPECT_TRUE(s.body_states == nullptr || s.body_states->step == s.step);
    EXPECT_TRUE(s.spring_states == nullptr || s.spring_states->step == s.step);
    EXPECT_TRUE(s.energy == nullptr || s.energy->step == s.step);
    return Ok{};
  });
  EXPECT_TRUE(st.ok()) << st.error().message;
  return seen;
}

TEST(Recording, ReadStepsGivesTypedStepsOfAnInProcessRecording) {
  TempDir dir;
  const fs::path file = dir / "r.mcap";
  record_scene(source_path("scenes/cantilever.xml"), file, 40);
  auto opened = recordings::Recording::open(file.string(), {});
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  recordings::Recording& r = *opened.value();
  EXPECT_EQ(r.topic(TopicId::BodyStates), "/rbsim/body_states");
  EXPECT_EQ(r.topic(TopicId::Energy), "/rbsim/energy");
  ASSERT_NE(r.scene(), nullptr);

  Result<Scene> scene = load_scene(source_path("scenes/cantilever.xml"));
  ASSERT_TRUE(scene.ok());
  Result<World> world = World::create(scene.value().world);
  ASSERT_TRUE(world.ok());
  World& w = world.value();
  EXPECT_EQ(r.scene()->bodies.size(), static_cast<std::size_t>(w.body_count()));
  EXPECT_EQ(r.scene()->springs.size(), scene.value().world.springs.size());
  EXPECT_EQ(r.scene()->dt, w.dt());

  std::uint64_t steps = 0;
  const Status st = r.read_steps([&](const recordings::RecordedStep& s) -> Status {
    EXPECT_EQ(s.step, static_cast<std::uint64_t>(w.step_index()));
    if (s.body_states == nullptr || s.spring_states == nullptr || s.energy == nullptr) {
      return Error{"step " + std::to_string(s.step) + " incomplete"};
    }
    for (std::int32_t b = 0; b < w.body_count(); ++b) {
      const BodyState& got = s.body_states->bodies[static_cast<std::size_t>(b)].state;
      EXPECT_EQ(got.position.x(), w.x()[b]);
      EXPECT_EQ(got.position.y(), w.y()[b]);
      EXPECT_EQ(got.theta, w.theta()[b]);
      EXPECT_EQ(s.energy->bodies[static_cast<std::size_t>(b)].t_spin, w.quantities(BodyId{b}).t_spin);
    }
    EXPECT_EQ(s.spring_states->springs.size(), scene.value().world.springs.size());
    EXPECT_EQ(s.energy->kinetic_point, w.energy().t_point);
    EXPECT_EQ(s.log_time.body_states, msgs::sim_time_ns(w));
    ++steps;
    w.step();
    return Ok{};
  });
  ASSERT_TRUE(st.ok()) << st.error().message;
  EXPECT_EQ(steps, 41u);
}

TEST(Recording, OpenFindsASceneDescriptionRecordedAfterTheFirstBodyStates) {
  TempDir dir;
  const fs::path file = dir / "late-scene.mcap";
  // As a DDS recorder may log it: the latched scene description arrives after two steps.
  write_recording(file, {{TopicId::BodyStates, 0, 100},
                         {TopicId::SpringStates, 0, 101},
                         {TopicId::Energy, 0, 102},
                         {TopicId::BodyStates, 1, 200},
                         {TopicId::SpringStates, 1, 201},
                         {TopicId::Energy, 1, 202},
                         {TopicId::SceneDescription, 0, 250},
                         {TopicId::BodyStates, 2, 300},
                         {TopicId::SpringStates, 2, 301},
                         {TopicId::Energy, 2, 302}});
  auto opened = recordings::Recording::open(file.string(), {});
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  ASSERT_NE(opened.value()->scene(), nullptr);
  EXPECT_EQ(opened.value()->scene()->integrator, "symplectic-euler");
  const auto seen = read_all(*opened.value());
  ASSERT_EQ(seen.size(), 3u);
  for (std::size_t k = 0; k < seen.size(); ++k) {
    EXPECT_EQ(seen[k].step, k);
    EXPECT_TRUE(seen[k].states && seen[k].springs && seen[k].energy) << k;
  }
}

TEST(Recording, OpenLearnsChannelsTheSummaryDoesNotList) {
  TempDir dir;
  const fs::path file = dir / "no-summary-channels.mcap";
  write_recording(file,
                  {{TopicId::BodyStates, 0, 10},
                   {TopicId::SpringStates, 0, 11},
                   {TopicId::Energy, 0, 12},
                   {TopicId::SceneDescription, 0, 13},
                   {TopicId::BodyStates, 1, 20},
                   {TopicId::SpringStates, 1, 21},
                   {TopicId::Energy, 1, 22}},
                  "rbsim",
                  {TopicId::SceneDescription, TopicId::BodyStates, TopicId::SpringStates, TopicId::Energy},
                  /*summary_channels=*/false);
  auto opened = recordings::Recording::open(file.string(), {});
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  ASSERT_NE(opened.value()->scene(), nullptr);
  const auto seen = read_all(*opened.value());
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_TRUE(seen[1].states && seen[1].springs && seen[1].energy);
}

TEST(Recording, OpenWithoutASceneDescriptionIsAClearError) {
  TempDir dir;
  // The scene topic is there, with no message on it.
  const fs::path empty_scene = dir / "empty-scene.mcap";
  write_recording(empty_scene, {{TopicId::BodyStates, 0, 0}, {TopicId::Energy, 0, 0}});
  auto r = recordings::Recording::open(empty_scene.string(), {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message.rfind(empty_scene.string() + ": ", 0), 0u) << r.error().message;
  EXPECT_NE(r.error().message.find("no scene description recorded"), std::string::npos) << r.error().message;

  // No scene topic at all.
  const fs::path no_topic = dir / "no-scene-topic.mcap";
  write_recording(no_topic, {{TopicId::BodyStates, 0, 0}}, "rbsim", {TopicId::BodyStates});
  r = recordings::Recording::open(no_topic.string(), {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find(no_topic.string() + ": no rbsim_msgs/msg/SceneDescription topic"),
            std::string::npos)
      << r.error().message;

  // Without require_scene the steps are still read.
  recordings::RecordingOptions o;
  o.require_scene = false;
  auto lenient = recordings::Recording::open(no_topic.string(), o);
  ASSERT_TRUE(lenient.ok()) << lenient.error().message;
  EXPECT_EQ(lenient.value()->scene(), nullptr);
  EXPECT_EQ(read_all(*lenient.value()).size(), 1u);

  // A missing required per-step topic.
  o.require = {TopicId::Energy};
  auto required = recordings::Recording::open(no_topic.string(), o);
  ASSERT_FALSE(required.ok());
  EXPECT_NE(required.error().message.find("no rbsim_msgs/msg/EnergyTerms topic"), std::string::npos)
      << required.error().message;
}

TEST(Recording, ReadStepsJoinsInterleavedTopicsByStep) {
  TempDir dir;
  const fs::path file = dir / "interleaved.mcap";
  // Energy lags two steps behind body states, spring states one; the spring state of step 3 was
  // lost, and the recording ends before the energy of the last two steps.
  std::vector<Planned> plan = {{TopicId::SceneDescription, 0, 5}};
  for (std::int64_t k = 0; k < 8; ++k) {
    const auto t = static_cast<mcap::Timestamp>(10 * (k + 1));
    plan.push_back({TopicId::BodyStates, k, t});
    if (k >= 1 && k - 1 != 3) plan.push_back({TopicId::SpringStates, k - 1, t + 1});
    if (k >= 2) plan.push_back({TopicId::Energy, k - 2, t + 2});
  }
  plan.push_back({TopicId::SpringStates, 7, 200});
  write_recording(file, plan);
  auto opened = recordings::Recording::open(file.string(), {});
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  const auto seen = read_all(*opened.value());
  ASSERT_EQ(seen.size(), 8u);
  for (std::size_t k = 0; k < seen.size(); ++k) {
    EXPECT_EQ(seen[k].step, k);
    EXPECT_TRUE(seen[k].states) << k;
    EXPECT_EQ(seen[k].springs, k != 3) << k;
    EXPECT_EQ(seen[k].energy, k < 6) << k;
  }

  // Only the topics asked for are read and waited for.
  recordings::RecordingOptions o;
  o.read = {TopicId::Energy};
  auto energy_only = recordings::Recording::open(file.string(), o);
  ASSERT_TRUE(energy_only.ok()) << energy_only.error().message;
  const auto energy = read_all(*energy_only.value());
  ASSERT_EQ(energy.size(), 6u);
  for (const Seen& s : energy) EXPECT_TRUE(s.energy && !s.states && !s.springs);
}

TEST(Recording, ReadStepsRefusesARepeatedOrDecreasingStep) {
  TempDir dir;
  const fs::path file = dir / "repeat.mcap";
  write_recording(file, {{TopicId::SceneDescription, 0, 0},
                         {TopicId::BodyStates, 0, 0},
                         {TopicId::BodyStates, 1, 10},
                         {TopicId::BodyStates, 1, 20}});
  auto opened = recordings::Recording::open(file.string(), {});
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  const Status st =
      opened.value()->read_steps([](const recordings::RecordedStep&) -> Status { return Ok{}; });
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find(file.string() + ": message at log time"), std::string::npos)
      << st.error().message;
  EXPECT_NE(st.error().message.find("step 1 has two rbsim_msgs/msg/BodyStates messages"), std::string::npos)
      << st.error().message;
}

// Each scene description after the first starts an epoch at its step, so they cannot go back.
TEST(Recording, ReadStepsRefusesASceneDescriptionOfAnEarlierStep) {
  TempDir dir;
  const fs::path file = dir / "back.mcap";
  write_recording(file, {{TopicId::SceneDescription, 5, 0},
                         {TopicId::BodyStates, 5, 1},
                         {TopicId::SceneDescription, 3, 2},
                         {TopicId::BodyStates, 6, 3}});
  auto opened = recordings::Recording::open(file.string(), {});
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  const Status st =
      opened.value()->read_steps([](const recordings::RecordedStep&) -> Status { return Ok{}; });
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.error().message.find("a scene description of step 3 after one of step 5"), std::string::npos)
      << st.error().message;
}

TEST(Recording, OpenChoosesTheNamespaceAmongSeveralRecordings) {
  TempDir dir;
  const fs::path a = dir / "a.mcap";
  record_scene(source_path("scenes/chain.xml"), a, 3);
  // Two recordings in one file: copy a's messages under a second namespace.
  const fs::path both = dir / "both.mcap";
  {
    mcap::IndexedReader in;
    ASSERT_TRUE(in.open(a.string()).ok());
    mcap::Writer out;
    ASSERT_TRUE(out.open(both.string(), recordings::writer_options(mcap::Compression::None)).ok());
    std::map<std::uint16_t, std::uint16_t> other;
    for (const auto& [id, s] : in.schemas()) ASSERT_TRUE(out.add_schema(s).ok());
    for (const auto& [id, c] : in.channels()) {
      ASSERT_TRUE(out.add_channel(c).ok());
      mcap::Channel copy = c;
      copy.id = static_cast<std::uint16_t>(c.id + 100);
      const auto slash = c.topic.find('/', 1);  // "/rbsim/x" -> "/other/x"; "/clock" stays at the root
      copy.topic = slash == std::string::npos ? c.topic + "_other" : "/other" + c.topic.substr(slash);
      ASSERT_TRUE(out.add_channel(copy).ok());
      other[c.id] = copy.id;
    }
    ASSERT_TRUE(in.read_messages({}, [&](const mcap::MessageEntry& e) {
                    EXPECT_TRUE(out.write_message(e.message).ok());
                    mcap::Message m = e.message;
                    m.channel_id = other.at(m.channel_id);
                    EXPECT_TRUE(out.write_message(m).ok());
                    return true;
                  }).ok());
    ASSERT_TRUE(out.close().ok());
  }
  auto ambiguous = recordings::Recording::open(both.string(), {});
  ASSERT_FALSE(ambiguous.ok());
  EXPECT_NE(ambiguous.error().message.find("choose one recording with --namespace"), std::string::npos)
      << ambiguous.error().message;
  recordings::RecordingOptions o;
  o.ns = "other";
  auto chosen = recordings::Recording::open(both.string(), o);
  ASSERT_TRUE(chosen.ok()) << chosen.error().message;
  EXPECT_EQ(chosen.value()->topic(TopicId::BodyStates), "/other/body_states");
  EXPECT_EQ(read_all(*chosen.value()).size(), 4u);
}

TEST(Recording, OpenNamesTheFileOfAnUnreadableInput) {
  TempDir dir;
  const fs::path junk = dir / "junk.mcap";
  write_bytes(junk, bytes_of("not mcap"));
  auto r = recordings::Recording::open(junk.string(), {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().message.rfind(junk.string() + ": ", 0), 0u) << r.error().message;
  auto missing = recordings::Recording::open((dir / "missing.mcap").string(), {});
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("missing.mcap"), std::string::npos);
}

// Raw reading: every topic's messages as recorded, in log-time order whatever the file order,
// picked by topic and log-time window.
TEST(Recording, ReadMessagesGivesRawMessagesInLogTimeOrder) {
  TempDir dir;
  const fs::path file = dir / "shuffled.mcap";
  write_recording(file, {{TopicId::BodyStates, 0, 30},
                         {TopicId::SceneDescription, 0, 10},
                         {TopicId::SpringStates, 0, 20},
                         {TopicId::Energy, 0, 50},
                         {TopicId::BodyStates, 1, 40}});
  auto opened = recordings::Recording::open(file.string(), recordings::raw_options());
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  recordings::Recording& r = *opened.value();
  EXPECT_EQ(r.scene(), nullptr);
  std::vector<std::pair<mcap::Timestamp, std::string>> seen;
  const auto collect = [&](const recordings::RecordedMessage& m) {
    EXPECT_NE(m.channel->spec, nullptr);
    EXPECT_GE(m.cdr().size(), 4u);
    seen.emplace_back(m.message->log_time, m.topic());
    return true;
  };
  ASSERT_TRUE(r.read_messages({}, collect).ok());
  const std::vector<std::pair<mcap::Timestamp, std::string>> all = {{10, "/rbsim/scene"},
                                                                    {20, "/rbsim/spring_states"},
                                                                    {30, "/rbsim/body_states"},
                                                                    {40, "/rbsim/body_states"},
                                                                    {50, "/rbsim/energy"}};
  EXPECT_EQ(seen, all);
  seen.clear();
  ASSERT_TRUE(r.read_messages({{"/rbsim/body_states", "/rbsim/energy"}, 31, 60}, collect).ok());
  EXPECT_EQ(seen, (std::vector<std::pair<mcap::Timestamp, std::string>>{{40, "/rbsim/body_states"},
                                                                        {50, "/rbsim/energy"}}));
  seen.clear();
  ASSERT_TRUE(r.read_messages({}, [&](const recordings::RecordedMessage& m) {
                 seen.emplace_back(m.message->log_time, m.topic());
                 return seen.size() < 2;  // false stops the read, without an error
               }).ok());
  EXPECT_EQ(seen.size(), 2u);
  EXPECT_EQ(r.last_log_time(), std::optional<mcap::Timestamp>(50));
}

// channels() lists channels of any type; a raw reader opens a file of none of ours, which a
// reader of steps refuses.
TEST(Recording, ChannelsListsTopicsOfOtherTypes) {
  TempDir dir;
  const fs::path file = dir / "foreign.mcap";
  {
    mcap::Writer w;
    ASSERT_TRUE(w.open(file.string(), recordings::writer_options(mcap::Compression::None)).ok());
    const std::string text = "int32 x\n";
    ASSERT_TRUE(w.add_schema({1, "other_msgs/msg/Thing", "ros2msg", bytes_of(text)}).ok());
    ASSERT_TRUE(w.add_channel({1, 1, "/thing", "cdr", {}}).ok());
    const mcap::Bytes cdr = bytes({0, 1, 0, 0, 7, 0, 0, 0});
    for (std::uint32_t k = 0; k < 3; ++k) ASSERT_TRUE(w.write_message(1, k, 100 + k, 100 + k, cdr).ok());
    ASSERT_TRUE(w.close().ok());
  }
  auto steps = recordings::Recording::open(file.string(), {});
  ASSERT_FALSE(steps.ok());
  EXPECT_NE(steps.error().message.find("no rbsim_msgs/msg/SceneDescription topic"), std::string::npos)
      << steps.error().message;
  auto opened = recordings::Recording::open(file.string(), recordings::raw_options());
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  const auto& channels = opened.value()->channels();
  ASSERT_EQ(channels.size(), 1u);
  EXPECT_EQ(channels[0].spec, nullptr);
  EXPECT_EQ(channels[0].channel->topic, "/thing");
  EXPECT_EQ(channels[0].schema_text(), "int32 x\n");
  EXPECT_EQ(channels[0].message_count, std::optional<std::uint64_t>(3));
  EXPECT_TRUE(opened.value()->lists_every_channel());
  int messages = 0;
  ASSERT_TRUE(opened.value()
                  ->read_messages({},
                                  [&](const recordings::RecordedMessage& m) {
                                    EXPECT_EQ(m.cdr()[4], std::byte{7});
                                    ++messages;
                                    return true;
                                  })
                  .ok());
  EXPECT_EQ(messages, 3);
}

// read_steps() with other topics beside: one pass gives the joined steps and those topics' raw
// messages, each in its order.
TEST(Recording, ReadStepsPassesOtherTopicsInTheSamePass) {
  TempDir dir;
  const fs::path file = dir / "chain.mcap";
  record_scene(source_path("scenes/chain.xml"), file, 5);
  auto opened = recordings::Recording::open(file.string(), {});
  ASSERT_TRUE(opened.ok()) << opened.error().message;
  recordings::Recording& r = *opened.value();
  std::vector<std::uint64_t> steps;
  std::vector<std::string> raw;
  const recordings::MessageFilter also{{"/tf", r.topic(TopicId::SceneDescription)}};
  const Status st = r.read_steps(
      [&](const recordings::RecordedStep& s) -> Status {
        steps.push_back(s.step);
        return Ok{};
      },
      also,
      [&](const recordings::RecordedMessage& m) {
        EXPECT_EQ(m.channel->spec,
                  &msgs::topic(m.topic() == "/tf" ? TopicId::Tf : TopicId::SceneDescription));
        raw.push_back(m.topic());
        return true;
      });
  ASSERT_TRUE(st.ok()) << st.error().message;
  EXPECT_EQ(steps, (std::vector<std::uint64_t>{0, 1, 2, 3, 4, 5}));
  EXPECT_EQ(std::count(raw.begin(), raw.end(), "/tf"), 6);
  EXPECT_EQ(std::count(raw.begin(), raw.end(), "/rbsim/scene"), 1);
  // Stopping from the raw side ends the pass without an error and passes no more steps.
  steps.clear();
  ASSERT_TRUE(r.read_steps(
                   [&](const recordings::RecordedStep& s) -> Status {
                     steps.push_back(s.step);
                     return Ok{};
                   },
                   also, [](const recordings::RecordedMessage&) { return false; })
                  .ok());
  EXPECT_LT(steps.size(), 6u);
}

}  // namespace
}  // namespace rbsim::test
