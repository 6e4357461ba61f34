// Pictures that would be wrong if a body, a colour, the viewport or the frame timing were.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <png.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "rbsim/mcap.hpp"
#include "rbsim/render.hpp"

extern char** environ;

namespace fs = std::filesystem;

namespace {

struct Image {
  int width = 0, height = 0;
  std::vector<unsigned char> rgb;
  std::array<int, 3> at(int x, int y) const {
    const std::size_t i = 3 * (static_cast<std::size_t>(y) * width + x);
    return {rgb[i], rgb[i + 1], rgb[i + 2]};
  }
};

Image read_png(const fs::path& path) {
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  Image out;
  if (!png_image_begin_read_from_file(&image, path.c_str())) return out;
  image.format = PNG_FORMAT_RGB;
  out.rgb.resize(PNG_IMAGE_SIZE(image));
  if (!png_image_finish_read(&image, nullptr, out.rgb.data(), 0, nullptr)) return Image{};
  out.width = static_cast<int>(image.width);
  out.height = static_cast<int>(image.height);
  return out;
}

fs::path temp_dir(const std::string& name) {
  const fs::path d =
      fs::path(testing::TempDir()) / ("rbsim_render_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

// One 2 x 2 red square (r = 0.1) at the origin on a blue background, viewport half-size 2.
const char* kSquareScene = R"(<scene>
  <simtype type="rigid-body"/>
  <duration time="1.0"/>
  <viewport cx="0.0" cy="0.0" size="2.0"/>
  <backgroundcolor r="0.0" g="0.0" b="1.0"/>
  <rigidbodyintegrator type="symplectic-euler" dt="0.01"/>
  <rigidbodyvertex x="-1" y="-1" m="1"/>
  <rigidbodyvertex x="-1" y="1" m="1"/>
  <rigidbodyvertex x="1" y="1" m="1"/>
  <rigidbodyvertex x="1" y="-1" m="1"/>
  <rigidbody p="0" p="1" p="2" p="3" vx="0.0" vy="0.0" omega="0.0" r="0.1"/>
  <rigidbodycolor body="0" r="1.0" g="0.0" b="0.0"/>
</scene>
)";

fs::path write_scene(const fs::path& dir, const std::string& text) {
  fs::create_directories(dir);
  const fs::path p = dir / "scene.xml";
  std::ofstream(p) << text;
  return p;
}

int run(const std::vector<std::string>& args, std::string* err = nullptr) {
  std::vector<char*> argv;
  for (const auto& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  const fs::path err_file = fs::path(testing::TempDir()) / ("rbsim_render_err_" + std::to_string(::getpid()));
  posix_spawn_file_actions_t fa;
  posix_spawn_file_actions_init(&fa);
  posix_spawn_file_actions_addopen(&fa, 2, err_file.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  if (posix_spawn(&pid, argv[0], &fa, nullptr, argv.data(), environ) != 0) return -1;
  posix_spawn_file_actions_destroy(&fa);
  int status = 0;
  waitpid(pid, &status, 0);
  if (err != nullptr) {
    std::ifstream in(err_file);
    err->assign(std::istreambuf_iterator<char>(in), {});
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(Render, BodyCentreHasItsColourAndOutsideIsBackground) {
  const fs::path dir = temp_dir("pixels");
  const fs::path scene = write_scene(dir, kSquareScene);
  rbsim::render::RenderOptions o;
  o.out_dir = (dir / "frames").string();
  o.width = 200;
  o.height = 200;
  o.fps = 10;
  auto frames = rbsim::render::render(scene.string(), o);
  ASSERT_TRUE(frames.ok()) << frames.error().message;
  const Image img = read_png(dir / "frames" / "frame00000.png");
  ASSERT_EQ(img.width, 200);
  ASSERT_EQ(img.height, 200);
  // 200 px span 2 * size = 4 units: 50 px per unit, the square covers pixels 50..150 (+5 for r).
  EXPECT_EQ(img.at(100, 100), (std::array<int, 3>{255, 0, 0}));
  EXPECT_EQ(img.at(60, 140), (std::array<int, 3>{255, 0, 0}));
  EXPECT_EQ(img.at(152, 100), (std::array<int, 3>{255, 0, 0}));  // inside the radius band
  EXPECT_EQ(img.at(190, 190), (std::array<int, 3>{0, 0, 255}));
  EXPECT_EQ(img.at(160, 100), (std::array<int, 3>{0, 0, 255}));  // beyond hull + r
}

TEST(Render, FrameCountIsDurationTimesFps) {
  const fs::path dir = temp_dir("count");
  const fs::path scene = write_scene(dir, kSquareScene);
  for (double fps : {24.0, 10.0, 7.0}) {
    rbsim::render::RenderOptions o;
    o.out_dir = (dir / ("f" + std::to_string(static_cast<int>(fps)))).string();
    o.width = 64;
    o.height = 48;
    o.fps = fps;
    o.duration = 2.0;
    auto frames = rbsim::render::render(scene.string(), o);
    ASSERT_TRUE(frames.ok()) << frames.error().message;
    EXPECT_EQ(frames.value(), static_cast<std::int64_t>(2.0 * fps));
    std::int64_t files = 0;
    for (const auto& e : fs::directory_iterator(o.out_dir)) files += e.path().extension() == ".png";
    EXPECT_EQ(files, static_cast<std::int64_t>(2.0 * fps));
  }
}

TEST(Render, McapDrivenEqualsSceneDrivenPixelForPixel) {
  const fs::path dir = temp_dir("mcap");
  const std::string scene = std::string(RBSIM_SOURCE_DIR) + "/scenes/creative/wind-garden.xml";
  const fs::path log = dir / "run.mcap";
  fs::create_directories(dir);
  ASSERT_EQ(run({RBSIM_BINARY, "run", scene, "--duration", "1.5", "--record", log.string(), "-q"}), 0);
  rbsim::render::RenderOptions o;
  o.width = 320;
  o.height = 180;
  o.duration = 1.5;
  o.out_dir = (dir / "from_scene").string();
  auto a = rbsim::render::render(scene, o);
  ASSERT_TRUE(a.ok()) << a.error().message;
  o.out_dir = (dir / "from_log").string();
  auto b = rbsim::render::render(log.string(), o);
  ASSERT_TRUE(b.ok()) << b.error().message;
  ASSERT_EQ(a.value(), b.value());
  ASSERT_EQ(a.value(), 36);
  int differing_frames = 0;
  for (std::int64_t k = 0; k < a.value(); ++k) {
    char name[32];
    std::snprintf(name, sizeof name, "frame%05lld.png", static_cast<long long>(k));
    const Image x = read_png(dir / "from_scene" / name), y = read_png(dir / "from_log" / name);
    ASSERT_FALSE(x.rgb.empty());
    differing_frames += x.rgb != y.rgb;
  }
  EXPECT_EQ(differing_frames, 0);
  // and the frames do change over time (a moving scene)
  EXPECT_NE(read_png(dir / "from_scene" / "frame00000.png").rgb,
            read_png(dir / "from_scene" / "frame00035.png").rgb);
}

std::int64_t frame_files(const fs::path& dir) {
  std::int64_t n = 0;
  for (const auto& e : fs::directory_iterator(dir))
    n += rbsim::render::is_frame_file(e.path().filename().string());
  return n;
}

// The frames a movie holds, counted by decoding it (ffprobe -count_frames); -1 when unreadable.
std::int64_t movie_frames(const fs::path& mp4) {
  const std::string cmd =
      "ffprobe -v error -select_streams v:0 -count_frames -show_entries "
      "stream=nb_read_frames -of csv=p=0 '" +
      mp4.string() + "'";
  std::FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) return -1;
  char buf[64] = {};
  const bool got = std::fgets(buf, sizeof buf, p) != nullptr;
  if (::pclose(p) != 0 || !got) return -1;
  return std::atoll(buf);
}

// One rule: T x fps frames for T simulated seconds, whether drawn from the scene, from a recording
// of its run, or during the run (rbsim run --frames); for the scene's own duration and for another.
TEST(RenderCli, FrameCountIsTheSameFromSceneRecordingAndRun) {
  const fs::path dir = temp_dir("samecount");
  // dt 0.01 does not divide the duration 1.005: the full-length run has ceil(100.5) = 101 steps.
  std::string text = kSquareScene;
  text.replace(text.find("time=\"1.0\""), 10, "time=\"1.005\"");
  const fs::path scene = write_scene(dir, text);
  struct Case {
    std::string name;
    std::vector<std::string> duration;  // empty: the scene's
    double fps;
    std::int64_t expected;
  };
  for (const Case& c :
       {Case{"full24", {}, 24.0, 24}, Case{"two24", {"--duration", "2"}, 24.0, 48},
        Case{"two7", {"--duration", "2"}, 7.0, 14}, Case{"half10", {"--duration", "0.5"}, 10.0, 5}}) {
    SCOPED_TRACE(c.name);
    const std::string fps = std::to_string(c.fps);
    const fs::path log = dir / (c.name + ".mcap"), during = dir / (c.name + "_run");
    std::vector<std::string> args = {RBSIM_BINARY, "run",        scene.string(), "-q",
                                     "--record",   log.string(), "--frames",     during.string(),
                                     "--fps",      fps,          "--size",       "64x48"};
    args.insert(args.end(), c.duration.begin(), c.duration.end());
    std::string err;
    ASSERT_EQ(run(args, &err), 0) << err;
    EXPECT_EQ(frame_files(during), c.expected) << "rbsim run --frames";
    for (const fs::path& input : {scene, log}) {
      const fs::path out = dir / (c.name + "_" + input.extension().string().substr(1));
      std::vector<std::string> r = {RBSIM_BINARY, "render", input.string(), "--out", out.string(),
                                    "--fps",      fps,      "--size",       "64x48"};
      r.insert(r.end(), c.duration.begin(), c.duration.end());
      ASSERT_EQ(run(r, &err), 0) << err;
      EXPECT_EQ(frame_files(out), c.expected) << "rbsim render " << input;
      EXPECT_NE(err.find(" " + std::to_string(c.expected) + " frames "), std::string::npos) << err;
    }
  }
}

// A second, shorter render into the same folder: refused unless --overwrite, which removes the old
// frames (and nothing else) first; the movie holds this render's frames only.
TEST(RenderCli, MovieHoldsOnlyThisRendersFrames) {
  const fs::path dir = temp_dir("movie");
  const fs::path scene = write_scene(dir, kSquareScene);
  const fs::path frames = dir / "frames";
  fs::create_directories(frames);
  std::ofstream(frames / "notes.txt") << "mine";
  std::ofstream(frames / "frame_cover.png") << "mine too";
  std::string err;
  const std::vector<std::string> common = {RBSIM_BINARY,    "render", scene.string(), "--out",
                                           frames.string(), "--size", "64x48"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> args = common;
    args.insert(args.end(), extra.begin(), extra.end());
    return args;
  };
  ASSERT_EQ(run(with({"--duration", "0.5", "--mp4", (dir / "a.mp4").string()}), &err), 0) << err;
  EXPECT_EQ(frame_files(frames), 12);
  EXPECT_EQ(movie_frames(dir / "a.mp4"), 12);

  // the folder holds a render's frames: refused, nothing touched
  EXPECT_EQ(run(with({"--duration", "0.25", "--mp4", (dir / "w.mp4").string()}), &err), 1);
  EXPECT_NE(err.find("--overwrite"), std::string::npos) << err;
  EXPECT_EQ(frame_files(frames), 12);
  EXPECT_FALSE(fs::exists(dir / "w.mp4"));
  // an existing movie: refused too
  EXPECT_EQ(run(with({"--duration", "0.25", "--mp4", (dir / "a.mp4").string()}), &err), 1);
  EXPECT_NE(err.find("--overwrite"), std::string::npos) << err;
  EXPECT_EQ(movie_frames(dir / "a.mp4"), 12);

  ASSERT_EQ(run(with({"--duration", "0.25", "--mp4", (dir / "w.mp4").string(), "--overwrite"}), &err), 0)
      << err;
  EXPECT_NE(err.find(" 6 frames "), std::string::npos) << err;
  EXPECT_EQ(frame_files(frames), 6);
  EXPECT_FALSE(fs::exists(frames / "frame00006.png"));
  EXPECT_EQ(movie_frames(dir / "w.mp4"), 6);
  EXPECT_TRUE(fs::exists(frames / "notes.txt"));
  EXPECT_TRUE(fs::exists(frames / "frame_cover.png"));

  // rbsim run --frames follows the same rule
  EXPECT_EQ(run({RBSIM_BINARY, "run", scene.string(), "-q", "--duration", "0.1", "--frames", frames.string(),
                 "--size", "64x48"},
                &err),
            1);
  EXPECT_NE(err.find("--overwrite"), std::string::npos) << err;
  EXPECT_EQ(run({RBSIM_BINARY, "run", scene.string(), "-q", "--duration", "0.1", "--frames", frames.string(),
                 "--size", "64x48", "--overwrite"},
                &err),
            0)
      << err;
  EXPECT_EQ(frame_files(frames), 2);  // 0.1 s at 24 fps: frames at 0 and 1/24 s
  EXPECT_TRUE(fs::exists(frames / "notes.txt"));
}

TEST(Plot, WritesAPngOfTheRequestedSize) {
  const fs::path dir = temp_dir("plot");
  fs::create_directories(dir);
  const std::string scene = std::string(RBSIM_SOURCE_DIR) + "/scenes/cantilever.xml";
  ASSERT_EQ(run({RBSIM_BINARY, "plot", scene, "--out", (dir / "p.png").string(), "--size", "640x480",
                 "--duration", "2"}),
            0);
  const Image img = read_png(dir / "p.png");
  EXPECT_EQ(img.width, 640);
  EXPECT_EQ(img.height, 480);
  // from a recording too
  const fs::path log = dir / "run.mcap";
  ASSERT_EQ(run({RBSIM_BINARY, "run", scene, "--steps", "500", "--record", log.string(), "-q"}), 0);
  ASSERT_EQ(run({RBSIM_BINARY, "plot", log.string(), "--out", (dir / "q.png").string(), "--size", "800x600"}),
            0);
  EXPECT_EQ(read_png(dir / "q.png").width, 800);
}

TEST(RenderCli, BadInputGivesAClearErrorAndNonzeroExit) {
  const fs::path dir = temp_dir("bad");
  const fs::path scene = write_scene(dir, kSquareScene);
  std::string err;
  EXPECT_EQ(
      run({RBSIM_BINARY, "render", scene.string(), "--out", (dir / "f").string(), "--size", "12x"}, &err), 1);
  EXPECT_NE(err.find("invalid --size"), std::string::npos) << err;
  EXPECT_EQ(
      run({RBSIM_BINARY, "render", scene.string(), "--out", (dir / "f").string(), "--size", "0x100"}, &err),
      1);
  // unwritable output folder: a path below a regular file
  const fs::path file = dir / "plain-file";
  std::ofstream(file) << "x";
  EXPECT_EQ(run({RBSIM_BINARY, "render", scene.string(), "--out", (file / "frames").string()}, &err), 1);
  EXPECT_NE(err.find("cannot create output folder"), std::string::npos) << err;
  if (::geteuid() != 0) {  // root writes anywhere
    fs::create_directories(dir / "ro");
    fs::permissions(dir / "ro", fs::perms::owner_read | fs::perms::owner_exec);
    EXPECT_EQ(run({RBSIM_BINARY, "render", scene.string(), "--out", (dir / "ro").string()}, &err), 1);
    EXPECT_NE(err.find("not writable"), std::string::npos) << err;
  }
  // a log with no scene description: record only body states through a raw MCAP with the wrong topics
  const fs::path log = dir / "states-only.mcap";
  ASSERT_EQ(run({RBSIM_BINARY, "run", scene.string(), "--steps", "5", "--record", log.string(), "-q"}), 0);
  std::string noscene = (dir / "noscene.mcap").string();
  {
    // rewrite without the scene topic using the MCAP library via the CLI is not available; build one here
    rbsim::mcap::IndexedReader r;
    ASSERT_TRUE(r.open(log.string()).ok());
    rbsim::mcap::Writer w;
    ASSERT_TRUE(w.open(noscene).ok());
    for (const auto& [id, s] : r.schemas()) ASSERT_TRUE(w.add_schema(s).ok());
    for (const auto& [id, c] : r.channels()) ASSERT_TRUE(w.add_channel(c).ok());
    ASSERT_TRUE(r.read_messages({}, [&](const rbsim::mcap::MessageEntry& e) {
                   if (e.channel->topic != "/rbsim/scene") {
                     EXPECT_TRUE(w.write_message(e.message).ok());
                   }
                   return true;
                 }).ok());
    ASSERT_TRUE(w.close().ok());
  }
  EXPECT_EQ(run({RBSIM_BINARY, "render", noscene, "--out", (dir / "g").string()}, &err), 1);
  EXPECT_NE(err.find(noscene + ": no scene description recorded"), std::string::npos) << err;
  // not a scene, not a log
  const fs::path junk = dir / "junk.bin";
  std::ofstream(junk) << "definitely not a scene";
  EXPECT_EQ(run({RBSIM_BINARY, "render", junk.string(), "--out", (dir / "h").string()}, &err), 1);
  EXPECT_NE(err.find("not well-formed XML"), std::string::npos) << err;
  EXPECT_EQ(run({RBSIM_BINARY, "plot", junk.string(), "--out", (dir / "p.png").string()}, &err), 1);
}

}  // namespace
