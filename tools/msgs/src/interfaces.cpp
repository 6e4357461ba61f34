// CDR codecs of the service and parameter interfaces (rbsim/interfaces.hpp), on the one writer
// (CdrWriter) and the one cursor (through detail::Reader).
#include "rbsim/interfaces.hpp"

#include <type_traits>

#include "interface_codec.hpp"

namespace rbsim::msgs {

ParameterValue ParameterValue::of_bool(bool v) {
  ParameterValue p;
  p.type = ParameterType::Bool;
  p.bool_value = v;
  return p;
}
ParameterValue ParameterValue::of_integer(std::int64_t v) {
  ParameterValue p;
  p.type = ParameterType::Integer;
  p.integer_value = v;
  return p;
}
ParameterValue ParameterValue::of_double(double v) {
  ParameterValue p;
  p.type = ParameterType::Double;
  p.double_value = v;
  return p;
}
ParameterValue ParameterValue::of_string(std::string v) {
  ParameterValue p;
  p.type = ParameterType::String;
  p.string_value = std::move(v);
  return p;
}

using detail::CdrWriter;
using detail::Reader;

namespace {

using detail::get_strings;
using detail::kMinString;
using detail::put_strings;

// The fewest bytes one element can take on the wire, before any padding: what a sequence length is
// checked against (detail::Reader::length), so a huge length in a short message fails before
// anything is allocated. Never more than the real minimum, so no valid message is refused.
// type, bool, int64, float64, string, five sequence lengths
constexpr std::size_t kMinValue = 1 + 1 + 8 + 8 + kMinString + 5 * 4;
constexpr std::size_t kMinParameter = kMinString + kMinValue;
// name, type, description, additional_constraints, read_only, dynamic_typing, two sequence lengths
constexpr std::size_t kMinDescriptor = 3 * kMinString + 3 + 2 * 4;
constexpr std::size_t kMinResult = 1 + kMinString;

template <class T>
void put_values(CdrWriter& w, const std::vector<T>& v) {
  w.sequence_length(v.size());
  for (const T x : v) {
    if constexpr (std::is_same_v<T, bool>) {
      w.boolean(x);
    } else if constexpr (std::is_same_v<T, std::uint8_t>) {
      w.u8(x);
    } else if constexpr (std::is_same_v<T, std::int64_t>) {
      w.i64(x);
    } else {
      w.f64(x);
    }
  }
}
template <class T>
void get_values(Reader& r, std::vector<T>& v) {
  v.resize(r.length(sizeof(T)));
  for (std::size_t i = 0; i < v.size(); ++i) {
    if constexpr (std::is_same_v<T, bool>) {
      v[i] = r.get<std::uint8_t>() != 0;
    } else {
      v[i] = r.get<T>();
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Each type once: put() writes its fields, get() reads them (nested types call each other).

void put(CdrWriter& w, const ParameterValue& m) {
  w.u8(static_cast<std::uint8_t>(m.type));
  w.boolean(m.bool_value);
  w.i64(m.integer_value);
  w.f64(m.double_value);
  w.string(m.string_value);
  put_values(w, m.byte_array_value);
  put_values(w, m.bool_array_value);
  put_values(w, m.integer_array_value);
  put_values(w, m.double_array_value);
  put_strings(w, m.string_array_value);
}
void get(Reader& r, ParameterValue& m) {
  m.type = static_cast<ParameterType>(r.get<std::uint8_t>());  // any value, as received
  m.bool_value = r.get<std::uint8_t>() != 0;
  m.integer_value = r.get<std::int64_t>();
  m.double_value = r.get<double>();
  m.string_value = r.string();
  get_values(r, m.byte_array_value);
  get_values(r, m.bool_array_value);
  get_values(r, m.integer_array_value);
  get_values(r, m.double_array_value);
  get_strings(r, m.string_array_value);
}
void put(CdrWriter& w, const Parameter& m) {
  w.string(m.name);
  put(w, m.value);
}
void get(Reader& r, Parameter& m) {
  m.name = r.string();
  get(r, m.value);
}
void put(CdrWriter& w, const ParameterDescriptor& m) {
  w.string(m.name);
  w.u8(static_cast<std::uint8_t>(m.type));
  w.string(m.description);
  w.string(m.additional_constraints);
  w.boolean(m.read_only);
  w.boolean(m.dynamic_typing);
  w.sequence_length(m.floating_point_range ? 1 : 0);
  if (const auto& f = m.floating_point_range) {
    w.f64(f->from_value);
    w.f64(f->to_value);
    w.f64(f->step);
  }
  w.sequence_length(m.integer_range ? 1 : 0);
  if (const auto& i = m.integer_range) {
    w.i64(i->from_value);
    w.i64(i->to_value);
    w.u64(i->step);
  }
}
void get(Reader& r, ParameterDescriptor& m) {
  m.name = r.string();
  m.type = static_cast<ParameterType>(r.get<std::uint8_t>());  // any value, as received
  m.description = r.string();
  m.additional_constraints = r.string();
  m.read_only = r.get<std::uint8_t>() != 0;
  m.dynamic_typing = r.get<std::uint8_t>() != 0;
  m.floating_point_range.reset();
  m.integer_range.reset();
  const std::uint32_t floats = r.length(24);
  if (floats > 1) r.fail();  // a bounded sequence, [<=1]
  if (floats == 1) {
    FloatingPointRange f;
    f.from_value = r.get<double>();
    f.to_value = r.get<double>();
    f.step = r.get<double>();
    m.floating_point_range = f;
  }
  const std::uint32_t ints = r.ok() ? r.length(24) : 0;
  if (ints > 1) r.fail();
  if (ints == 1) {
    IntegerRange i;
    i.from_value = r.get<std::int64_t>();
    i.to_value = r.get<std::int64_t>();
    i.step = r.get<std::uint64_t>();
    m.integer_range = i;
  }
}
void put(CdrWriter& w, const SetParametersResult& m) {
  w.boolean(m.successful);
  w.string(m.reason);
}
void get(Reader& r, SetParametersResult& m) {
  m.successful = r.get<std::uint8_t>() != 0;
  m.reason = r.string();
}
void put(CdrWriter& w, const ListParametersResult& m) {
  put_strings(w, m.names);
  put_strings(w, m.prefixes);
}
void get(Reader& r, ListParametersResult& m) {
  get_strings(r, m.names);
  get_strings(r, m.prefixes);
}
template <class T>
void put_all(CdrWriter& w, const std::vector<T>& v) {
  w.sequence_length(v.size());
  for (const T& x : v) put(w, x);
}
template <class T>
void get_all(Reader& r, std::vector<T>& v, std::size_t min_size) {
  v.resize(r.length(min_size));
  for (T& x : v) {
    if (!r.ok()) break;  // a failed element leaves the rest unread: no work on garbage
    get(r, x);
  }
}
void put(CdrWriter& w, const ParameterEvent& m) {
  w.time(m.stamp);
  w.string(m.node);
  put_all(w, m.new_parameters);
  put_all(w, m.changed_parameters);
  put_all(w, m.deleted_parameters);
}
void get(Reader& r, ParameterEvent& m) {
  m.stamp = r.time();
  m.node = r.string();
  get_all(r, m.new_parameters, kMinParameter);
  get_all(r, m.changed_parameters, kMinParameter);
  get_all(r, m.deleted_parameters, kMinParameter);
}

void put(CdrWriter& w, const CommandMessage& m) {
  w.u64(m.seq);
  w.u64(m.step);
  w.time(m.stamp);
  w.u8(m.kind);
  w.string(m.source);
  put_all(w, m.parameters);
  w.boolean(m.atomic);
  w.u64(m.steps);
  w.f64(m.pause_seconds);
  w.u32(m.body);
  w.f64(m.jx);
  w.f64(m.jy);
  w.f64(m.px);
  w.f64(m.py);
  w.boolean(m.success);
  w.string(m.message);
}
void get(Reader& r, CommandMessage& m) {
  m.seq = r.get<std::uint64_t>();
  m.step = r.get<std::uint64_t>();
  m.stamp = r.time();
  m.kind = r.get<std::uint8_t>();
  m.source = r.string();
  get_all(r, m.parameters, kMinParameter);
  m.atomic = r.get<std::uint8_t>() != 0;
  m.steps = r.get<std::uint64_t>();
  m.pause_seconds = r.get<double>();
  m.body = r.get<std::uint32_t>();
  m.jx = r.get<double>();
  m.jy = r.get<double>();
  m.px = r.get<double>();
  m.py = r.get<double>();
  m.success = r.get<std::uint8_t>() != 0;
  m.message = r.string();
}

void put(CdrWriter& w, const ListParametersRequest& m) {
  put_strings(w, m.prefixes);
  w.u64(m.depth);
}
void get(Reader& r, ListParametersRequest& m) {
  get_strings(r, m.prefixes);
  m.depth = r.get<std::uint64_t>();
}
void put(CdrWriter& w, const ListParametersResponse& m) {
  put(w, m.result);
}
void get(Reader& r, ListParametersResponse& m) {
  get(r, m.result);
}
void put(CdrWriter& w, const GetParametersRequest& m) {
  put_strings(w, m.names);
}
void get(Reader& r, GetParametersRequest& m) {
  get_strings(r, m.names);
}
void put(CdrWriter& w, const GetParametersResponse& m) {
  put_all(w, m.values);
}
void get(Reader& r, GetParametersResponse& m) {
  get_all(r, m.values, kMinValue);
}
void put(CdrWriter& w, const SetParametersRequest& m) {
  put_all(w, m.parameters);
}
void get(Reader& r, SetParametersRequest& m) {
  get_all(r, m.parameters, kMinParameter);
}
void put(CdrWriter& w, const SetParametersResponse& m) {
  put_all(w, m.results);
}
void get(Reader& r, SetParametersResponse& m) {
  get_all(r, m.results, kMinResult);
}
void put(CdrWriter& w, const SetParametersAtomicallyRequest& m) {
  put_all(w, m.parameters);
}
void get(Reader& r, SetParametersAtomicallyRequest& m) {
  get_all(r, m.parameters, kMinParameter);
}
void put(CdrWriter& w, const SetParametersAtomicallyResponse& m) {
  put(w, m.result);
}
void get(Reader& r, SetParametersAtomicallyResponse& m) {
  get(r, m.result);
}
void put(CdrWriter& w, const DescribeParametersRequest& m) {
  put_strings(w, m.names);
}
void get(Reader& r, DescribeParametersRequest& m) {
  get_strings(r, m.names);
}
void put(CdrWriter& w, const DescribeParametersResponse& m) {
  put_all(w, m.descriptors);
}
void get(Reader& r, DescribeParametersResponse& m) {
  get_all(r, m.descriptors, kMinDescriptor);
}
void put(CdrWriter& w, const GetParameterTypesRequest& m) {
  put_strings(w, m.names);
}
void get(Reader& r, GetParameterTypesRequest& m) {
  get_strings(r, m.names);
}
void put(CdrWriter& w, const GetParameterTypesResponse& m) {
  put_values(w, m.types);
}
void get(Reader& r, GetParameterTypesResponse& m) {
  get_values(r, m.types);
}

void put(CdrWriter& w, const TriggerRequest&) {
  w.u8(0);
}  // structure_needs_at_least_one_member
void get(Reader& r, TriggerRequest&) {
  (void)r.get<std::uint8_t>();
}
void put(CdrWriter& w, const TriggerResponse& m) {
  w.boolean(m.success);
  w.string(m.message);
}
void get(Reader& r, TriggerResponse& m) {
  m.success = r.get<std::uint8_t>() != 0;
  m.message = r.string();
}
void put(CdrWriter& w, const StepRequest& m) {
  w.u32(m.steps);
}
void get(Reader& r, StepRequest& m) {
  m.steps = r.get<std::uint32_t>();
}
void put(CdrWriter& w, const StepResponse& m) {
  w.boolean(m.success);
  w.string(m.message);
  w.u64(m.step);
}
void get(Reader& r, StepResponse& m) {
  m.success = r.get<std::uint8_t>() != 0;
  m.message = r.string();
  m.step = r.get<std::uint64_t>();
}
void put(CdrWriter& w, const ApplyImpulseRequest& m) {
  w.u32(m.body);
  w.f64(m.jx);
  w.f64(m.jy);
  w.f64(m.px);
  w.f64(m.py);
}
void get(Reader& r, ApplyImpulseRequest& m) {
  m.body = r.get<std::uint32_t>();
  m.jx = r.get<double>();
  m.jy = r.get<double>();
  m.px = r.get<double>();
  m.py = r.get<double>();
}
void put(CdrWriter& w, const ApplyImpulseResponse& m) {
  w.boolean(m.success);
  w.string(m.message);
  w.u64(m.step);
}
void get(Reader& r, ApplyImpulseResponse& m) {
  m.success = r.get<std::uint8_t>() != 0;
  m.message = r.string();
  m.step = r.get<std::uint64_t>();
}

// rosbag2_interfaces: empty halves are the placeholder byte, as TriggerRequest.
template <class T>
requires(std::is_empty_v<T>) void put(CdrWriter& w, const T&) {
  w.u8(0);
}
template <class T>
requires(std::is_empty_v<T>) void get(Reader& r, T&) {
  (void)r.get<std::uint8_t>();
}
void put(CdrWriter& w, const SnapshotResponse& m) {
  w.boolean(m.success);
}
void get(Reader& r, SnapshotResponse& m) {
  m.success = r.get<std::uint8_t>() != 0;
}
void put(CdrWriter& w, const IsPausedResponse& m) {
  w.boolean(m.paused);
}
void get(Reader& r, IsPausedResponse& m) {
  m.paused = r.get<std::uint8_t>() != 0;
}
void put(CdrWriter& w, const GetRateResponse& m) {
  w.f64(m.rate);
}
void get(Reader& r, GetRateResponse& m) {
  m.rate = r.get<double>();
}
void put(CdrWriter& w, const SetRateRequest& m) {
  w.f64(m.rate);
}
void get(Reader& r, SetRateRequest& m) {
  m.rate = r.get<double>();
}
void put(CdrWriter& w, const SetRateResponse& m) {
  w.boolean(m.success);
}
void get(Reader& r, SetRateResponse& m) {
  m.success = r.get<std::uint8_t>() != 0;
}
void put(CdrWriter& w, const SeekRequest& m) {
  w.i32(m.time.sec);
  w.u32(m.time.nanosec);
}
void get(Reader& r, SeekRequest& m) {
  m.time.sec = r.get<std::int32_t>();
  m.time.nanosec = r.get<std::uint32_t>();
}
void put(CdrWriter& w, const SeekResponse& m) {
  w.boolean(m.success);
}
void get(Reader& r, SeekResponse& m) {
  m.success = r.get<std::uint8_t>() != 0;
}
void put(CdrWriter& w, const PlayNextResponse& m) {
  w.boolean(m.success);
}
void get(Reader& r, PlayNextResponse& m) {
  m.success = r.get<std::uint8_t>() != 0;
}
void put(CdrWriter& w, const BurstRequest& m) {
  w.u64(m.num_messages);
}
void get(Reader& r, BurstRequest& m) {
  m.num_messages = r.get<std::uint64_t>();
}
void put(CdrWriter& w, const BurstResponse& m) {
  w.u64(m.actually_burst);
}
void get(Reader& r, BurstResponse& m) {
  m.actually_burst = r.get<std::uint64_t>();
}

void put(CdrWriter& w, const GoalInfo& m) {
  detail::put_uuid(w, m.goal_id);
  w.time(m.stamp);
}
void get(Reader& r, GoalInfo& m) {
  detail::get_uuid(r, m.goal_id);
  m.stamp = r.time();
}
// uuid (16) + time (8)
constexpr std::size_t kMinGoalInfo = 24;
void put(CdrWriter& w, const GoalStatusArray& m) {
  w.sequence_length(m.status_list.size());
  for (const GoalStatus& s : m.status_list) {
    put(w, s.goal_info);
    w.u8(static_cast<std::uint8_t>(s.status));
  }
}
void get(Reader& r, GoalStatusArray& m) {
  m.status_list.resize(r.length(kMinGoalInfo + 1));
  for (GoalStatus& s : m.status_list) {
    get(r, s.goal_info);
    s.status = r.get<std::int8_t>();
  }
}
void put(CdrWriter& w, const CancelGoalRequest& m) {
  put(w, m.goal_info);
}
void get(Reader& r, CancelGoalRequest& m) {
  get(r, m.goal_info);
}
void put(CdrWriter& w, const CancelGoalResponse& m) {
  w.u8(static_cast<std::uint8_t>(m.return_code));
  w.sequence_length(m.goals_canceling.size());
  for (const GoalInfo& g : m.goals_canceling) put(w, g);
}
void get(Reader& r, CancelGoalResponse& m) {
  m.return_code = r.get<std::int8_t>();
  m.goals_canceling.resize(r.length(kMinGoalInfo));
  for (GoalInfo& g : m.goals_canceling) get(r, g);
}
void put(CdrWriter& w, const SendGoalResponse& m) {
  w.boolean(m.accepted);
  w.time(m.stamp);
}
void get(Reader& r, SendGoalResponse& m) {
  m.accepted = r.get<std::uint8_t>() != 0;
  m.stamp = r.time();
}
void put(CdrWriter& w, const GetResultRequest& m) {
  detail::put_uuid(w, m.goal_id);
}
void get(Reader& r, GetResultRequest& m) {
  detail::get_uuid(r, m.goal_id);
}

}  // namespace

RBSIM_DEFINE_CODEC(ParameterValue, "")
RBSIM_DEFINE_CODEC(Parameter, "")
RBSIM_DEFINE_CODEC(ParameterDescriptor, "")
RBSIM_DEFINE_CODEC(SetParametersResult, "")
RBSIM_DEFINE_CODEC(ListParametersResult, "")
RBSIM_DEFINE_CODEC(ParameterEvent, "")
RBSIM_DEFINE_CODEC(CommandMessage, "")
RBSIM_DEFINE_CODEC(ListParametersRequest, " request")
RBSIM_DEFINE_CODEC(ListParametersResponse, " response")
RBSIM_DEFINE_CODEC(GetParametersRequest, " request")
RBSIM_DEFINE_CODEC(GetParametersResponse, " response")
RBSIM_DEFINE_CODEC(SetParametersRequest, " request")
RBSIM_DEFINE_CODEC(SetParametersResponse, " response")
RBSIM_DEFINE_CODEC(SetParametersAtomicallyRequest, " request")
RBSIM_DEFINE_CODEC(SetParametersAtomicallyResponse, " response")
RBSIM_DEFINE_CODEC(DescribeParametersRequest, " request")
RBSIM_DEFINE_CODEC(DescribeParametersResponse, " response")
RBSIM_DEFINE_CODEC(GetParameterTypesRequest, " request")
RBSIM_DEFINE_CODEC(GetParameterTypesResponse, " response")
RBSIM_DEFINE_CODEC(TriggerRequest, " request")
RBSIM_DEFINE_CODEC(TriggerResponse, " response")
RBSIM_DEFINE_CODEC(StepRequest, " request")
RBSIM_DEFINE_CODEC(StepResponse, " response")
RBSIM_DEFINE_CODEC(ApplyImpulseRequest, " request")
RBSIM_DEFINE_CODEC(ApplyImpulseResponse, " response")
RBSIM_DEFINE_CODEC(PauseRequest, " request")
RBSIM_DEFINE_CODEC(PauseResponse, " response")
RBSIM_DEFINE_CODEC(ResumeRequest, " request")
RBSIM_DEFINE_CODEC(ResumeResponse, " response")
RBSIM_DEFINE_CODEC(TogglePausedRequest, " request")
RBSIM_DEFINE_CODEC(TogglePausedResponse, " response")
RBSIM_DEFINE_CODEC(IsPausedRequest, " request")
RBSIM_DEFINE_CODEC(IsPausedResponse, " response")
RBSIM_DEFINE_CODEC(GetRateRequest, " request")
RBSIM_DEFINE_CODEC(GetRateResponse, " response")
RBSIM_DEFINE_CODEC(SetRateRequest, " request")
RBSIM_DEFINE_CODEC(SetRateResponse, " response")
RBSIM_DEFINE_CODEC(SeekRequest, " request")
RBSIM_DEFINE_CODEC(SeekResponse, " response")
RBSIM_DEFINE_CODEC(PlayNextRequest, " request")
RBSIM_DEFINE_CODEC(PlayNextResponse, " response")
RBSIM_DEFINE_CODEC(BurstRequest, " request")
RBSIM_DEFINE_CODEC(BurstResponse, " response")
RBSIM_DEFINE_CODEC(SnapshotRequest, " request")
RBSIM_DEFINE_CODEC(SnapshotResponse, " response")
RBSIM_DEFINE_CODEC(SplitBagfileRequest, " request")
RBSIM_DEFINE_CODEC(SplitBagfileResponse, " response")
RBSIM_DEFINE_CODEC(GoalStatusArray, "")
RBSIM_DEFINE_CODEC(CancelGoalRequest, " request")
RBSIM_DEFINE_CODEC(CancelGoalResponse, " response")
RBSIM_DEFINE_CODEC(SendGoalResponse, "")
RBSIM_DEFINE_CODEC(GetResultRequest, "")

Result<GoalUuid> request_goal_id(std::span<const std::byte> cdr) {
  GetResultRequest prefix;  // the goal id alone: what every action request begins with
  if (Status st = decode(cdr, prefix); !st) return st.error();
  return prefix.goal_id;
}

}  // namespace rbsim::msgs
