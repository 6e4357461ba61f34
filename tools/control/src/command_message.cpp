// Commands as rbsim_msgs/msg/Command (rbsim/control.hpp): what the node publishes on
// /<ns>/commands and a re-simulation reads back.
#include <string>

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
  m.parameters = command.parameters;
  m.atomic = command.atomic;
  m.steps = command.steps > 0 ? static_cast<std::uint64_t>(command.steps) : 0;
  m.pause_seconds = command.pause_seconds;
  // A body index the controller refused may not fit the field: the message says so in its text.
  m.body = command.impulse.body >= 0 && command.impulse.body <= 0xffffffffLL
               ? static_cast<std::uint32_t>(command.impulse.body)
               : 0xffffffffU;
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
  if (m.kind > msgs::CommandMessage::ApplyImpulse) {
    return Error{which + ": unknown kind " + std::to_string(m.kind) + " (rbsim_msgs/msg/Command has 0..5)",
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
  c.source = m.source;
  return c;
}

}  // namespace rbsim::control
