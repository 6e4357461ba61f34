// Commands as rbsim_msgs/msg/Command (rbsim/control.hpp): what the node publishes on
// /<ns>/commands and a re-simulation reads back.
#include <string>
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
  m.parameters = command.kind == CommandKind::SetState ? state_parameters(command.state) : command.parameters;
  m.atomic = command.atomic;
  m.steps = command.steps > 0 ? static_cast<std::uint64_t>(command.steps) : 0;
  m.pause_seconds = command.pause_seconds;
  // A body index the controller refused may not fit the field: the message says so in its text.
  const std::int64_t body = command.kind == CommandKind::SetState ? command.state.body : command.impulse.body;
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
  if (m.kind > msgs::CommandMessage::StopStepping) {
    return Error{which + ": unknown kind " + std::to_string(m.kind) + " (rbsim_msgs/msg/Command has 0..7)",
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
  c.source = m.source;
  return c;
}

}  // namespace rbsim::control
