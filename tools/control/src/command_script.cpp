// Command scripts (rbsim/command_script.hpp): YAML entries -> Commands, checked before step 0.
#include "rbsim/command_script.hpp"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <memory>
#include <optional>
#include <utility>

#include "rbsim/read_file.hpp"
#include "yaml_value.hpp"

namespace rbsim::control {

namespace {

constexpr const char* kActions =
    "set, impulse, set_entity_state, pause, resume, steps, stop_stepping, reset, spawn, delete or "
    "reset_spawned";

// The entry being read: its place in the file for every message.
struct Entry {
  const std::string& path;
  const YAML::Node& node;

  Error error(const YAML::Node& at, const std::string& field, const std::string& rule) const {
    return Error{yaml_line(path, at) + ": " + field + ": " + rule, ErrorCode::InvalidArgument};
  }
};

std::optional<double> number(const YAML::Node& n) {
  if (!n.IsScalar()) return std::nullopt;
  const ParameterValue v = yaml_scalar(n);
  if (v.type == ParameterType::Double) return v.double_value;
  if (v.type == ParameterType::Integer) return static_cast<double>(v.integer_value);
  return std::nullopt;
}

std::optional<std::int64_t> integer(const YAML::Node& n) {
  if (!n.IsScalar()) return std::nullopt;
  const ParameterValue v = yaml_scalar(n);
  if (v.type != ParameterType::Integer) return std::nullopt;
  return v.integer_value;
}

// [x, y], two finite numbers.
Result<Vec2> vector(const Entry& e, const YAML::Node& n, const std::string& field) {
  if (!n.IsSequence() || n.size() != 2) return e.error(n, field, "must be [x, y]");
  const std::optional<double> x = number(n[0]), y = number(n[1]);
  if (!x || !y || !std::isfinite(*x) || !std::isfinite(*y))
    return e.error(n, field, "must be two finite numbers");
  return Vec2{*x, *y};
}

// The boundary an entry names: `step: N` or `t: SECONDS`, exactly one.
Result<std::int64_t> boundary(const Entry& e, double dt, std::int64_t steps) {
  const YAML::Node step = e.node["step"], t = e.node["t"];
  if (step && t) return e.error(t, "t", "give step or t, not both");
  if (!step && !t) return e.error(e.node, "step", "each entry needs step: N or t: SECONDS");
  std::int64_t k = 0;
  if (step) {
    const std::optional<std::int64_t> v = integer(step);
    if (!v) return e.error(step, "step", "must be an integer");
    k = *v;
  } else {
    const std::optional<double> v = number(t);
    if (!v || !std::isfinite(*v) || *v < 0.0)
      return e.error(t, "t", "must be a finite number of seconds >= 0");
    k = steps_for(*v, dt);
  }
  // A command at boundary k acts on the steps after k: the last step has none after it.
  if (k < 0 || k >= steps) {
    return e.error(step ? step : t, step ? "step" : "t",
                   "step " + std::to_string(k) +
                       " is outside the run (a command at step k acts on the steps after "
                       "it: k in 0.." +
                       std::to_string(steps - 1) + ")");
  }
  return k;
}

// Nested maps joined with '.' ({forces: {0: {fy: -3.7}}} is forces.0.fy), as parameters files.
Status parameters(const Entry& e, const YAML::Node& map, const std::string& prefix,
                  const ParameterTable& table, std::vector<Parameter>& out) {
  for (const auto& kv : map) {
    const std::string name = prefix.empty() ? kv.first.Scalar() : prefix + "." + kv.first.Scalar();
    if (kv.second.IsMap()) {
      if (Status st = parameters(e, kv.second, name, table, out); !st) return st;
      continue;
    }
    Result<ParameterValue> value = yaml_value(kv.second);
    if (!value)
      return e.error(kv.second.IsNull() ? kv.first : kv.second, "set." + name, value.error().message);
    Parameter p{name, std::move(value.value())};
    if (SetParametersResult r = table.check(p); !r.successful) {
      return e.error(kv.second, "set." + name, r.reason);
    }
    out.push_back(std::move(p));
  }
  return Ok{};
}

Status impulse(const Entry& e, const YAML::Node& n, std::int64_t bodies, ImpulseArgs& out) {
  if (!n.IsMap()) return e.error(n, "impulse", "must be a map {body: I, j: [x, y], p: [x, y]}");
  for (const auto& kv : n) {
    const std::string key = kv.first.Scalar();
    if (key != "body" && key != "j" && key != "p") {
      return e.error(kv.first, "impulse." + key, "unknown field (want body, j and optionally p)");
    }
  }
  const YAML::Node body = n["body"], j = n["j"], p = n["p"];
  if (!body) return e.error(n, "impulse.body", "missing");
  const std::optional<std::int64_t> b = integer(body);
  if (!b || *b < 0 || *b >= bodies) {
    return e.error(body, "impulse.body", "must be a body index in [0, " + std::to_string(bodies) + ")");
  }
  if (!j) return e.error(n, "impulse.j", "missing");
  Result<Vec2> jv = vector(e, j, "impulse.j");
  if (!jv) return jv.error();
  Vec2 pv{0.0, 0.0};
  if (p) {
    Result<Vec2> read = vector(e, p, "impulse.p");
    if (!read) return read.error();
    pv = read.value();
  }
  out = ImpulseArgs{*b, jv.value(), pv};
  return Ok{};
}

// {body: I, x: [x, y], theta: T, v: [vx, vy], omega: W}: the pose (x and theta) and/or the
// twist (v and omega), each pair whole, as StateArgs sets them.
Status set_entity_state(const Entry& e, const YAML::Node& n, std::int64_t bodies, StateArgs& out) {
  const std::string rule = "must be a map {body: I, x: [x, y], theta: T, v: [vx, vy], omega: W}";
  if (!n.IsMap()) return e.error(n, "set_entity_state", rule);
  for (const auto& kv : n) {
    const std::string key = kv.first.Scalar();
    if (key != "body" && key != "x" && key != "theta" && key != "v" && key != "omega") {
      return e.error(kv.first, "set_entity_state." + key,
                     "unknown field (want body, x and theta, v and omega)");
    }
  }
  const YAML::Node body = n["body"];
  if (!body) return e.error(n, "set_entity_state.body", "missing");
  const std::optional<std::int64_t> b = integer(body);
  if (!b || *b < 0 || *b >= bodies) {
    return e.error(body, "set_entity_state.body",
                   "must be a body index in [0, " + std::to_string(bodies) + ")");
  }
  StateArgs s;
  s.body = *b;
  // One pair: both fields or neither; `vector_field` is [x, y], `scalar_field` a finite number.
  const auto pair = [&](const char* vector_field, const char* scalar_field, bool& set, Vec2& v,
                        double& a) -> Status {
    const YAML::Node vn = n[vector_field], an = n[scalar_field];
    if (!vn && !an) return Ok{};
    const std::string both = std::string("give ") + vector_field + " and " + scalar_field + " together";
    if (!vn) return e.error(n, std::string("set_entity_state.") + vector_field, "missing (" + both + ")");
    if (!an) return e.error(n, std::string("set_entity_state.") + scalar_field, "missing (" + both + ")");
    Result<Vec2> read = vector(e, vn, std::string("set_entity_state.") + vector_field);
    if (!read) return read.error();
    const std::optional<double> value = number(an);
    if (!value || !std::isfinite(*value))
      return e.error(an, std::string("set_entity_state.") + scalar_field, "must be a finite number");
    set = true;
    v = read.value();
    a = *value;
    return Ok{};
  };
  if (Status st = pair("x", "theta", s.set_pose, s.position, s.theta); !st) return st;
  if (Status st = pair("v", "omega", s.set_twist, s.velocity, s.omega); !st) return st;
  if (!s.set_pose && !s.set_twist)
    return e.error(n, "set_entity_state", "sets nothing: give x and theta, v and omega, or both");
  out = s;
  return Ok{};
}

// spawn: {file: FRAGMENT | resource: TEXT, name: NAME, x: [X, Y], theta: RAD, allow_renaming: BOOL};
// a file is read now (relative to the script's folder) and its text kept in the command, so the
// run, and its recording, depend on no file after this.
Status spawn(const Entry& e, const YAML::Node& n, SpawnArgs& out) {
  if (!n.IsMap())
    return e.error(n, "spawn", "must be a map {file: FRAGMENT or resource: TEXT, name, x, theta}");
  for (const auto& kv : n) {
    const std::string key = kv.first.Scalar();
    if (key != "file" && key != "resource" && key != "name" && key != "x" && key != "theta" &&
        key != "allow_renaming") {
      return e.error(kv.first, "spawn." + key,
                     "unknown field (want file or resource, name, x, theta, allow_renaming)");
    }
  }
  SpawnArgs a;
  const YAML::Node file = n["file"], resource = n["resource"];
  if ((file && resource) || (!file && !resource))
    return e.error(n, "spawn", "give file or resource, one of them");
  if (file) {
    if (!file.IsScalar() || file.Scalar().empty()) return e.error(file, "spawn.file", "must be a path");
    std::filesystem::path where(file.Scalar());
    if (where.is_relative()) where = std::filesystem::path(e.path).parent_path() / where;
    Result<std::string> text = read_text_file(where.string(), "the fragment");
    if (!text) return e.error(file, "spawn.file", text.error().message);
    a.resource = std::move(text.value());
    a.uri = where.string();
  } else {
    if (!resource.IsScalar()) return e.error(resource, "spawn.resource", "must be the fragment's XML text");
    a.resource = resource.Scalar();
  }
  if (const YAML::Node name = n["name"]) {
    if (!name.IsScalar()) return e.error(name, "spawn.name", "must be a name");
    a.name = name.Scalar();
  }
  if (const YAML::Node x = n["x"]) {
    Result<Vec2> read = vector(e, x, "spawn.x");
    if (!read) return read.error();
    a.position = read.value();
  }
  if (const YAML::Node theta = n["theta"]) {
    const std::optional<double> value = number(theta);
    if (!value || !std::isfinite(*value)) return e.error(theta, "spawn.theta", "must be a finite number");
    a.theta = *value;
  }
  if (const YAML::Node renaming = n["allow_renaming"]) {
    const ParameterValue v = renaming.IsScalar() ? yaml_scalar(renaming) : ParameterValue{};
    if (v.type != ParameterType::Bool)
      return e.error(renaming, "spawn.allow_renaming", "must be true or false");
    a.allow_renaming = v.bool_value;
  }
  // The fragment is checked now: its errors name the file (or the script) and line.
  Result<Fragment> parsed = parse_fragment(a.resource, a.uri.empty() ? yaml_line(e.path, resource) : a.uri);
  if (!parsed)
    return e.error(file ? file : resource, file ? "spawn.file" : "spawn.resource", parsed.error().message);
  a.fragment = std::make_shared<const Fragment>(std::move(parsed.value()));
  out = std::move(a);
  return Ok{};
}

bool is_true(const YAML::Node& n) {
  if (!n.IsScalar()) return false;
  const ParameterValue v = yaml_scalar(n);
  return v.type == ParameterType::Bool && v.bool_value;
}

// The entry's one action into `c`.
Status action(const Entry& e, const ParameterTable& table, std::int64_t bodies, Command& c) {
  std::optional<std::string> name;
  for (const auto& kv : e.node) {
    const std::string key = kv.first.Scalar();
    if (key == "step" || key == "t") continue;
    if (key != "set" && key != "impulse" && key != "set_entity_state" && key != "pause" && key != "resume" &&
        key != "steps" && key != "stop_stepping" && key != "reset" && key != "spawn" && key != "delete" &&
        key != "reset_spawned") {
      return e.error(kv.first, key,
                     std::string("unknown field (want step or t, and one of ") + kActions + ")");
    }
    if (name) return e.error(kv.first, key, "one action per entry (this one also has " + *name + ")");
    name = key;
  }
  if (!name) return e.error(e.node, "action", std::string("missing: one of ") + kActions);
  const YAML::Node v = e.node[*name];
  if (*name == "set") {
    if (!v.IsMap() || v.size() == 0) return e.error(v, "set", "must be a map of parameters {NAME: VALUE}");
    c.kind = CommandKind::SetParameters;
    c.atomic = true;
    return parameters(e, v, "", table, c.parameters);
  }
  if (*name == "impulse") {
    c.kind = CommandKind::Impulse;
    return impulse(e, v, bodies, c.impulse);
  }
  if (*name == "set_entity_state") {
    c.kind = CommandKind::SetState;
    return set_entity_state(e, v, bodies, c.state);
  }
  if (*name == "spawn") {
    c.kind = CommandKind::Spawn;
    return spawn(e, v, c.spawn);
  }
  if (*name == "delete") {
    if (!v.IsScalar() || v.Scalar().empty()) return e.error(v, "delete", "must be the name of a body");
    c.kind = CommandKind::Delete;
    c.entity = v.Scalar();
    return Ok{};
  }
  if (*name == "steps") {
    const std::optional<std::int64_t> n = integer(v);
    if (!n || *n < 1) return e.error(v, "steps", "must be an integer >= 1");
    c.kind = CommandKind::Step;
    c.steps = *n;
    return Ok{};
  }
  if (*name == "pause") {
    c.kind = CommandKind::Pause;
    if (is_true(v)) return Ok{};
    const std::optional<double> s = number(v);
    if (!s || !std::isfinite(*s) || *s <= 0.0) {
      return e.error(v, "pause", "must be true (until a resume) or wall-clock seconds > 0");
    }
    c.pause_seconds = *s;
    return Ok{};
  }
  if (!is_true(v)) return e.error(v, *name, "must be true");
  c.kind = *name == "resume"          ? CommandKind::Resume
           : *name == "stop_stepping" ? CommandKind::StopStepping
           : *name == "reset_spawned" ? CommandKind::ResetSpawned
                                      : CommandKind::Reset;
  return Ok{};
}

// An offline run has no one to resume it: walks the commands in the order they apply, as the
// Controller does, with the last step a pause can reach (its step plus the `steps` given while it
// holds). A command past that step, or a pause no resume ends, would leave the run paused for ever.
Status check_pauses(const std::vector<Command>& commands, const std::vector<YAML::Node>& nodes,
                    const std::string& path) {
  std::vector<std::size_t> order(commands.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(),
                   [&](std::size_t a, std::size_t b) { return commands[a].step < commands[b].step; });
  std::optional<std::size_t> open;  // the pause: true in effect
  std::int64_t reach = 0;           // the last step the run reaches while it holds
  const auto stuck = [&]() {
    return Entry{path, nodes[*open]}.error(
        nodes[*open], "pause",
        "no resume follows at or before step " + std::to_string(reach) +
            ", where the run would stay paused for ever (add a resume entry, "
            "or pause for SECONDS of wall time)");
  };
  for (std::size_t i : order) {
    const Command& c = commands[i];
    if (open && c.step > reach) return stuck();
    if (c.kind == CommandKind::Pause && c.pause_seconds == 0.0 && !open) {
      open = i;
      reach = c.step;
    }
    if (c.kind == CommandKind::Resume) open.reset();
    if (c.kind == CommandKind::Step) {
      if (!open) {
        return Entry{path, nodes[i]}.error(
            nodes[i], "steps", "only while paused (a pause: true at or before this step, not resumed)");
      }
      reach += c.steps;
    }
    if (c.kind == CommandKind::StopStepping && open) reach = c.step;  // the steps still to take are dropped
    if (c.kind == CommandKind::Reset && open) reach = 0;  // a reset keeps the run paused, at step 0
  }
  if (open) return stuck();
  return Ok{};
}

}  // namespace

Result<std::vector<Command>> parse_command_script(std::string_view text, const std::string& path,
                                                  const Scene& scene, std::int64_t steps) {
  const ParameterTable table(scene, steps, RunSettings{});
  const auto bodies = static_cast<std::int64_t>(scene.world.bodies.size());
  std::vector<Command> out;
  std::vector<YAML::Node> nodes;
  try {
    const YAML::Node root = YAML::Load(std::string(text));
    if (root.IsNull()) return out;  // an empty script: no commands
    if (!root.IsSequence()) {
      return Error{yaml_line(path, root) + ": expected a list of commands (- {step: N, set: {...}})",
                   ErrorCode::InvalidArgument};
    }
    for (const YAML::Node& node : root) {
      const Entry e{path, node};
      if (!node.IsMap()) return e.error(node, "entry", "must be a map ({step: N, ACTION: ...})");
      Command c;
      Result<std::int64_t> k = boundary(e, scene.world.dt, steps);
      if (!k) return k.error();
      c.step = k.value();
      if (Status st = action(e, table, bodies, c); !st) return st.error();
      c.source = "script " + yaml_line(path, node);
      out.push_back(std::move(c));
      nodes.push_back(node);
    }
  } catch (const YAML::Exception& e) {
    return Error{path + ":" + std::to_string(e.mark.line + 1) + ": not valid YAML: " + e.msg,
                 ErrorCode::InvalidArgument};
  }
  if (Status st = check_pauses(out, nodes, path); !st) return st.error();
  return out;
}

Result<std::vector<Command>> load_command_script(const std::string& path, const Scene& scene,
                                                 std::int64_t steps) {
  Result<std::string> text = read_text_file(path, "the commands file");
  if (!text) return text.error();
  return parse_command_script(text.value(), path, scene, steps);
}

}  // namespace rbsim::control
