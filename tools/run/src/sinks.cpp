// CSV and FOSSSim-binary outputs of a run.
#include <bit>
#include <cstring>

#include "rbsim/atomic_file.hpp"
#include "rbsim/csv.hpp"
#include "rbsim/fosssim.hpp"
#include "rbsim/sink.hpp"

namespace rbsim {

namespace {

// The CSV sinks: one CsvWriter, rows appended after every step. A step's rows stay in the buffer
// until the next step's come (the earlier ones are written as the buffer fills), so a change of
// bodies at its boundary can write them again: a step's rows hold the world after its changes, as
// a recording read back does (rbsim/recording.hpp: of a step recorded again, the last).
class CsvSink : public Sink {
 public:
  CsvSink(std::string path, const char* columns) : path_(std::move(path)), columns_(columns) {}
  Status begin(const Scene&, const World& world) override {
    if (Status st = csv_.open(path_, columns_); !st) return st;
    return write(world);
  }
  Status write(const World& world) override {
    if (Status st = csv_.flush_if_full(); !st) return st;
    step_rows_ = csv_.rows().size();
    step_ = world.step_index();
    rows(world, csv_.rows());
    return Ok{};
  }
  Status finish() override { return csv_.commit(); }
  // Rows name bodies by id (World::body_id), so a changed world needs no new header: this step's
  // rows are written again with the bodies it now has, and later steps' hold them too. A world
  // loaded starts again at step 0 with other bodies: one CSV cannot hold two worlds.
  bool follows_structure() const override { return true; }
  Status restructure(const World& world, const Entities& entities) override {
    if (entities.world != 0) {
      return Error{path_ +
                   ": a CSV output cannot follow a world loaded during the run (its steps start "
                   "again at 0): record the run (--record) and export each world from it"};
    }
    // A reset: step 0's rows again after the step it left, as a reset's later steps follow it.
    if (world.step_index() != step_) return write(world);
    csv_.rows().resize(step_rows_);
    rows(world, csv_.rows());
    return Ok{};
  }

 private:
  virtual void rows(const World& world, std::string& out) const = 0;
  std::string path_;
  const char* columns_;
  CsvWriter csv_;
  std::size_t step_rows_ = 0;  // where the current step's rows start in the buffer
  std::int64_t step_ = 0;      // the step they are of
};

class BodyCsvSink final : public CsvSink {
 public:
  explicit BodyCsvSink(std::string path) : CsvSink(std::move(path), kBodyCsvColumns) {}

 private:
  void rows(const World& world, std::string& out) const override {
    const double t = world.time();
    for (std::int32_t b = 0; b < world.body_count(); ++b) {
      append_body_row(out, world.step_index(), t, world.body_id(BodyId{b}), world.state(BodyId{b}),
                      world.quantities(BodyId{b}));
    }
  }
};

class EnergyCsvSink final : public CsvSink {
 public:
  explicit EnergyCsvSink(std::string path) : CsvSink(std::move(path), kEnergyCsvColumns) {}

 private:
  void rows(const World& world, std::string& out) const override {
    append_energy_row(out, world.step_index(), world.time(), world.energy(), world.totals());
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
  return std::make_unique<BodyCsvSink>(std::move(path));
}
std::unique_ptr<Sink> make_energy_csv_sink(std::string path) {
  return std::make_unique<EnergyCsvSink>(std::move(path));
}
std::unique_ptr<Sink> make_fosssim_sink(std::string path) {
  return std::make_unique<FosssimSink>(std::move(path));
}

}  // namespace rbsim
