// Commands as rbsim_msgs/msg/Command (rbsim/control.hpp): what the node publishes on
// /<ns>/commands and a re-simulation reads back.
#include <algorithm>
#include <initializer_list>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

#include "rbsim/control.hpp"

namespace rbsim::control {

namespace {

// CommandKind and the message's constants are one list in the same order (Command.msg).
static_assert(static_cast<int>(CommandKind::SetParameters) == msgs::CommandMessage::SetParameters);
static_assert(static_cast<int>(CommandKind::Pause) == msgs::CommandMessage::Pause);
static_assert(static_cast<int>(CommandKind::Resume) == msgs::CommandMessage::Resume);
static_assert(static_cast<int>(CommandKind::Step) == msgs::CommandMessage::Step);
static_assert(static_cast<int>(CommandKind::Reset) == msgs::CommandMessage::Reset);
static_assert(static_cast<int>(CommandKind::Impulse) == msgs::CommandMessage::ApplyImpulse);
static_assert(static_cast<int>(CommandKind::SetState) == msgs::CommandMessage::SetEntityState);
static_assert(static_cast<int>(CommandKind::StopStepping) == msgs::CommandMessage::StopStepping);
static_assert(static_cast<int>(CommandKind::Spawn) == msgs::CommandMessage::SpawnEntity);
static_assert(static_cast<int>(CommandKind::Delete) == msgs::CommandMessage::DeleteEntity);
static_assert(static_cast<int>(CommandKind::ResetSpawned) == msgs::CommandMessage::ResetSpawned);
static_assert(static_cast<int>(CommandKind::LoadWorld) == msgs::CommandMessage::LoadWorld);
static_assert(static_cast<int>(CommandKind::UnloadWorld) == msgs::CommandMessage::UnloadWorld);

// SetEntityState's values travel as named float64 parameters (the message's layout predates the
// kind, and recordings made before it stay readable): x, y, theta for a pose, vx, vy, omega for a
// twist, each group whole or absent.
constexpr const char* kPoseNames[] = {"x", "y", "theta"};
constexpr const char* kTwistNames[] = {"vx", "vy", "omega"};

std::vector<Parameter> state_parameters(const StateArgs& a) {
  std::vector<Parameter> out;
  const auto put = [&](const char* const(&names)[3], double v0, double v1, double v2) {
    const double values[] = {v0, v1, v2};
    for (int k = 0; k < 3; ++k) out.push_back({names[k], ParameterValue::of_double(values[k])});
  };
  if (a.set_pose) put(kPoseNames, a.position.x(), a.position.y(), a.theta);
  if (a.set_twist) put(kTwistNames, a.velocity.x(), a.velocity.y(), a.omega);
  return out;
}

Status state_args(const std::vector<Parameter>& parameters, const std::string& which, StateArgs& a) {
  double pose[3] = {0, 0, 0}, twist[3] = {0, 0, 0};
  int pose_n = 0, twist_n = 0;
  for (const Parameter& p : parameters) {
    if (p.value.type != ParameterType::Double) {
      return Error{which + ": set_entity_state parameter '" + p.name + "' is not a double",
                   ErrorCode::Malformed};
    }
    bool known = false;
    for (int k = 0; k < 3; ++k) {
      if (p.name == kPoseNames[k]) pose[k] = p.value.double_value, ++pose_n, known = true;
      if (p.name == kTwistNames[k]) twist[k] = p.value.double_value, ++twist_n, known = true;
    }
    if (!known) {
      return Error{
          which + ": set_entity_state parameter '" + p.name + "' is none of x, y, theta, vx, vy, omega",
          ErrorCode::Malformed};
    }
  }
  if ((pose_n != 0 && pose_n != 3) || (twist_n != 0 && twist_n != 3)) {
    return Error{which + ": set_entity_state needs x, y and theta together, and vx, vy and omega together",
                 ErrorCode::Malformed};
  }
  a.set_pose = pose_n == 3;
  a.set_twist = twist_n == 3;
  a.position = Vec2(pose[0], pose[1]);
  a.theta = pose[2];
  a.velocity = Vec2(twist[0], twist[1]);
  a.omega = twist[2];
  return Ok{};
}

// spawn_entity's and delete_entity's arguments as named parameters (see interfaces.hpp).
std::vector<Parameter> spawn_parameters(const SpawnArgs& a) {
  return {{"resource", ParameterValue::of_string(a.resource)},
          {"uri", ParameterValue::of_string(a.uri)},
          {"name", ParameterValue::of_string(a.name)},
          {"allow_renaming", ParameterValue::of_bool(a.allow_renaming)},
          {"x", ParameterValue::of_double(a.position.x())},
          {"y", ParameterValue::of_double(a.position.y())},
          {"theta", ParameterValue::of_double(a.theta)}};
}

// Each named parameter exactly once with its type: anything else is a malformed record.
class NamedParameters {
 public:
  NamedParameters(const std::vector<Parameter>& parameters, std::string which)
      : parameters_(parameters), which_(std::move(which)) {}
  Status take(const char* name, ParameterType type, ParameterValue& out) const {
    const Parameter* found = nullptr;
    for (const Parameter& p : parameters_) {
      if (p.name != name) continue;
      if (found != nullptr)
        return Error{which_ + ": parameter '" + name + "' given twice", ErrorCode::Malformed};
      found = &p;
    }
    if (found == nullptr) return Error{which_ + ": parameter '" + name + "' missing", ErrorCode::Malformed};
    if (found->value.type != type) {
      return Error{which_ + ": parameter '" + std::string(name) + "' is not a " + to_string(type),
                   ErrorCode::Malformed};
    }
    out = found->value;
    return Ok{};
  }
  Status only(std::initializer_list<const char*> names) const {
    for (const Parameter& p : parameters_) {
      if (std::none_of(names.begin(), names.end(), [&](const char* n) { return p.name == n; }))
        return Error{which_ + ": unknown parameter '" + p.name + "'", ErrorCode::Malformed};
    }
    return Ok{};
  }

 private:
  const std::vector<Parameter>& parameters_;
  std::string which_;
};

Status spawn_args(const std::vector<Parameter>& parameters, const std::string& which, SpawnArgs& a) {
  const NamedParameters named(parameters, which + ": spawn_entity");
  ParameterValue resource, uri, name, renaming, x, y, theta;
  for (auto [key, type, out] : {std::tuple{"resource", ParameterType::String, &resource},
                                {"uri", ParameterType::String, &uri},
                                {"name", ParameterType::String, &name},
                                {"allow_renaming", ParameterType::Bool, &renaming},
                                {"x", ParameterType::Double, &x},
                                {"y", ParameterType::Double, &y},
                                {"theta", ParameterType::Double, &theta}}) {
    if (Status st = named.take(key, type, *out); !st) return st;
  }
  if (Status st = named.only({"resource", "uri", "name", "allow_renaming", "x", "y", "theta"}); !st)
    return st;
  a.resource = resource.string_value;
  a.uri = uri.string_value;
  a.name = name.string_value;
  a.allow_renaming = renaming.bool_value;
  a.position = Vec2(x.double_value, y.double_value);
  a.theta = theta.double_value;
  return Ok{};
}

// load_world's: the scene's text and where it came from.
Status world_args(const std::vector<Parameter>& parameters, const std::string& which, WorldArgs& a) {
  const NamedParameters named(parameters, which + ": load_world");
  ParameterValue resource, uri;
  if (Status st = named.take("resource", ParameterType::String, resource); !st) return st;
  if (Status st = named.take("uri", ParameterType::String, uri); !st) return st;
  if (Status st = named.only({"resource", "uri"}); !st) return st;
  a.resource = resource.string_value;
  a.uri = uri.string_value;
  return Ok{};
}

}  // namespace

msgs::CommandMessage to_message(const Command& command, const CommandResult& result, std::uint64_t sequence,
                                double dt) {
  msgs::CommandMessage m;
  m.seq = sequence;
  const std::int64_t step = result.step >= 0 ? result.step : 0;
  m.step = static_cast<std::uint64_t>(step);
  m.stamp = msgs::sim_time(step, dt);
  m.kind = static_cast<std::uint8_t>(command.kind);
  m.source = command.source;
  switch (command.kind) {
    case CommandKind::SetState:
      m.parameters = state_parameters(command.state);
      break;
    case CommandKind::Spawn:
      m.parameters = spawn_parameters(command.spawn);
      break;
    case CommandKind::Delete:
      m.parameters = {{"name", ParameterValue::of_string(command.entity)}};
      break;
    case CommandKind::LoadWorld:
      m.parameters = {{"resource", ParameterValue::of_string(command.world.resource)},
                      {"uri", ParameterValue::of_string(command.world.uri)}};
      break;
    default:
      m.parameters = command.parameters;
  }
  m.atomic = command.atomic;
  m.steps = command.steps > 0 ? static_cast<std::uint64_t>(command.steps) : 0;
  m.pause_seconds = command.pause_seconds;
  // A body index the controller refused may not fit the field: the message says so in its text.
  // Spawn and delete_entity: the body's id, as the result names it.
  const bool entity = command.kind == CommandKind::Spawn || command.kind == CommandKind::Delete;
  const std::int64_t body = entity                                  ? result.body_id
                            : command.kind == CommandKind::SetState ? command.state.body
                                                                    : command.impulse.body;
  m.body = body >= 0 && body <= 0xffffffffLL ? static_cast<std::uint32_t>(body) : 0xffffffffU;
  m.jx = command.impulse.impulse.x();
  m.jy = command.impulse.impulse.y();
  m.px = command.impulse.point.x();
  m.py = command.impulse.point.y();
  m.success = result.successful;
  m.message = result.message;
  return m;
}

Result<Command> from_message(const msgs::CommandMessage& m) {
  const std::string which = "command " + std::to_string(m.seq);
  if (m.kind > msgs::CommandMessage::UnloadWorld) {
    return Error{which + ": unknown kind " + std::to_string(m.kind) + " (rbsim_msgs/msg/Command has 0..12)",
                 ErrorCode::Malformed};
  }
  if (m.step > static_cast<std::uint64_t>(INT64_MAX) || m.steps > static_cast<std::uint64_t>(INT64_MAX)) {
    return Error{which + ": step or steps past the int64 range", ErrorCode::Malformed};
  }
  Command c;
  c.step = static_cast<std::int64_t>(m.step);
  c.kind = static_cast<CommandKind>(m.kind);
  c.parameters = m.parameters;
  c.atomic = m.atomic;
  c.steps = static_cast<std::int64_t>(m.steps);
  c.pause_seconds = m.pause_seconds;
  c.impulse = ImpulseArgs{m.body, Vec2(m.jx, m.jy), Vec2(m.px, m.py)};
  if (c.kind == CommandKind::SetState) {
    c.parameters.clear();
    c.state.body = m.body;
    if (Status st = state_args(m.parameters, which, c.state); !st) return st.error();
  }
  if (c.kind == CommandKind::Spawn) {
    c.parameters.clear();
    if (Status st = spawn_args(m.parameters, which, c.spawn); !st) return st.error();
  }
  if (c.kind == CommandKind::Delete) {
    c.parameters.clear();
    ParameterValue name;
    const NamedParameters named(m.parameters, which + ": delete_entity");
    if (Status st = named.take("name", ParameterType::String, name); !st) return st.error();
    if (Status st = named.only({"name"}); !st) return st.error();
    c.entity = name.string_value;
  }
  if (c.kind == CommandKind::LoadWorld) {
    c.parameters.clear();
    if (Status st = world_args(m.parameters, which, c.world); !st) return st.error();
  }
  if ((c.kind == CommandKind::ResetSpawned || c.kind == CommandKind::UnloadWorld) && !m.parameters.empty()) {
    return Error{which + ": " + to_string(c.kind) + " takes no parameters", ErrorCode::Malformed};
  }
  c.source = m.source;
  return c;
}

}  // namespace rbsim::control
