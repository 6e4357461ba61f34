// rbsim render / rbsim plot: pictures of a scene or a recording.
#include <cstdio>
#include <memory>

#include "cli_util.hpp"
#include "commands.hpp"
#include "rbsim/bag.hpp"
#include "rbsim/counts.hpp"
#include "rbsim/outputs.hpp"
#include "rbsim/render.hpp"
#include "validators.hpp"

namespace rbsim::cli {

namespace {
struct RenderArgs {
  std::string input, out, size = "1280x720", mp4;
  double fps = 24.0;
  std::optional<double> duration;
  bool overwrite = false;
};

int render_command(const RenderArgs& a) {
  render::RenderOptions o;
  if (!render::parse_size(a.size, o.width, o.height)) {
    return fail("render", "invalid --size \"" + a.size + "\" (expected WxH, e.g. 1280x720, each 16..16384)");
  }
  if (!(a.fps > 0.0 && a.fps <= 1000.0)) return fail("render", "--fps must be in (0, 1000]");
  o.out_dir = a.out;
  o.fps = a.fps;
  o.duration = a.duration;
  o.overwrite = a.overwrite;
  // Before any frame is drawn: the movie must not replace a file unasked, nor an input.
  if (Status st = check_outputs({{a.out, "--out", true}, {a.mp4, "--mp4"}}, {a.input}, a.overwrite); !st)
    return fail("render", st.error().message);
  Result<std::int64_t> frames = render::render(a.input, o);
  if (!frames) return fail("render", frames.error().message);
  std::fprintf(stderr, "rbsim render: %lld %s (%dx%d at %g fps) in %s\n",
               static_cast<long long>(frames.value()), plural(frames.value(), "frame", "frames"), o.width,
               o.height, o.fps, a.out.c_str());
  if (!a.mp4.empty()) {
    if (Status st = render::make_movie(a.out, a.fps, frames.value(), a.mp4); !st)
      return fail("render", st.error().message);
    std::fprintf(stderr, "rbsim render: movie %s\n", a.mp4.c_str());
  }
  return 0;
}

struct PlotArgs {
  std::string input, out, size = "1200x900";
  std::optional<double> duration;
  bool overwrite = false;
};

int plot_command(const PlotArgs& a) {
  render::PlotOptions o;
  o.out_png = a.out;
  o.duration = a.duration;
  if (!render::parse_size(a.size, o.width, o.height)) {
    std::fprintf(stderr, "rbsim plot: error: invalid --size \"%s\" (expected WxH)\n", a.size.c_str());
    return 1;
  }
  if (a.duration && recordings::is_recording(a.input)) {  // a recording plots what it holds
    std::fprintf(stderr,
                 "rbsim plot: error: --duration applies to a scene, not to a recording (%s)\n"
                 "Run 'rbsim plot --help' for usage.\n",
                 a.input.c_str());
    return 2;
  }
  if (Status st = check_outputs({{a.out, "--out"}}, {a.input}, a.overwrite); !st) {
    std::fprintf(stderr, "rbsim plot: error: %s\n", st.error().message.c_str());
    return 1;
  }
  if (Status st = render::plot(a.input, o); !st) {
    std::fprintf(stderr, "rbsim plot: error: %s\n", st.error().message.c_str());
    return 1;
  }
  return 0;
}
}  // namespace

Subcommand add_render_command(CLI::App& parent) {
  auto a = std::make_shared<RenderArgs>();
  CLI::App* app = parent.add_subcommand(
      "render", "Draw a scene (simulated on the fly) or an MCAP recording as PNG frames");
  app->add_option("input", a->input, "FOSSSim XML scene, or an rbsim MCAP recording")->required();
  app->add_option("--out", a->out, "Folder for frame00000.png, frame00001.png, ... (created if needed)")
      ->required();
  app->add_option("--fps", a->fps, "Frames per simulated second")->default_str("24");
  app->add_option("--size", a->size, "Frame size WxH in pixels")->default_str("1280x720");
  app->add_option("--duration", a->duration, "Simulated seconds to draw (default: the scene's duration)")
      ->check(positive());
  app->add_option("--mp4", a->mp4,
                  "Also assemble this render's frames (and only them) into an H.264 (yuv420p) movie with "
                  "ffmpeg");
  app->add_flag("--overwrite", a->overwrite,
                "Replace an earlier render: remove the frame files (frameNNNNN.png, nothing else) already in "
                "--out first, and replace an existing --mp4 file");
  app->footer(
      "Frames cover T simulated seconds: frame k shows time k / fps (the first step at or after it) for "
      "k = 0 .. floor(T x fps) - 1, so T x fps frames. T is --duration, else the scene's duration, or for a "
      "recording the run's: the scene's duration for a run of its full length, else the last recorded step "
      "x dt (rbsim run --frames counts the same way). A folder that already holds frame files, or an "
      "existing --mp4 file, is refused unless --overwrite, so old frames never end up in a movie. Bodies are "
      "filled hulls grown by their radius r in their scene colours, springs are lines in theirs (fixed ends "
      "ringed), on the scene's background, framed by its viewport (or fitted to the bodies).\n"
      "Exit status: 0 success, 1 error (bad input, divergence, unwritable or existing output, ffmpeg "
      "failure), 2 usage error.");
  return {app, [a] { return render_command(*a); }};
}

Subcommand add_plot_command(CLI::App& parent) {
  auto a = std::make_shared<PlotArgs>();
  CLI::App* app = parent.add_subcommand("plot",
                                        "Plot kinetic (centre of mass, spin), potential and total energy and "
                                        "total momentum over time (gnuplot)");
  app->add_option("input", a->input, "FOSSSim XML scene (simulated), or an rbsim MCAP recording")->required();
  app->add_option("--out", a->out, "PNG file to write")->required();
  app->add_option("--size", a->size, "Image size WxH in pixels")->default_str("1200x900");
  app->add_option("--duration", a->duration, "Simulated seconds (scenes only; default: the scene's duration)")
      ->check(positive());
  app->add_flag("--overwrite", a->overwrite, "Replace the PNG if it exists (by default it is refused)");
  app->footer(
      "Exit status: 0 success, 1 error (bad input, divergence, unwritable output, gnuplot failure), 2 usage "
      "error.");
  return {app, [a] { return plot_command(*a); }};
}

}  // namespace rbsim::cli
