// The FOSSSim reference format and the reference's grading rule.
#include <zstd.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "rbsim/fosssim.hpp"
#include "rbsim/read_file.hpp"

namespace rbsim {

Result<std::vector<std::byte>> read_file(const std::string& path) {
  Result<Bytes> read = read_whole_file(path);
  if (!read || !path.ends_with(".zst")) return read;
  const Bytes& raw = read.value();
  std::vector<std::byte> out;
  ZSTD_DCtx* ctx = ZSTD_createDCtx();
  ZSTD_inBuffer input{raw.data(), raw.size(), 0};
  std::vector<std::byte> chunk(ZSTD_DStreamOutSize());
  std::size_t last = 1;
  while (input.pos < input.size) {
    ZSTD_outBuffer output{chunk.data(), chunk.size(), 0};
    last = ZSTD_decompressStream(ctx, &output, &input);
    if (ZSTD_isError(last)) {
      ZSTD_freeDCtx(ctx);
      return Error{path + ": not a valid zstd stream: " + ZSTD_getErrorName(last)};
    }
    out.insert(out.end(), chunk.begin(), chunk.begin() + static_cast<std::ptrdiff_t>(output.pos));
  }
  ZSTD_freeDCtx(ctx);
  if (last != 0) return Error{path + ": truncated zstd stream"};
  return out;
}

Result<FosssimLog> parse_fosssim(std::span<const std::byte> data, std::int32_t bodies) {
  const std::size_t b = static_cast<std::size_t>(bodies);
  const std::size_t count = data.size() / sizeof(double);
  const std::size_t head = 16 * b + 1, per_step = 12 * b + 1;  // state+constants+quantities; state+quantities
  if (bodies <= 0 || data.size() % sizeof(double) != 0 || count < head || (count - head) % per_step != 0) {
    return Error{"reference output: size " + std::to_string(data.size()) + " bytes does not fit " +
                 std::to_string(bodies) + " bodies"};
  }
  std::vector<double> v(count);
  std::memcpy(v.data(), data.data(), count * sizeof(double));
  std::size_t at = 0;
  FosssimLog log;
  auto frame = [&](bool with_constants) {
    FosssimFrame f;
    for (std::size_t i = 0; i < b; ++i, at += 6) {
      f.states.push_back(BodyState{{v[at], v[at + 1]}, v[at + 2], {v[at + 3], v[at + 4]}, v[at + 5]});
    }
    if (with_constants) {
      for (std::size_t i = 0; i < b; ++i) log.mass.push_back(v[at++]);
      for (std::size_t i = 0; i < b; ++i, at += 2) log.center.emplace_back(v[at], v[at + 1]);
      for (std::size_t i = 0; i < b; ++i) log.inertia.push_back(v[at++]);
    }
    f.quantities.resize(b);
    for (auto& q : f.quantities) q.momentum = {v[at], v[at + 1]}, at += 2;
    for (auto& q : f.quantities) q.l_point = v[at++];
    for (auto& q : f.quantities) q.l_spin = v[at++];
    for (auto& q : f.quantities) q.t_point = v[at++];
    for (auto& q : f.quantities) q.t_spin = v[at++];
    f.potential = v[at++];
    log.frames.push_back(std::move(f));
  };
  frame(true);
  while (at < count) frame(false);
  return log;
}

namespace {
struct Tracker {
  double worst = 0.0;
  std::string where;
  void see(double expected, double actual, const std::string& what) {
    const double d = std::abs(expected - actual);
    if (!(d <= worst)) {  // NaN counts as the worst
      worst = std::isnan(d) ? INFINITY : d;
      where = what;
    }
  }
};
}  // namespace

Result<GradeReport> grade(const Scene& scene, const FosssimLog& ref, const GradeOptions& options) {
  Result<World> created = World::create(scene.world);
  if (!created) return created.error();
  World& w = created.value();
  const std::int32_t n = w.body_count();
  if (static_cast<std::int32_t>(ref.mass.size()) != n) return Error{"reference has a different body count"};
  const auto expected_frames = scene.step_count() + 1;
  if (static_cast<std::int64_t>(ref.frames.size()) != expected_frames) {
    return Error{"reference has " + std::to_string(ref.frames.size()) + " frames, the scene needs " +
                 std::to_string(expected_frames)};
  }
  Tracker q;
  for (std::int32_t b = 0; b < n; ++b) {
    const std::string body = "body " + std::to_string(b) + " ";
    q.see(ref.mass[b], w.mass(BodyId{b}), body + "M");
    q.see(ref.center[b].x(), w.x()[b], body + "X.x");
    q.see(ref.center[b].y(), w.y()[b], body + "X.y");
    q.see(ref.inertia[b], w.inertia(BodyId{b}), body + "I");
  }
  GradeReport r;
  r.steps = expected_frames - 1;
  for (std::size_t k = 0; k < ref.frames.size(); ++k) {
    const FosssimFrame& f = ref.frames[k];
    for (std::int32_t b = 0; b < n; ++b) w.set_state(BodyId{b}, f.states[b]);
    w.set_step_index(static_cast<std::int64_t>(k));
    const std::string at = "step " + std::to_string(k) + " ";
    for (std::int32_t b = 0; b < n; ++b) {
      const BodyQuantities mine = w.quantities(BodyId{b});
      const BodyQuantities& theirs = f.quantities[b];
      const std::string who = at + "body " + std::to_string(b) + " ";
      q.see(theirs.momentum.x(), mine.momentum.x(), who + "P.x");
      q.see(theirs.momentum.y(), mine.momentum.y(), who + "P.y");
      q.see(theirs.l_point, mine.l_point, who + "L_point");
      q.see(theirs.l_spin, mine.l_spin, who + "L_spin");
      q.see(theirs.t_point, mine.t_point, who + "T_point");
      q.see(theirs.t_spin, mine.t_spin, who + "T_spin");
    }
    q.see(f.potential, w.potential_energy(), at + "U");
    if (k + 1 == ref.frames.size()) break;
    w.step();
    double diff = 0.0;
    for (std::int32_t b = 0; b < n; ++b) {
      const BodyState mine = w.state(BodyId{b});
      const BodyState& next = ref.frames[k + 1].states[b];
      for (double d : {mine.position.x() - next.position.x(), mine.position.y() - next.position.y(),
                       mine.theta - next.theta, mine.velocity.x() - next.velocity.x(),
                       mine.velocity.y() - next.velocity.y(), mine.omega - next.omega}) {
        diff = std::isnan(d) ? INFINITY : std::max(diff, std::abs(d));
      }
    }
    r.sum_step_diff += diff;
    if (diff > r.max_step_diff) r.max_step_diff = diff, r.worst_step = static_cast<std::int64_t>(k + 1);
  }
  r.max_quantity_diff = q.worst;
  r.worst_quantity = q.where;
  if (!(r.max_step_diff < options.max_step_diff)) {
    r.message =
        "state differs by " + std::to_string(r.max_step_diff) + " at step " + std::to_string(r.worst_step);
  } else if (!(r.sum_step_diff < options.sum_step_diff)) {
    r.message = "summed state difference " + std::to_string(r.sum_step_diff) + " too large";
  } else if (!(r.max_quantity_diff < options.quantity_tol)) {
    r.message = "quantity " + r.worst_quantity + " differs by " + std::to_string(r.max_quantity_diff);
  }
  r.passed = r.message.empty();
  return r;
}

}  // namespace rbsim
