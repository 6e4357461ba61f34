// CSV and FOSSSim-binary outputs of a run.
#include <bit>
#include <charconv>
#include <cstring>

#include "rbsim/io.hpp"

namespace rbsim {

void append_double(std::string& out, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  out.append(buf, ec == std::errc() ? end : buf);
}

namespace {

void append_int(std::string& out, std::int64_t v) {
  char buf[24];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ec == std::errc() ? end : buf);
}

// Text sinks build rows in a reused string and hand it to the file in large writes.
class TextSink : public Sink {
 public:
  explicit TextSink(std::string path) : path_(std::move(path)) {}
  Status begin(const Scene&, const World& world) override {
    if (Status st = file_.open(path_); !st) return st;
    buffer_.reserve(kFlushAt + 4096);
    buffer_ = header();
    buffer_ += '\n';
    return write(world);
  }
  Status write(const World& world) override {
    rows(world);
    if (buffer_.size() >= kFlushAt) return flush();
    return Ok{};
  }
  Status finish() override {
    if (Status st = flush(); !st) return st;
    return file_.commit();
  }

 protected:
  virtual std::string header() const = 0;
  virtual void rows(const World& world) = 0;
  std::string buffer_;

 private:
  static constexpr std::size_t kFlushAt = 1 << 20;
  Status flush() {
    Status st = file_.write(buffer_.data(), buffer_.size());
    buffer_.clear();
    return st;
  }
  std::string path_;
  AtomicFile file_;
};

class CsvSink final : public TextSink {
 public:
  using TextSink::TextSink;

 private:
  std::string header() const override {
    return "step,t,body,x,y,theta,vx,vy,omega,px,py,L_point,L_spin,T_point,T_spin";
  }
  void rows(const World& world) override {
    const double t = world.time();
    for (std::int32_t b = 0; b < world.body_count(); ++b) {
      const BodyState s = world.state(BodyId{b});
      const BodyQuantities q = world.quantities(BodyId{b});
      append_int(buffer_, world.step_index());
      buffer_ += ',';
      append_double(buffer_, t);
      buffer_ += ',';
      append_int(buffer_, b);
      for (double v : {s.position.x(), s.position.y(), s.theta, s.velocity.x(), s.velocity.y(), s.omega,
                       q.momentum.x(), q.momentum.y(), q.l_point, q.l_spin, q.t_point, q.t_spin}) {
        buffer_ += ',';
        append_double(buffer_, v);
      }
      buffer_ += '\n';
    }
  }
};

class EnergyCsvSink final : public TextSink {
 public:
  using TextSink::TextSink;

 private:
  std::string header() const override { return "step,t,U,T_point,T_spin,T,E,U_gravity,U_spring,px,py,L"; }
  void rows(const World& world) override {
    const Energy e = world.energy();
    Vec2 p(0.0, 0.0);
    double l = 0.0;
    for (std::int32_t b = 0; b < world.body_count(); ++b) {
      const BodyQuantities q = world.quantities(BodyId{b});
      p += q.momentum;
      l += q.l_point + q.l_spin;
    }
    append_int(buffer_, world.step_index());
    for (double v : {world.time(), e.potential(), e.t_point, e.t_spin, e.kinetic(), e.total(), e.u_gravity,
                     e.u_spring, p.x(), p.y(), l}) {
      buffer_ += ',';
      append_double(buffer_, v);
    }
    buffer_ += '\n';
  }
};

static_assert(std::endian::native == std::endian::little, "the FOSSSim format is little-endian doubles");

class FosssimSink final : public Sink {
 public:
  explicit FosssimSink(std::string path) : path_(std::move(path)) {}
  Status begin(const Scene&, const World& world) override {
    if (Status st = file_.open(path_); !st) return st;
    const auto n = world.body_count();
    values_.reserve(static_cast<std::size_t>(12 * n + 1));
    state(world);
    for (std::int32_t b = 0; b < n; ++b) values_.push_back(world.mass(BodyId{b}));
    for (std::int32_t b = 0; b < n; ++b) {
      values_.push_back(world.x()[b]);
      values_.push_back(world.y()[b]);
    }
    for (std::int32_t b = 0; b < n; ++b) values_.push_back(world.inertia(BodyId{b}));
    quantities(world);
    return emit();
  }
  Status write(const World& world) override {
    state(world);
    quantities(world);
    return emit();
  }
  Status finish() override { return file_.commit(); }

 private:
  void state(const World& w) {
    for (std::int32_t b = 0; b < w.body_count(); ++b) {
      for (double v : {w.x()[b], w.y()[b], w.theta()[b], w.vx()[b], w.vy()[b], w.omega()[b]})
        values_.push_back(v);
    }
  }
  void quantities(const World& w) {
    const auto n = w.body_count();
    quantities_.resize(static_cast<std::size_t>(n));
    for (std::int32_t b = 0; b < n; ++b) quantities_[b] = w.quantities(BodyId{b});
    for (const auto& q : quantities_) {
      values_.push_back(q.momentum.x());
      values_.push_back(q.momentum.y());
    }
    for (const auto& q : quantities_) values_.push_back(q.l_point);
    for (const auto& q : quantities_) values_.push_back(q.l_spin);
    for (const auto& q : quantities_) values_.push_back(q.t_point);
    for (const auto& q : quantities_) values_.push_back(q.t_spin);
    values_.push_back(w.potential_energy());
  }
  Status emit() {
    Status st = file_.write(values_.data(), values_.size() * sizeof(double));
    values_.clear();
    return st;
  }
  std::string path_;
  AtomicFile file_;
  std::vector<double> values_;
  std::vector<BodyQuantities> quantities_;
};

}  // namespace

std::unique_ptr<Sink> make_csv_sink(std::string path) {
  return std::make_unique<CsvSink>(std::move(path));
}
std::unique_ptr<Sink> make_energy_csv_sink(std::string path) {
  return std::make_unique<EnergyCsvSink>(std::move(path));
}
std::unique_ptr<Sink> make_fosssim_sink(std::string path) {
  return std::make_unique<FosssimSink>(std::move(path));
}

}  // namespace rbsim
