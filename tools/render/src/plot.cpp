// Energy and momentum over time, drawn by gnuplot.
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>

#include "process.hpp"
#include "rbsim/atomic_file.hpp"
#include "rbsim/bag.hpp"
#include "rbsim/recording.hpp"
#include "rbsim/render.hpp"
#include "rbsim/run.hpp"

namespace rbsim::render {

namespace fs = std::filesystem;

namespace {

struct Sample {
  double t, t_point, t_spin, u, e, px, py, l;
};

// Samples of step 0, every `every`-th step and step `last`: at most about 8000 in all.
class SampleSink final : public Sink {
 public:
  explicit SampleSink(std::int64_t last) : last_(last), every_(std::max<std::int64_t>(1, last / 4000)) {}
  Status begin(const Scene&, const World& world) override {
    samples_.clear();
    samples_.reserve(static_cast<std::size_t>(last_ / every_ + 2));
    return write(world);
  }
  Status write(const World& w) override {
    if (w.step_index() % every_ == 0 || w.step_index() == last_) {
      const Energy e = w.energy();
      const SceneTotals totals = w.totals();
      samples_.push_back({w.time(), e.t_point, e.t_spin, e.potential(), e.total(), totals.momentum.x(),
                          totals.momentum.y(), totals.angular});
    }
    return Ok{};
  }
  Status finish() override { return Ok{}; }
  std::vector<Sample>& samples() { return samples_; }

 private:
  std::int64_t last_, every_;
  std::vector<Sample> samples_;
};

Result<std::vector<Sample>> samples_from_scene(const std::string& path, std::optional<double> duration) {
  Result<Scene> scene = load_scene(path);
  if (!scene) return scene.error();
  Result<Driver> driver = Driver::create(scene.value());
  if (!driver) return driver.error();
  DriverOptions options;
  options.steps = steps_for(duration.value_or(scene->duration), driver->world().dt());
  SampleSink sink(options.steps);
  driver->add(sink);
  if (Status st = driver->run_pass(options); !st) return st.error();
  return std::move(sink.samples());
}

// The totals of every recorded rbsim_msgs/msg/EnergyTerms, at the time its header stamp says.
Result<std::vector<Sample>> samples_from_log(const std::string& path) {
  recordings::RecordingOptions ro;
  ro.read = {msgs::TopicId::Energy};
  ro.require = {msgs::TopicId::Energy};
  ro.require_scene = false;
  auto recording = recordings::Recording::open(path, ro);
  if (!recording) return recording.error();
  std::vector<Sample> out;
  Status st = recording.value()->read_steps([&](const recordings::RecordedStep& step) -> Status {
    if (step.energy == nullptr) return Ok{};
    const msgs::EnergyTermsMessage& e = *step.energy;
    const double t = static_cast<double>(e.stamp.sec) + 1e-9 * static_cast<double>(e.stamp.nanosec);
    out.push_back({t, e.kinetic_point, e.kinetic_spin, e.potential, e.total, e.momentum.x(), e.momentum.y(),
                   e.angular_momentum});
    return Ok{};
  });
  if (!st) return st.error();
  if (out.empty())
    return Error{path + ": no energy terms recorded (topic " +
                 recording.value()->topic(msgs::TopicId::Energy) + ")"};
  return out;
}

}  // namespace

Status plot(const std::string& input, const PlotOptions& o) {
  Result<std::vector<Sample>> samples =
      recordings::is_recording(input) ? samples_from_log(input) : samples_from_scene(input, o.duration);
  if (!samples) return samples.error();

  AtomicFile png;  // gnuplot writes it
  png.open_external(o.out_png, AtomicFile::Leftovers::Remove);
  // gnuplot's data and script: unnamed scratch files (tmpfile), read by their /proc paths, so a
  // killed plot leaves neither.
  const std::unique_ptr<std::FILE, int (*)(std::FILE*)> data(std::tmpfile(), &std::fclose),
      script(std::tmpfile(), &std::fclose);
  if (!data || !script) return Error{o.out_png + ": no scratch file for gnuplot: " + std::strerror(errno)};
  for (const Sample& s : samples.value()) {
    std::fprintf(data.get(), "%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g,%.17g\n", s.t, s.t_point, s.t_spin,
                 s.u, s.e, s.px, s.py, s.l);
  }
  const std::string data_path = open_file_path(::fileno(data.get()));
  std::ostringstream gp;
  gp << "set terminal pngcairo size " << o.width << "," << o.height << " enhanced font 'DejaVu Sans,11'\n"
     << "set output '" << png.writer_path() << "'\n"
     << "set datafile separator ','\nset grid\nset key outside right top\nset xlabel 'time (s)'\n"
     << "set multiplot layout 2,1 title '" << fs::path(input).filename().string() << "'\n"
     << "set title 'Energy'\nset ylabel 'energy'\n"
     << "plot '" << data_path << "' using 1:2 with lines lw 1.5 title 'T_{point} (centre of mass)', "
     << "'' using 1:3 with lines lw 1.5 title 'T_{spin}', '' using 1:4 with lines lw 1.5 title 'U "
        "(potential)', "
     << "'' using 1:5 with lines lw 2.5 title 'E = T + U'\n"
     << "set title 'Momentum'\nset ylabel 'momentum'\n"
     << "plot '" << data_path
     << "' using 1:6 with lines lw 1.5 title 'P_x', '' using 1:7 with lines lw 1.5 title 'P_y', "
     << "'' using 1:8 with lines lw 2 title 'L = L_{point} + L_{spin}'\n"
     << "unset multiplot\n";
  const std::string text = gp.str();
  std::fwrite(text.data(), 1, text.size(), script.get());
  if (std::fflush(data.get()) != 0 || std::fflush(script.get()) != 0 || std::ferror(data.get()) != 0 ||
      std::ferror(script.get()) != 0)
    return Error{o.out_png + ": cannot write gnuplot's scratch files: " + std::strerror(errno)};
  Result<int> code = detail::run_process({"gnuplot", open_file_path(::fileno(script.get()))});
  if (!code) return with_context("gnuplot: ", code.error());
  if (code.value() != 0) return Error{"gnuplot failed drawing " + o.out_png};
  return png.commit();
}

}  // namespace rbsim::render
