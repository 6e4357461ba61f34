// Frames, movies and plots of a scene or a recording.
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string_view>

#include "process.hpp"

#include "rbsim/atomic_file.hpp"
#include "rbsim/bag.hpp"
#include "rbsim/mcap.hpp"
#include "rbsim/mcap_records.hpp"
#include "rbsim/recording.hpp"
#include "rbsim/render.hpp"
#include "rbsim/run.hpp"

extern char** environ;

namespace rbsim::render {

namespace fs = std::filesystem;

bool parse_size(const std::string& text, int& width, int& height) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X')) return false;
  if (w < 16 || h < 16 || w > 16384 || h > 16384) return false;
  width = w;
  height = h;
  return true;
}

// ---------------------------------------------------------------------------------------------
bool is_frame_file(const std::string& name) {
  constexpr std::string_view prefix = "frame", suffix = ".png";
  if (name.size() < prefix.size() + 5 + suffix.size() || !name.starts_with(prefix) || !name.ends_with(suffix))
    return false;
  for (std::size_t i = prefix.size(); i < name.size() - suffix.size(); ++i) {
    if (name[i] < '0' || name[i] > '9') return false;
  }
  return true;
}

namespace {
std::string frame_name(std::int64_t k) {
  char name[32];
  std::snprintf(name, sizeof name, "frame%05lld.png", static_cast<long long>(k));
  return name;
}
}  // namespace

FrameWriter::FrameWriter(std::string dir, int width, int height, double fps, bool overwrite)
    : dir_(std::move(dir)), fps_(fps), overwrite_(overwrite), canvas_(width, height) {}

Status FrameWriter::open() {
  std::error_code ec;
  fs::create_directories(dir_, ec);
  if (ec || !fs::is_directory(dir_)) return Error{dir_ + ": cannot create output folder: " + ec.message()};
  const std::string probe = (fs::path(dir_) / ".rbsim-write-test").string();
  std::FILE* f = std::fopen(probe.c_str(), "wb");
  if (f == nullptr) return Error{dir_ + ": output folder is not writable: " + std::strerror(errno)};
  std::fclose(f);
  std::remove(probe.c_str());
  // Frames of an earlier render: never overwritten or mixed with this one's unless asked.
  std::vector<fs::path> old;
  for (fs::directory_iterator it(dir_, ec), end; !ec && it != end; it.increment(ec)) {
    if (is_frame_file(it->path().filename().string())) old.push_back(it->path());
  }
  if (ec) return Error{dir_ + ": cannot list the output folder: " + ec.message()};
  if (old.empty()) return Ok{};
  if (!overwrite_) {
    return Error{
        dir_ + ": already holds " + std::to_string(old.size()) +
        " frame files (frameNNNNN.png) of an earlier render; use --overwrite to replace them, or another "
        "folder"};
  }
  for (const fs::path& p : old) {
    if (!fs::remove(p, ec) && ec) return Error{p.string() + ": cannot remove an old frame: " + ec.message()};
  }
  return Ok{};
}

Status FrameWriter::offer(const Stage& stage, std::int64_t step, double dt, std::span<const Pose> poses) {
  while (frame_step(next_, fps_, dt) <= step && next_ < frame_count(stage.duration, fps_)) {
    if (!camera_) camera_ = camera_for(stage, poses, canvas_.width(), canvas_.height());
    canvas_.draw(stage, poses, static_cast<double>(step) * dt, *camera_);
    if (Status st = canvas_.write_png((fs::path(dir_) / frame_name(next_)).string()); !st) return st;
    ++next_;
  }
  return Ok{};
}

Status FrameWriter::truncate(std::int64_t count) {
  for (; next_ > count; --next_) {
    const fs::path p = fs::path(dir_) / frame_name(next_ - 1);
    std::error_code ec;
    if (!fs::remove(p, ec) && ec) return Error{p.string() + ": cannot remove: " + ec.message()};
  }
  return Ok{};
}

namespace {

void poses_of(const World& world, std::vector<Pose>& out) {
  out.resize(static_cast<std::size_t>(world.body_count()));
  for (std::int32_t b = 0; b < world.body_count(); ++b)
    out[b] = {world.x()[b], world.y()[b], world.theta()[b]};
}

// Frames of [0, duration) as the run goes. `trim`: the frames end with the run too, at
// run_duration() of its last step (rbsim run --frames; an interrupted run included).
class FrameSink final : public Sink {
 public:
  FrameSink(std::string dir, int width, int height, double fps, double duration, bool overwrite, bool trim)
      : frames_(std::move(dir), width, height, fps, overwrite), fps_(fps), duration_(duration), trim_(trim) {}
  Status begin(const Scene& scene, const World& world) override {
    stage_ = stage_of(scene, world);
    scene_duration_ = scene.duration;
    scene_steps_ = scene.step_count();
    stage_.duration = duration_;
    if (Status st = frames_.open(); !st) return st;
    return write(world);
  }
  Status write(const World& world) override {
    last_step_ = world.step_index();
    poses_of(world, poses_);
    return frames_.offer(stage_, world.step_index(), world.dt(), poses_);
  }
  Status finish() override {
    if (!trim_) return Ok{};
    const double covered = run_duration(last_step_, stage_.dt, scene_duration_, scene_steps_);
    return frames_.truncate(frame_count(std::min(duration_, covered), fps_));
  }
  std::int64_t frames() const { return frames_.frames(); }

 private:
  FrameWriter frames_;
  double fps_, duration_;
  bool trim_;
  Stage stage_;
  double scene_duration_ = 0.0;
  std::int64_t scene_steps_ = 0, last_step_ = 0;
  std::vector<Pose> poses_;
};

}  // namespace

namespace detail {
Result<int> run_process(const std::vector<std::string>& args) {
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int err = posix_spawnp(&pid, argv[0], nullptr, nullptr, argv.data(), environ);
  if (err != 0) {
    return Error{args[0] + " could not be started (" + std::strerror(err) +
                 "): install it (scripts/setup installs it)"};
  }
  int status = 0;
  while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

}  // namespace detail

std::unique_ptr<Sink> make_frame_sink(std::string dir, int width, int height, double fps, double duration,
                                      bool overwrite) {
  return std::make_unique<FrameSink>(std::move(dir), width, height, fps, duration, overwrite, /*trim=*/true);
}

Result<std::int64_t> render(const std::string& input, const RenderOptions& o) {
  if (recordings::is_recording(input)) {
    FrameWriter frames(o.out_dir, o.width, o.height, o.fps, o.overwrite);
    std::vector<Pose> poses;
    recordings::RecordingOptions ro;
    ro.read = {msgs::TopicId::BodyStates};
    auto recording = recordings::Recording::open(input, ro);
    if (!recording) return recording.error();
    const msgs::SceneMessage& scene = *recording.value()->scene();
    // The recording's T is known once its last step is read: draw up to it, then drop the frames
    // at or after T (those showing exactly the last step's time, or past the scene's duration).
    const auto drawn = [&](const msgs::SceneMessage& described) {
      Stage s = stage_of(described);
      s.duration = o.duration.value_or(INFINITY);
      return s;
    };
    Stage stage = drawn(scene);
    if (Status st = frames.open(); !st) return st.error();
    std::optional<std::uint64_t> last;
    std::uint32_t epoch = 0;
    Status st = recording.value()->read_steps([&](const recordings::RecordedStep& step) -> Status {
      if (step.body_states == nullptr) return Ok{};
      if (step.epoch != epoch) {  // bodies came or went: the shapes of the step's scene description
        epoch = step.epoch;
        stage = drawn(*step.scene);
      }
      last = step.step;
      poses.clear();
      for (const auto& b : step.body_states->bodies)
        poses.push_back({b.state.position.x(), b.state.position.y(), b.state.theta});
      return frames.offer(stage, static_cast<std::int64_t>(step.step), stage.dt, poses);
    });
    if (!st) return st.error();
    if (!last) return Error{input + ": no body states recorded"};
    const double covered = run_duration(static_cast<std::int64_t>(*last), stage.dt, scene.duration,
                                        static_cast<std::int64_t>(scene.step_count));
    if (Status t = frames.truncate(frame_count(std::min(stage.duration, covered), o.fps)); !t)
      return t.error();
    return frames.frames();
  }
  Result<Scene> scene = load_scene(input);
  if (!scene) return scene.error();
  Result<Driver> driver = Driver::create(scene.value());
  if (!driver) return driver.error();
  const double duration = o.duration.value_or(scene->duration);
  FrameSink sink(o.out_dir, o.width, o.height, o.fps, duration, o.overwrite, /*trim=*/false);
  driver->add(sink);
  DriverOptions options;
  options.steps =
      frame_step(frame_count(duration, o.fps) - 1, o.fps, driver->world().dt());  // the last frame's
  if (Status st = driver->run_pass(options); !st) return st.error();
  return sink.frames();
}

Status make_movie(const std::string& frames_dir, double fps, std::int64_t frames, const std::string& mp4) {
  AtomicFile movie;
  movie.open_external(mp4, AtomicFile::Leftovers::Remove);
  char rate[32];
  std::snprintf(rate, sizeof rate, "%g", fps);
  // -f mp4: the temporary's name does not end in .mp4, so ffmpeg is told the container.
  const std::string input = (fs::path(frames_dir) / "frame%05d.png").string();
  const std::string output = movie.writer_path();
  Result<int> code =
      detail::run_process({"ffmpeg", "-y",        "-loglevel",  "error",     "-framerate",
                           rate,     "-i",        input,        "-frames:v", std::to_string(frames),
                           "-c:v",   "libx264",   "-pix_fmt",   "yuv420p",   "-crf",
                           "20",     "-movflags", "+faststart", "-f",        "mp4",
                           output});
  if (!code) return with_context("ffmpeg: ", code.error());
  if (code.value() != 0) {
    return Error{"ffmpeg failed (exit " + std::to_string(code.value()) + ") making " + mp4};
  }
  return movie.commit();
}

}  // namespace rbsim::render
