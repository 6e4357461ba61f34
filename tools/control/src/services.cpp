// The control services' requests as Commands and their results as replies (rbsim/control.hpp):
// the one mapping the node's DDS services and the Foxglove server share.
#include "rbsim/control.hpp"

namespace rbsim::control {

namespace {
constexpr ControlService kServices[] = {
    {"pause", msgs::TriggerRequest::kService, CommandKind::Pause},
    {"resume", msgs::TriggerRequest::kService, CommandKind::Resume},
    {"reset", msgs::TriggerRequest::kService, CommandKind::Reset},
    {"step", msgs::StepRequest::kService, CommandKind::Step},
    {"apply_impulse", msgs::ApplyImpulseRequest::kService, CommandKind::Impulse},
};

std::uint64_t step_of(const CommandResult& r) {
  return r.step < 0 ? 0 : static_cast<std::uint64_t>(r.step);
}
}  // namespace

std::span<const ControlService> control_services() {
  return kServices;
}

Command command_for(CommandKind trigger_kind, const msgs::TriggerRequest&) {
  Command c;
  c.kind = trigger_kind;
  return c;
}

Command command_for(const msgs::StepRequest& request) {
  Command c;
  c.kind = CommandKind::Step;
  c.steps = request.steps;
  return c;
}

Command command_for(const msgs::ApplyImpulseRequest& request) {
  Command c;
  c.kind = CommandKind::Impulse;
  c.impulse.body = request.body;
  c.impulse.impulse = Vec2(request.jx, request.jy);
  c.impulse.point = Vec2(request.px, request.py);
  return c;
}

msgs::TriggerResponse trigger_response(const CommandResult& result) {
  return {result.successful, result.message};
}

msgs::StepResponse step_response(const CommandResult& result) {
  if (result.successful && result.ends_at >= 0)
    return {result.successful, result.message, static_cast<std::uint64_t>(result.ends_at)};
  return {result.successful, result.message, step_of(result)};
}

msgs::ApplyImpulseResponse impulse_response(const CommandResult& result) {
  return {result.successful, result.message, step_of(result)};
}

}  // namespace rbsim::control
