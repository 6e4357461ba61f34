// rbsim.run (the outputs of `rbsim run`, through the same driver and sinks), the recording reader
// behind rbsim.Recording (recordings::Recording's read_steps into NumPy columns), and rbsim.check
// (check::check_logs and its report).
#include <nanobind/ndarray.h>
#include <nanobind/stl/optional.h>
#include <nanobind/stl/string.h>
#include <nanobind/stl/vector.h>

#include <algorithm>
#include <limits>
#include <memory>
#include <optional>

#include "bindings.hpp"
#include "interrupt.hpp"
#include "rbsim/assert.hpp"
#include "rbsim/check.hpp"
#include "rbsim/csv.hpp"
#include "rbsim/export.hpp"
#include "rbsim/mcap_sink.hpp"
#include "rbsim/offline_run.hpp"
#include "rbsim/recording.hpp"
#include "rbsim/run.hpp"
#include "rbsim/sink.hpp"

namespace rbsim::python {

namespace {

using namespace nb::literals;

std::string optional_path(nb::handle path) {
  return path.is_none() ? std::string() : fs_path(path);
}

// ---------------------------------------------------------------------------------------------
// rbsim.run

struct RunArgs {
  std::string scene, csv, energy_csv, fosssim_out, record, commands;
  std::optional<std::int64_t> steps;
  std::optional<double> duration;
  std::int64_t record_every = 1;
  std::string compression = "zstd";
  int compression_level = 0;
  std::string ns = "rbsim";
  std::optional<std::vector<std::string>> topics;
  bool overwrite = false, allow_nonfinite = false;
};

recordings::McapSinkOptions record_options(const RunArgs& a) {
  recordings::McapSinkOptions ro;
  if (a.record_every < 1) throw nb::value_error("rbsim.run: record_every must be >= 1");
  ro.every = a.record_every;
  if (const std::string problem = msgs::ros_namespace_problem(a.ns); !problem.empty())
    throw nb::value_error(
        ("rbsim.run: namespace \"" + a.ns + "\" is not a ROS 2 namespace: it " + problem).c_str());
  ro.ns = a.ns[0] == '/' ? a.ns.substr(1) : a.ns;
  if (!mcap::parse_compression(a.compression, ro.compression))
    throw nb::value_error(("rbsim.run: unknown compression " + a.compression + " (zstd, lz4, none)").c_str());
  if (const std::string bad = mcap::check_compression_level(ro.compression, a.compression_level);
      !bad.empty())
    throw nb::value_error(("rbsim.run: compression_level: " + bad).c_str());
  ro.compression_level = a.compression_level;
  if (a.topics) {
    std::string list;
    for (const std::string& t : *a.topics) list += (list.empty() ? "" : ",") + t;
    Result<msgs::TopicSet> set = msgs::parse_topic_set(list, ro.ns);
    if (!set) throw nb::value_error(("rbsim.run: topics: " + set.error().message).c_str());
    ro.topics = set.value();
  }
  return ro;
}

// The outputs `rbsim run` would write with the same options (control::OfflineRun, as `rbsim run`
// runs), and the steps done.
std::int64_t run(const RunArgs& a) {
  Result<Scene> loaded = load_scene(a.scene);
  if (!loaded) raise_scene_error(a.scene, loaded.error().message);
  if (a.duration && !(*a.duration >= 0.0)) throw nb::value_error("rbsim.run: duration must be >= 0");
  if (a.steps && *a.steps < 0) throw nb::value_error("rbsim.run: steps must be >= 0");
  control::OfflineRunDef def;
  def.scene = a.scene;
  def.steps = a.steps;
  def.duration = a.duration;
  def.commands = a.commands;
  def.csv = {a.csv, "csv"};
  def.energy_csv = {a.energy_csv, "energy_csv"};
  def.fosssim_out = {a.fosssim_out, "fosssim_out"};
  def.record = {a.record, "record"};
  def.recording = record_options(a);
  def.overwrite = a.overwrite;
  def.overwrite_option = "overwrite=True";
  Result<std::unique_ptr<control::OfflineRun>> prepared =
      control::OfflineRun::prepare(def, std::move(loaded.value()));
  if (!prepared) raise_error(prepared.error().message);
  control::OfflineRun& offline = *prepared.value();

  InterruptPoll poll;
  Result<PassEnd> end = Error{""};
  {
    nb::gil_scoped_release unlocked;
    ScopedStop stop(poll);
    DriverOptions options;
    options.allow_nonfinite = a.allow_nonfinite;
    options.stop = &ScopedStop::requested;
    end = offline.run(options);
    if (end) {
      if (Status st = offline.finish(); !st) end = st.error();
    }
  }
  if (!end) raise_error(end.error().message);
  const std::int64_t done = offline.driver().world().step_index();
  if (end.value() == PassEnd::Diverged) {
    raise_divergence(describe_divergence(offline.driver().divergence()) + ". Outputs hold steps 0.." +
                     std::to_string(done - 1) + " (allow_nonfinite=True keeps going).");
  }
  if (Status st = offline.finish_commands(); !st) {
    std::string named;
    for (const std::string& m : offline.script()->mismatches()) named += "\n  " + m;
    raise_error(st.error().message + named + "; outputs hold the run");
  }
  if (end.value() == PassEnd::Stopped) raise_interrupt();
  return done;
}

// ---------------------------------------------------------------------------------------------
// rbsim.Recording: one topic at a time, as NumPy columns.

// A column filled while reading, handed to NumPy without a copy (the array owns the vector).
struct Column {
  std::string name;
  std::vector<double> values;
};

template <class T>
nb::object to_numpy(std::vector<T>&& values, std::size_t rows, std::size_t cols = 0) {
  auto* owned = new std::vector<T>(std::move(values));
  nb::capsule owner(owned, [](void* p) noexcept { delete static_cast<std::vector<T>*>(p); });
  if (cols == 0) return nb::cast(nb::ndarray<nb::numpy, T, nb::ndim<1>>(owned->data(), {rows}, owner));
  return nb::cast(nb::ndarray<nb::numpy, T, nb::ndim<2>>(owned->data(), {rows, cols}, owner));
}

msgs::TopicId topic_id(const std::string& topic) {
  if (topic == "body_states") return msgs::TopicId::BodyStates;
  if (topic == "spring_states") return msgs::TopicId::SpringStates;
  if (topic == "energy") return msgs::TopicId::Energy;
  throw nb::value_error(
      ("unknown per-step topic " + topic + " (body_states, spring_states, energy)").c_str());
}

std::unique_ptr<recordings::Recording> open_recording(const std::string& path, const std::string& ns,
                                                      std::vector<msgs::TopicId> read) {
  recordings::RecordingOptions o;
  o.ns = ns;
  o.require = read;
  o.read = std::move(read);
  Result<std::unique_ptr<recordings::Recording>> opened = recordings::Recording::open(path, o);
  if (!opened) raise_error(opened.error().message);
  return std::move(opened.value());
}

// The body (or spring) axis of a topic's columns: one column per id the recording holds, in
// increasing order (ids are never reused, and a world's arrays are in id order). A recording whose
// bodies never change has one set of ids in every row (0..n-1 for a scene's own): the rows are the
// matrix as read. After a spawn or delete, each value moves to its id's column, NaN where the id
// was not in the world at that step.
struct EntityAxis {
  std::vector<std::int32_t> ids;      // every row's ids, row after row, as read
  std::vector<std::size_t> row_ends;  // where each row's ids end in `ids`
  std::vector<std::int32_t> columns;  // the distinct ids, increasing

  void end_row() { row_ends.push_back(ids.size()); }

  std::size_t spread(std::size_t rows, std::vector<Column>& values) {
    RBSIM_ASSERT(row_ends.size() == rows, "one row of ids per step");
    columns = ids;
    std::sort(columns.begin(), columns.end());
    columns.erase(std::unique(columns.begin(), columns.end()), columns.end());
    const std::size_t width = columns.size();
    if (ids.size() == rows * width) return width;  // every row holds every id, in order
    for (Column& c : values) {
      std::vector<double> spread(rows * width, std::numeric_limits<double>::quiet_NaN());
      std::size_t k = 0;
      for (std::size_t row = 0; row < rows; ++row) {
        for (; k < row_ends[row]; ++k) {
          const auto at = std::lower_bound(columns.begin(), columns.end(), ids[k]) - columns.begin();
          spread[row * width + static_cast<std::size_t>(at)] = c.values[k];
        }
      }
      c.values = std::move(spread);
    }
    return width;
  }
};

// One recorded step's values of topic `id` appended to its columns (and its bodies' or springs'
// ids to `ids`).
void append_row(msgs::TopicId id, const recordings::RecordedStep& s, const msgs::SceneMessage& scene,
                std::vector<Column>& columns, std::vector<std::int32_t>& ids) {
  const auto put = [&columns](std::size_t column, double v) { columns[column].values.push_back(v); };
  if (id == msgs::TopicId::BodyStates) {
    for (const auto& b : s.body_states->bodies) {
      ids.push_back(b.id);
      put(0, b.state.position.x());
      put(1, b.state.position.y());
      put(2, b.state.theta);
      put(3, b.state.velocity.x());
      put(4, b.state.velocity.y());
      put(5, b.state.omega);
    }
  } else if (id == msgs::TopicId::SpringStates) {
    for (const auto& k : s.spring_states->springs) {
      ids.push_back(k.id);
      put(0, k.end_i.x());
      put(1, k.end_i.y());
      put(2, k.end_j.x());
      put(3, k.end_j.y());
      put(4, k.length);
      put(5, k.rest_length);
      put(6, k.potential);
    }
  } else {
    // The energy CSV's numbers: World::energy() as recorded, U, T and E by Energy's formulas.
    const Energy e =
        recordings::recorded_energy(s.scene != nullptr ? *s.scene : scene, *s.energy, s.body_states);
    put(0, e.potential());
    put(1, e.t_point);
    put(2, e.t_spin);
    put(3, e.kinetic());
    put(4, e.total());
    put(5, e.u_gravity);
    put(6, e.u_spring);
    put(7, s.energy->momentum.x());
    put(8, s.energy->momentum.y());
    put(9, s.energy->angular_momentum);
  }
}

// Per-step values of one topic: a row per recorded step, for each column one value per body or
// spring by id (EntityAxis; "id" names them) or one for scene-wide columns.
nb::dict read_topic(const std::string& path, const std::string& ns, const std::string& topic) {
  const msgs::TopicId id = topic_id(topic);
  std::unique_ptr<recordings::Recording> rec = open_recording(path, ns, {id});
  std::vector<std::int32_t> out_ids;
  if (id == msgs::TopicId::Energy) {
    // A recording made before the potential split, with several gravity fields: its U_gravity
    // comes from the body states (recordings::recorded_energy).
    for (const recordings::RecordedChannel& c : rec->channels()) {
      if (c.spec != nullptr && c.spec->id == id &&
          c.energy_version == msgs::EnergyTermsVersion::WithoutSplit && rec->scene()->gravity.size() > 1) {
        rec = open_recording(path, ns, {id, msgs::TopicId::BodyStates});
        break;
      }
    }
  }
  const msgs::SceneMessage& scene = *rec->scene();
  std::vector<Column> columns;
  const auto add = [&columns](std::initializer_list<const char*> names) {
    for (const char* n : names) columns.push_back({n, {}});
  };
  const bool per_entity = id != msgs::TopicId::Energy;
  if (id == msgs::TopicId::BodyStates) {
    add({"x", "y", "theta", "vx", "vy", "omega"});
  } else if (id == msgs::TopicId::SpringStates) {
    add({"end_i_x", "end_i_y", "end_j_x", "end_j_y", "length", "rest_length", "potential"});
  } else {
    add({"U", "T_point", "T_spin", "T", "E", "U_gravity", "U_spring", "px", "py", "L"});
  }
  std::uint64_t expected = 0;
  for (const recordings::RecordedChannel& c : rec->channels()) {
    if (c.spec != nullptr && c.spec->id == id && c.channel->topic == rec->topic(id))
      expected = c.message_count.value_or(0);
  }
  const std::size_t first_width = id == msgs::TopicId::BodyStates     ? scene.bodies.size()
                                  : id == msgs::TopicId::SpringStates ? scene.springs.size()
                                                                      : 1;
  std::vector<std::uint64_t> steps, segments;
  std::vector<double> t;  // World::time() of each step: step * its world's dt
  steps.reserve(expected);
  for (Column& c : columns) c.values.reserve(expected * std::max<std::size_t>(first_width, 1));
  EntityAxis axis;  // bodies or springs by id (a recording of a world whose bodies change)
  Status read;
  {
    nb::gil_scoped_release unlocked;
    read = rec->read_steps([&](const recordings::RecordedStep& s) -> Status {
      const void* message = id == msgs::TopicId::BodyStates     ? static_cast<const void*>(s.body_states)
                            : id == msgs::TopicId::SpringStates ? static_cast<const void*>(s.spring_states)
                                                                : static_cast<const void*>(s.energy);
      if (message == nullptr) return Ok{};  // a step only the other topic has (a lost message)
      steps.push_back(s.step);
      segments.push_back(s.segment);
      t.push_back(static_cast<double>(s.step) * (s.scene != nullptr ? s.scene->dt : scene.dt));
      append_row(id, s, scene, columns, axis.ids);
      if (per_entity) axis.end_row();
      return Ok{};
    });
  }
  if (!read) raise_error(read.error().message);
  const std::size_t rows = steps.size();
  std::size_t width = 0;
  if (per_entity) {
    width = axis.spread(rows, columns);
    out_ids = axis.columns;
  }
  nb::dict out;
  if (per_entity) out["id"] = to_numpy(std::move(out_ids), width);
  out["step"] = to_numpy(std::move(steps), rows);
  out["segment"] = to_numpy(std::move(segments), rows);
  out["t"] = to_numpy(std::move(t), rows);
  for (Column& c : columns) out[c.name.c_str()] = to_numpy(std::move(c.values), rows, width);
  return out;
}

// What rbsim.Recording shows before any topic is read: the scene description and the topics.
nb::dict recording_info(const std::string& path, const std::string& ns) {
  std::unique_ptr<recordings::Recording> rec = open_recording(path, ns, {});
  const msgs::SceneMessage& s = *rec->scene();
  nb::dict scene;
  scene["name"] = s.name;
  scene["description"] = s.description;
  scene["integrator"] = s.integrator;
  scene["dt"] = s.dt;
  scene["duration"] = s.duration;
  scene["steps"] = s.step_count;
  scene["body_count"] = s.bodies.size();
  scene["spring_count"] = s.springs.size();
  std::vector<double> mass, inertia, radius;
  for (const auto& b : s.bodies) {
    mass.push_back(b.mass);
    inertia.push_back(b.inertia);
    radius.push_back(b.radius);
  }
  const std::size_t n = s.bodies.size();
  scene["mass"] = to_numpy(std::move(mass), n);
  scene["inertia"] = to_numpy(std::move(inertia), n);
  scene["radius"] = to_numpy(std::move(radius), n);
  nb::list topics;
  for (const recordings::RecordedChannel& c : rec->channels()) topics.append(c.channel->topic);
  nb::dict per_step;
  for (const msgs::TopicId id :
       {msgs::TopicId::BodyStates, msgs::TopicId::SpringStates, msgs::TopicId::Energy})
    per_step[std::string(msgs::topics()[static_cast<std::size_t>(id)].suffix).c_str()] = rec->topic(id);
  nb::dict out;
  out["scene"] = scene;
  out["topics"] = topics;
  out["per_step"] = per_step;
  return out;
}

// ---------------------------------------------------------------------------------------------
// rbsim.check

struct PyCheck {
  check::CheckReport report;
  std::string text;
};

nb::object first_difference(const PyCheck& c) {
  if (!c.report.first) return nb::none();
  const check::FirstDifference& f = *c.report.first;
  nb::dict d;
  d["topic"] = f.topic;
  d["step"] = f.has_step ? nb::cast(f.step) : nb::none();
  d["message_index"] = f.has_step ? nb::none() : nb::cast(f.step);
  d["field"] = f.field;
  d["expected"] = f.expected;
  d["actual"] = f.actual;
  d["difference"] = f.difference;
  d["line"] = f.line();
  return d;
}

nb::list field_table(const PyCheck& c) {
  nb::list rows;
  for (const check::FieldStats& s : c.report.fields) {
    nb::dict d;
    d["topic"] = s.topic;
    d["field"] = s.field;
    d["kind"] = s.kind;
    d["values"] = s.values;
    d["over"] = s.over;
    d["max_abs"] = s.max_abs;
    d["max_rel"] = s.max_rel;
    d["step_at_max"] = s.has_step ? nb::cast(s.step_at_max) : nb::none();
    rows.append(d);
  }
  return rows;
}

PyCheck run_check(nb::handle run_path, nb::handle golden_path, double atol, double rtol,
                  std::vector<std::string> topics, std::vector<std::string> exclude_topics) {
  const std::string a = fs_path(run_path), b = fs_path(golden_path);
  if (!(atol >= 0.0) || !(rtol >= 0.0)) throw nb::value_error("rbsim.check: atol and rtol must be >= 0");
  check::CheckOptions o;
  o.atol = atol;
  o.rtol = rtol;
  o.topics = std::move(topics);
  o.exclude_topics = std::move(exclude_topics);
  Result<check::CheckReport> report = Error{""};
  {
    nb::gil_scoped_release unlocked;
    report = check::check_logs(a, b, o);
  }
  if (!report) raise_error(report.error().message);
  PyCheck out{std::move(report.value()), {}};
  out.text = check::format_report(a, b, o, out.report);
  return out;
}

}  // namespace

void bind_data(nb::module_& m) {
  m.def(
      "_run",
      [](nb::handle scene, std::optional<std::int64_t> steps, std::optional<double> duration, nb::handle csv,
         nb::handle energy_csv, nb::handle fosssim_out, nb::handle record, std::int64_t record_every,
         std::string compression, int compression_level, std::string ns,
         std::optional<std::vector<std::string>> topics, nb::handle commands, bool overwrite,
         bool allow_nonfinite) {
        RunArgs a;
        a.scene = fs_path(scene);
        a.steps = steps;
        a.duration = duration;
        a.csv = optional_path(csv);
        a.energy_csv = optional_path(energy_csv);
        a.fosssim_out = optional_path(fosssim_out);
        a.record = optional_path(record);
        a.commands = optional_path(commands);
        a.record_every = record_every;
        a.compression = std::move(compression);
        a.compression_level = compression_level;
        a.ns = std::move(ns);
        a.topics = std::move(topics);
        a.overwrite = overwrite;
        a.allow_nonfinite = allow_nonfinite;
        return run(a);
      },
      "scene"_a, "steps"_a.none(), "duration"_a.none(), "csv"_a.none(), "energy_csv"_a.none(),
      "fosssim_out"_a.none(), "record"_a.none(), "record_every"_a, "compression"_a, "compression_level"_a,
      "namespace"_a, "topics"_a.none(), "commands"_a.none(), "overwrite"_a, "allow_nonfinite"_a);
  m.def("_read_topic", &read_topic, "path"_a, "namespace"_a, "topic"_a);
  m.def("_recording_info", &recording_info, "path"_a, "namespace"_a);

  nb::class_<PyCheck>(m, "CheckResult",
                      "The outcome of rbsim.check: falsy on a divergence. `report` is the text `rbsim check` "
                      "prints; `first` and `fields` are the same report as data.")
      .def_prop_ro("passed", [](const PyCheck& c) { return c.report.passed(); })
      .def("__bool__", [](const PyCheck& c) { return c.report.passed(); })
      .def_prop_ro(
          "report", [](const PyCheck& c) { return c.text; }, "The report `rbsim check` prints.")
      .def_prop_ro("first", &first_difference,
                   "The first divergence (topic, step, field, expected, actual, difference, line), or None.")
      .def_prop_ro("fields", &field_table,
                   "Per topic and field: values compared, over the tolerance, max_abs, "
                   "max_rel, step_at_max.")
      .def_prop_ro("diverging_values", [](const PyCheck& c) { return c.report.diverging_values; })
      .def_prop_ro(
          "messages", [](const PyCheck& c) { return c.report.messages; }, "Message pairs compared.")
      .def_prop_ro("topics", [](const PyCheck& c) { return c.report.topics; })
      .def_prop_ro(
          "problems",
          [](const PyCheck& c) {
            std::vector<std::string> all;
            if (!c.report.scene_mismatch.empty()) all.push_back(c.report.scene_mismatch);
            all.insert(all.end(), c.report.topic_problems.begin(), c.report.topic_problems.end());
            all.insert(all.end(), c.report.step_problems.begin(), c.report.step_problems.end());
            return all;
          },
          "Scene, topic and step problems, one line each.")
      .def("__str__", [](const PyCheck& c) { return c.text; })
      .def("__repr__", [](const PyCheck& c) {
        return c.report.passed() ? std::string("<rbsim.CheckResult: match>")
                                 : "<rbsim.CheckResult: " + c.report.first->line() + ">";
      });
  m.def("check", &run_check, "run"_a, "golden"_a, nb::kw_only(), "atol"_a = 0.0, "rtol"_a = 0.0,
        "topics"_a = std::vector<std::string>{}, "exclude_topics"_a = std::vector<std::string>{},
        "Compares a recording (file or bag directory) with a golden one as `rbsim check` does: bit-exact by "
        "default, |actual - expected| <= atol + rtol |expected| otherwise; topics limits the comparison. "
        "Returns a CheckResult, falsy on a divergence. Raises rbsim.Error when an input cannot be read.");
}

}  // namespace rbsim::python
