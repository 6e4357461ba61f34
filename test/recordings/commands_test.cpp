// recordings::read_commands: a steered run's commands (rbsim_msgs/msg/Command on /<ns>/commands) read back
// in sequence order, each once, and a recording that lost one refused with the number it lacks.
#include <gtest/gtest.h>

#include "rbsim/mcap_sink.hpp"
#include "rbsim/recording.hpp"
#include "rbsim/run.hpp"
#include "rbsim/scene.hpp"
#include "rbsim/subprocess.hpp"
#include "recordings_test_util.hpp"

namespace rbsim::test {
namespace {

namespace fs = std::filesystem;

// Records 20 steps of scenes/cantilever.xml with the MCAP sink, and after step 5 the commands
// numbered `seqs` (in that order), each at step 5 + its number.
void record_with_commands(const fs::path& out, const std::vector<std::uint64_t>& seqs) {
  Result<Scene> scene = load_scene(source_path("scenes/cantilever.xml"));
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  Result<World> world = World::create(scene.value().world);
  ASSERT_TRUE(world.ok());
  std::unique_ptr<recordings::McapSink> sink = recordings::make_mcap_sink(out.string());
  ASSERT_TRUE(sink->begin(scene.value(), world.value()).ok());
  for (int i = 0; i < 20; ++i) {
    world.value().step();
    ASSERT_TRUE(sink->write(world.value()).ok());
    if (i != 5) continue;
    for (std::uint64_t seq : seqs) {
      msgs::CommandMessage c;
      c.seq = seq;
      c.step = 5 + seq;
      c.kind = msgs::CommandMessage::Pause;
      c.source = "test";
      c.success = true;
      msgs::Bytes cdr;
      msgs::encode(c, cdr);
      ASSERT_TRUE(sink->record_command(cdr, static_cast<std::int64_t>(c.step)).ok());
    }
  }
  ASSERT_TRUE(sink->finish().ok());
}

Result<std::vector<msgs::CommandMessage>> commands_of(const fs::path& path) {
  Result<std::unique_ptr<recordings::Recording>> r = recordings::Recording::open(path.string());
  if (!r) return r.error();
  return recordings::read_commands(*r.value());
}

TEST(ReadCommands, InSequenceOrderEachOnce) {
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(record_with_commands(dir / "a.mcap", {1, 0, 1, 2}));
  Result<std::vector<msgs::CommandMessage>> got = commands_of(dir / "a.mcap");
  ASSERT_TRUE(got) << got.error().message;
  ASSERT_EQ(got->size(), 3u);
  for (std::uint64_t i = 0; i < 3; ++i) {
    EXPECT_EQ((*got)[i].seq, i);
    EXPECT_EQ((*got)[i].step, 5 + i);
    EXPECT_EQ((*got)[i].source, "test");
  }
}

TEST(ReadCommands, AMissingCommandIsAnErrorNamingIt) {
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(record_with_commands(dir / "gap.mcap", {0, 2, 3}));
  Result<std::vector<msgs::CommandMessage>> got = commands_of(dir / "gap.mcap");
  ASSERT_FALSE(got);
  EXPECT_NE(got.error().message.find("/rbsim/commands: command 1 is missing"), std::string::npos)
      << got.error().message;
  ASSERT_NO_FATAL_FAILURE(record_with_commands(dir / "late.mcap", {4, 5}));
  got = commands_of(dir / "late.mcap");
  ASSERT_FALSE(got);
  EXPECT_NE(got.error().message.find("command 0 is missing"), std::string::npos) << got.error().message;
}

TEST(ReadCommands, NoneWithoutTheTopic) {
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(record_with_commands(dir / "none.mcap", {}));
  Result<std::vector<msgs::CommandMessage>> got = commands_of(dir / "none.mcap");
  ASSERT_TRUE(got) << got.error().message;
  EXPECT_TRUE(got->empty());
}

// rbsim run --commands REC.mcap: a steered run re-run from its own recording gives the same file,
// byte for byte; a recording that lost a command is refused before any output.
TEST(RunCommands, ARecordingRerunsToTheSameBytes) {
  TempDir dir;
  const std::string scene = source_path("scenes/chain.xml");
  write_text(dir / "c.yaml",
             "- {step: 20, set: {forces.0.fy: -3.7}}\n- {step: 30, pause: true}\n- {step: 30, steps: 4}\n"
             "- {step: 34, impulse: {body: 2, j: [0.5, 2.0], p: [0.1, 0.0]}}\n- {step: 34, resume: true}\n");
  const Outcome a = rbsim({"run", scene, "--steps", "100", "--commands", (dir / "c.yaml").string(),
                           "--record", (dir / "a.mcap").string()});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  const Outcome b = rbsim({"run", scene, "--steps", "100", "--commands", (dir / "a.mcap").string(),
                           "--record", (dir / "b.mcap").string()});
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(read_bytes(dir / "a.mcap"), read_bytes(dir / "b.mcap"));
  Result<std::vector<msgs::CommandMessage>> got = commands_of(dir / "b.mcap");
  ASSERT_TRUE(got) << got.error().message;
  ASSERT_EQ(got->size(), 5u);
  EXPECT_EQ((*got)[3].step, 34u);
  EXPECT_EQ((*got)[3].source, "script " + (dir / "c.yaml").string() + ":4");

  ASSERT_NO_FATAL_FAILURE(record_with_commands(dir / "gap.mcap", {0, 2}));
  const Outcome gap = rbsim({"run", source_path("scenes/cantilever.xml"), "--commands",
                             (dir / "gap.mcap").string(), "--csv", (dir / "out.csv").string()});
  EXPECT_EQ(gap.exit_code, 1) << gap.err;
  EXPECT_NE(gap.err.find("command 1 is missing"), std::string::npos) << gap.err;
  EXPECT_FALSE(fs::exists(dir / "out.csv"));
}

// A recording whose last command left the session paused ends the re-run there, not idling.
TEST(RunCommands, ARecordingThatEndsPausedEndsTheRerunThere) {
  TempDir dir;
  ASSERT_NO_FATAL_FAILURE(record_with_commands(dir / "paused.mcap", {0}));  // pause at step 5
  const Outcome o = rbsim({"run", source_path("scenes/cantilever.xml"), "--commands",
                           (dir / "paused.mcap").string(), "--csv", (dir / "out.csv").string()});
  EXPECT_EQ(o.exit_code, 0) << o.err;
  EXPECT_NE(o.err.find("left the run paused at step 5"), std::string::npos) << o.err;
  EXPECT_EQ(lines_of(read_text(dir / "out.csv")).size(), 1 + 6u * 5);  // the header, steps 0..5 of 5 bodies
  // A command for a later step is never reached while paused: the re-run still ends there, and
  // says that command did not apply.
  ASSERT_NO_FATAL_FAILURE(record_with_commands(dir / "later.mcap", {0, 1}));  // pauses at 5 and 6
  const Outcome later = rbsim({"run", source_path("scenes/cantilever.xml"), "--commands",
                               (dir / "later.mcap").string(), "--csv", (dir / "later.csv").string()});
  EXPECT_EQ(later.exit_code, 1) << later.err;
  EXPECT_NE(later.err.find("left the run paused at step 5"), std::string::npos) << later.err;
  EXPECT_NE(later.err.find("1 of its commands never applied"), std::string::npos) << later.err;
}

// A session that loaded another world (simulation_interfaces' LoadWorld: a load_world command
// carrying the scene's text) re-runs from its recording to the same bytes, with no scene file:
// the recording holds both worlds, the second from its own step 0, and rbsim check finds them
// equal. Outputs that cannot hold a second world are refused before step 0.
TEST(RunCommands, AWorldLoadedInTheSessionRerunsToTheSameBytes) {
  TempDir dir;
  const std::string scene = source_path("scenes/chain.xml");
  const fs::path other = dir / "other.xml";
  // The cantilever, 0.05 s long.
  std::string text = read_text(source_path("scenes/cantilever.xml"));
  const std::size_t at = text.find("<duration");
  ASSERT_NE(at, std::string::npos);
  text.replace(at, text.find("/>", at) + 2 - at, "<duration time=\"0.05\"/>");
  write_text(other, text);
  // The session's commands as the node numbers them: the other world at step 6, played there.
  {
    Result<Scene> s = load_scene(scene);
    ASSERT_TRUE(s.ok()) << s.error().message;
    Result<World> world = World::create(s.value().world);
    ASSERT_TRUE(world.ok());
    std::unique_ptr<recordings::McapSink> sink = recordings::make_mcap_sink((dir / "cmds.mcap").string());
    ASSERT_TRUE(sink->begin(s.value(), world.value()).ok());
    msgs::CommandMessage load;
    load.seq = 0;
    load.step = 6;
    load.kind = msgs::CommandMessage::LoadWorld;
    load.parameters = {{"resource", msgs::ParameterValue::of_string(read_text(other))},
                       {"uri", msgs::ParameterValue::of_string("other.xml")}};
    load.success = true;
    msgs::CommandMessage play;
    play.seq = 1;
    play.kind = msgs::CommandMessage::Resume;
    play.success = true;
    for (const msgs::CommandMessage& c : {load, play}) {
      msgs::Bytes cdr;
      msgs::encode(c, cdr);
      ASSERT_TRUE(sink->record_command(cdr, static_cast<std::int64_t>(c.step)).ok());
    }
    ASSERT_TRUE(sink->finish().ok());
  }
  const Outcome a = rbsim({"run", scene, "--steps", "40", "--commands", (dir / "cmds.mcap").string(),
                           "--record", (dir / "a.mcap").string()});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  fs::remove(other);
  const Outcome b = rbsim({"run", scene, "--steps", "40", "--commands", (dir / "a.mcap").string(), "--record",
                           (dir / "b.mcap").string()});
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(read_bytes(dir / "a.mcap"), read_bytes(dir / "b.mcap"));
  const Outcome check = rbsim({"check", (dir / "a.mcap").string(), (dir / "b.mcap").string()});
  EXPECT_EQ(check.exit_code, 0) << check.out << check.err;
  // The recording holds two scene descriptions: the chain's, then the other world's at its step 0.
  Result<std::unique_ptr<recordings::Recording>> rec = recordings::Recording::open((dir / "a.mcap").string());
  ASSERT_TRUE(rec.ok()) << rec.error().message;
  std::vector<std::string> names;
  recordings::MessageFilter scenes;
  scenes.topics = {rec.value()->topic(msgs::TopicId::SceneDescription)};
  ASSERT_TRUE(rec.value()
                  ->read_messages(scenes,
                                  [&](const recordings::RecordedMessage& m) {
                                    Result<msgs::SceneMessage> d = msgs::decode_scene(m.cdr());
                                    if (d) names.push_back(d.value().name);
                                    return true;
                                  })
                  .ok());
  EXPECT_EQ(names, (std::vector<std::string>{"chain", "other"}));
  // Read step by step: the chain's steps 0..6 (segment 0), then the other world's 0..50 (segment
  // 1), each with its own scene description; log times never go back.
  std::vector<std::string> seen;
  mcap::Timestamp last_log = 0;
  bool monotonic = true;
  ASSERT_TRUE(rec.value()
                  ->read_steps([&](const recordings::RecordedStep& st) {
                    seen.push_back(std::to_string(st.segment) + ":" + std::to_string(st.step) + ":" +
                                   st.scene->name + ":" + std::to_string(st.body_states->bodies.size()));
                    monotonic &= st.log_time.body_states >= last_log;
                    last_log = st.log_time.body_states;
                    return Status(Ok{});
                  })
                  .ok());
  EXPECT_TRUE(monotonic);
  ASSERT_EQ(seen.size(), 7u + 51u);
  EXPECT_EQ(seen[0], "0:0:chain:" + std::to_string(rec.value()->scene()->bodies.size()));
  EXPECT_EQ(seen[6].substr(0, 10), "0:6:chain:");
  EXPECT_EQ(seen[7].substr(0, 10), "1:0:other:");
  EXPECT_EQ(seen.back().substr(0, 11), "1:50:other:");
  const Outcome exported =
      rbsim({"log", "export", (dir / "a.mcap").string(), "--csv", (dir / "a.csv").string()});
  EXPECT_EQ(exported.exit_code, 0) << exported.err;
  const Outcome csv = rbsim({"run", scene, "--steps", "40", "--commands", (dir / "a.mcap").string(), "--csv",
                             (dir / "out.csv").string()});
  EXPECT_EQ(csv.exit_code, 2) << csv.err;
  EXPECT_NE(csv.err.find("cannot follow a world loaded during the run"), std::string::npos) << csv.err;
  EXPECT_FALSE(fs::exists(dir / "out.csv"));
}

// A reset is recorded as a restart: the scene description and step 0 again, then the steps from 1,
// so the recording reads as two segments, each from step 0, and re-runs to the same bytes.
TEST(RunCommands, AResetStartsTheRecordingsNextSegment) {
  TempDir dir;
  const std::string scene = source_path("scenes/chain.xml");
  write_text(dir / "c.yaml", "- {step: 12, reset: true}\n");
  const Outcome a = rbsim({"run", scene, "--steps", "20", "--commands", (dir / "c.yaml").string(), "--record",
                           (dir / "a.mcap").string()});
  ASSERT_EQ(a.exit_code, 0) << a.err;
  Result<std::unique_ptr<recordings::Recording>> rec = recordings::Recording::open((dir / "a.mcap").string());
  ASSERT_TRUE(rec.ok()) << rec.error().message;
  std::vector<std::pair<std::uint32_t, std::uint64_t>> seen;
  ASSERT_TRUE(rec.value()
                  ->read_steps([&](const recordings::RecordedStep& st) {
                    seen.emplace_back(st.segment, st.step);
                    return Status(Ok{});
                  })
                  .ok());
  std::vector<std::pair<std::uint32_t, std::uint64_t>> want;
  for (std::uint64_t k = 0; k <= 12; ++k) want.emplace_back(0, k);
  for (std::uint64_t k = 0; k <= 20; ++k) want.emplace_back(1, k);
  EXPECT_EQ(seen, want);
  const Outcome b = rbsim({"run", scene, "--steps", "20", "--commands", (dir / "a.mcap").string(), "--record",
                           (dir / "b.mcap").string()});
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_EQ(read_bytes(dir / "a.mcap"), read_bytes(dir / "b.mcap"));
}

}  // namespace
}  // namespace rbsim::test
