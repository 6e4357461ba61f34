// The CSV columns, rows and files shared by the run's sinks and rbsim log export.
#include "rbsim/csv.hpp"

#include <charconv>

namespace rbsim {

namespace {
constexpr std::size_t kBlock = 1 << 20;  // rows buffered before a write
}  // namespace

void append_int(std::string& out, std::int64_t v) {
  char buf[24];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  out.append(buf, ec == std::errc() ? end : buf);
}

void append_double(std::string& out, double v) {
  char buf[32];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);  // shortest round-trip form
  out.append(buf, ec == std::errc() ? end : buf);
}

void append_body_row(std::string& out, std::int64_t step, double t, std::int32_t body, const BodyState& s,
                     const BodyQuantities& q) {
  append_int(out, step);
  out += ',';
  append_double(out, t);
  out += ',';
  append_int(out, body);
  for (double v : {s.position.x(), s.position.y(), s.theta, s.velocity.x(), s.velocity.y(), s.omega,
                   q.momentum.x(), q.momentum.y(), q.l_point, q.l_spin, q.t_point, q.t_spin}) {
    out += ',';
    append_double(out, v);
  }
  out += '\n';
}

void append_energy_row(std::string& out, std::int64_t step, double t, const Energy& e,
                       const SceneTotals& totals) {
  append_int(out, step);
  for (double v : {t, e.potential(), e.t_point, e.t_spin, e.kinetic(), e.total(), e.u_gravity, e.u_spring,
                   totals.momentum.x(), totals.momentum.y(), totals.angular}) {
    out += ',';
    append_double(out, v);
  }
  out += '\n';
}

Status CsvWriter::open(const std::string& path, std::string_view columns) {
  if (Status st = file_.open(path); !st) return st;
  open_ = true;
  buffer_.reserve(kBlock + 4096);
  buffer_.assign(columns);
  buffer_ += '\n';
  return Ok{};
}

Status CsvWriter::flush_if_full() {
  return buffer_.size() >= kBlock ? flush() : Status(Ok{});
}

Status CsvWriter::commit() {
  if (!open_) return Ok{};
  if (Status st = flush(); !st) return st;
  return file_.commit();
}

Status CsvWriter::flush() {
  Status st = file_.write(buffer_.data(), buffer_.size());
  buffer_.clear();
  return st;
}

}  // namespace rbsim
