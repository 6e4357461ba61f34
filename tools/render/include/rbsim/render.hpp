// Pictures of a run: frames drawn with Cairo (anti-aliased) from a scene simulated on the fly or
// from a recording, movies assembled by ffmpeg, energy/momentum plots drawn by gnuplot.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/msgs.hpp"
#include "rbsim/scene.hpp"
#include "rbsim/sink.hpp"

namespace rbsim::render {

// Everything constant that a picture shows. Built from a Scene or from a recorded
// SceneDescription; both give the same stage for the same run (colours are the float32 values
// the message carries), so both ways draw the same pixels.
struct Stage {
  struct Body {
    std::vector<Vec2> hull;  // body space
    Color color;
    double radius = 0.0;
  };
  std::vector<Body> bodies;
  std::vector<SpringDef> springs;
  std::vector<Color> spring_colors;
  std::optional<Viewport> viewport;
  Color background{1.0, 1.0, 1.0};
  double dt = 0.0;
  double duration = 0.0;
};
Stage stage_of(const Scene& scene, const World& world);
Stage stage_of(const msgs::SceneMessage& scene);

// Pose of every body in one frame.
struct Pose {
  double x = 0.0, y = 0.0, theta = 0.0;
};

// World to pixel mapping: x right, y up; `scale` pixels per unit.
struct Camera {
  double cx = 0.0, cy = 0.0, scale = 1.0;
  int width = 0, height = 0;
};
// The scene's viewport (centre, and `size` = half the extent of the shorter image side), or,
// when the scene has none, the extent of the bodies in `poses` with a margin.
Camera camera_for(const Stage& stage, std::span<const Pose> poses, int width, int height);

// The one frame rule of render, run --frames and movies: frames cover [0, T) at `fps`, frame k
// shows time k / fps, for k = 0 .. count - 1 with count = floor(T * fps) (at least 1): T x fps
// frames for T simulated seconds.
std::int64_t frame_count(double duration, double fps);
// The T of a run of `steps` steps of `dt` (times 0 .. steps x dt): the scene's duration when the
// run is the scene's own length (steps == the scene's step count, ceil(duration / dt)), else
// steps x dt. A scene rendered for its duration, a recording of its run (up to its last recorded
// step) and `rbsim run --frames` of it thus give the same frames.
double run_duration(std::int64_t steps, double dt, double scene_duration, std::int64_t scene_steps);
// The step shown by frame k: the first step at or after its time.
std::int64_t frame_step(std::int64_t frame, double fps, double dt);

class Canvas {
 public:
  Canvas(int width, int height);
  ~Canvas();
  Canvas(const Canvas&) = delete;
  Canvas& operator=(const Canvas&) = delete;

  void draw(const Stage& stage, std::span<const Pose> poses, double time, const Camera& camera);
  // Writes the canvas as an 8-bit RGB PNG (written to a temporary name, then renamed).
  [[nodiscard]] Status write_png(const std::string& path) const;
  // Pixel (x, y) from the top-left, as 0..255 RGB.
  std::array<int, 3> pixel(int x, int y) const;
  int width() const { return width_; }
  int height() const { return height_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int width_, height_;
};

// Whether `name` is a frame file's name: "frame" + at least five digits + ".png".
bool is_frame_file(const std::string& name);

// Writes frames "frame00000.png", ... into a folder (created if needed; must be writable).
// A folder that already holds frame files (of an earlier render) is refused, so that they are
// neither overwritten nor mixed with this render's in a movie, unless `overwrite`: they are then
// removed first. No other file of the folder is touched.
class FrameWriter {
 public:
  FrameWriter(std::string dir, int width, int height, double fps, bool overwrite = false);
  [[nodiscard]] Status open();  // checks the folder is writable and holds no frames (see above)
  // Draws the frames of [0, stage.duration) that show `step` (the first offered step at or after
  // their time); returns how many frames were written.
  [[nodiscard]] Status offer(const Stage& stage, std::int64_t step, double dt, std::span<const Pose> poses);
  // Keeps the first `count` frames written, removing the files of any after them.
  [[nodiscard]] Status truncate(std::int64_t count);
  std::int64_t frames() const { return next_; }
  const std::string& dir() const { return dir_; }

 private:
  std::string dir_;
  double fps_;
  bool overwrite_;
  Canvas canvas_;
  std::optional<Camera> camera_;  // fixed at the first frame
  std::int64_t next_ = 0;         // next frame index
};

// A Sink that draws frames during a run (rbsim run --frames DIR): T is run_duration() of the steps
// the run did (`duration` when it is shorter), so a run of a scene's duration gives the frames
// `rbsim render` gives of that scene. `overwrite` as for FrameWriter.
std::unique_ptr<Sink> make_frame_sink(std::string dir, int width, int height, double fps, double duration,
                                      bool overwrite);

// Renders a scene (simulated on the fly) or an rbsim MCAP recording (drawn from its scene
// description and body states) into `dir`. Returns the number of frames.
struct RenderOptions {
  std::string out_dir;
  int width = 1280, height = 720;
  double fps = 24.0;
  // T; default: the scene's duration, or a recording's run_duration() of its last recorded step
  // (never more than that).
  std::optional<double> duration;
  bool overwrite = false;  // see FrameWriter
};
Result<std::int64_t> render(const std::string& input, const RenderOptions& options);

// Assembles dir/frame00000.png .. frame<frames - 1>.png (and no other) into an H.264 yuv420p movie
// with ffmpeg, written under a temporary name and renamed over `mp4`.
[[nodiscard]] Status make_movie(const std::string& frames_dir, double fps, std::int64_t frames,
                                const std::string& mp4);

// Plots kinetic (centre of mass, spin), potential and total energy and total linear and angular
// momentum over time with gnuplot, from a scene (simulated) or a recording.
struct PlotOptions {
  std::string out_png;
  int width = 1200, height = 900;
  std::optional<double> duration;
};
[[nodiscard]] Status plot(const std::string& input, const PlotOptions& options);

// Parses "1280x720".
bool parse_size(const std::string& text, int& width, int& height);

}  // namespace rbsim::render
