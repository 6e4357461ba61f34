// The parameters of a running scene, with ROS 2's parameter semantics (rcl_interfaces, rclcpp):
// typed values, descriptors (description, read-only, ranges), checks that name the parameter and
// the rule it breaks. No I/O and no DDS: the DDS parameter services, the Foxglove server and a
// script of commands all read and change parameters through this table (rbsim/control.hpp).
//
// The table of a run:
//   read-only   scene (string: the path), dt (double), integrator (string), bodies, springs,
//               steps (integers), start_type_description_service (bool, true: rclcpp's, whether
//               the node serves ~/get_type_description; given only by an override, -p or
//               --params-file, as rclcpp's read-only parameters are)
//   read-write  rate (double >= 0), publish_every (integer >= 1), paused (bool),
//               forces.<i>.fx|fy (gravity i, double), forces.<i>.beta (wind, double >= 0),
//               forces.<i>.fx|fy (wind velocity, double), forces.<i>.pointsperedge (wind,
//               integer in [2, 1000000]), springs.<j>.k, springs.<j>.l0 (doubles >= 0),
//               use_sim_time (bool, false: true is refused, rbsim is the clock),
//               service_configure_introspection (string: disabled, metadata or contents; the
//               node's services' introspection, REP 2012, named as ROS 2's introspection demos
//               name it)
// Forces are the scene's gravity and wind forces numbered together in file order from 0
// (Scene::forces); springs are numbered apart, in file order. Doubles must be finite.
//
// Types are strict, as rclcpp's statically typed parameters: an integer value for a double
// parameter is refused ("Wrong parameter type, parameter {rate} is of type {double}, setting it
// to {integer} is not allowed."), so `rate:=2` must be written `rate:=2.0`, as for any rclcpp
// node. Ranges follow rcl_interfaces: one FloatingPointRange or IntegerRange (step 0: any value
// in [from, to]); "no upper bound" is the largest finite double (JSON and CDR carry it), and the
// range check also refuses NaN and infinities, which rclcpp's lets through.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/core.hpp"
#include "rbsim/interfaces.hpp"
#include "rbsim/scene.hpp"
#include "rbsim/service_event.hpp"

namespace rbsim::control {

// The rcl_interfaces types are msgs's (rbsim/interfaces.hpp: one definition, with their CDR
// codecs); the table reads and answers in them.
using msgs::FloatingPointRange;
using msgs::IntegerRange;
using msgs::ListParametersResult;
using msgs::Parameter;
using msgs::ParameterDescriptor;
using msgs::ParameterType;
using msgs::ParameterValue;
using msgs::SetParametersResult;
// rclcpp's names: "not set", "bool", "integer", "double", "string", "byte_array", ...
const char* to_string(ParameterType type);
// The value as a person reads it: 2.5 (shortest round trip), 7, true, 'text', [1, 2].
std::string to_string(const ParameterValue& value);

inline constexpr std::uint64_t kDepthRecursive = 0;  // ListParameters.Request.DEPTH_RECURSIVE

// The run's own settings, beside the scene's parameters.
struct RunSettings {
  double rate = 1.0;               // real-time factor; 0: as fast as possible
  std::int64_t publish_every = 1;  // publish every k-th step
  bool paused = false;
  // rclcpp's read-only start_type_description_service: the node serves ~/get_type_description.
  bool start_type_description_service = true;
  // REP 2012 service introspection of the node's services (msgs::IntrospectionState's words);
  // `rbsim node` turns it on and off, other runs carry it unused.
  msgs::IntrospectionState service_introspection = msgs::IntrospectionState::Off;
};

// What a parameter is bound to (the table's internal map from a name to the state it reads and
// changes).
struct ParameterTarget {
  enum class Kind : std::uint8_t {
    // read-only
    Scene,
    Dt,
    Integrator,
    Bodies,
    Springs,
    Steps,
    // the run's settings
    Rate,
    PublishEvery,
    Paused,
    UseSimTime,
    // read-only, its value given at start by an override (rclcpp's node parameter)
    StartTypeDescriptionService,
    ServiceIntrospection,
    // index: into WorldDef::gravity
    GravityX,
    GravityY,
    // index: into WorldDef::winds
    WindBeta,
    WindX,
    WindY,
    WindPoints,
    // index: into WorldDef::springs
    SpringK,
    SpringL0,
  };
  Kind kind = Kind::Scene;
  std::int32_t index = 0;
};

// The declared parameters of one run, in a fixed order (the read-only ones, the run settings,
// forces, springs), with their current values.
class ParameterTable {
 public:
  // The parameters of a run of `scene` for `steps` steps with `settings`, valued from
  // scene.world and settings. A scene made in code without Scene::forces numbers its gravity
  // fields first, then its winds.
  ParameterTable(const Scene& scene, std::int64_t steps, const RunSettings& settings);

  std::size_t size() const { return entries_.size(); }
  const ParameterDescriptor& descriptor(std::size_t i) const { return entries_[i].descriptor; }
  const ParameterValue& value(std::size_t i) const { return entries_[i].value; }
  ParameterTarget target(std::size_t i) const { return entries_[i].target; }
  std::optional<std::size_t> find(std::string_view name) const;

  // Why setting `p` would be refused, as rclcpp words it where rclcpp has a rule: unknown name,
  // read-only, wrong type, out of range, not finite, use_sim_time true. Successful if none.
  // `at_start`: an override before the run (apply_overrides), which may give a read-only
  // parameter that has no value of the scene's (start_type_description_service) its value, as
  // rclcpp's overrides give read-only parameters theirs at declaration.
  SetParametersResult check(const Parameter& p, bool at_start = false) const;
  // Records a value that check() accepted (the caller applied it to the state).
  void store(std::size_t i, const ParameterValue& value) { entries_[i].value = value; }
  // Values read again from a world and settings (after a reset, a new pass).
  void refresh(const World& world, const RunSettings& settings);
  // After bodies or springs were added or removed (or the world made again): the `bodies` and
  // `springs` counts read again, and one `springs.<id>.k|l0` pair per spring the world now has,
  // named by its id (a scene's springs keep their file index), in spring order, last in the table.
  // The names that appeared go to `added` (with their values), the ones that went to `removed`.
  void follow_structure(const World& world, std::vector<Parameter>* added, std::vector<std::string>* removed);
  // Makes this table equal to `from`, a table of the same scene (a copy of it, changed since), at
  // the cost of what changed: each value compared and copied in place if it differs, the springs'
  // entries kept up to the first spring the two do not share and `from`'s copied from there. The
  // Controller's published table follows its own this way at a boundary: a spawn into a world of
  // 10,000 springs compares 20,000 values instead of copying 20,000 entries and their names.
  void follow(const ParameterTable& from);
  // rclcpp's list_parameters: names under any of `prefixes` (all when empty), at most `depth`
  // levels of '.' below the prefix (kDepthRecursive: any), and the prefixes of those names.
  ListParametersResult list(const std::vector<std::string>& prefixes, std::uint64_t depth) const;

 private:
  struct Entry {
    ParameterDescriptor descriptor;
    ParameterValue value;
    ParameterTarget target;
  };
  void add(ParameterDescriptor descriptor, ParameterValue value, ParameterTarget target);
  void add_spring(std::int32_t id, std::size_t index, const SpringDef& spring);
  std::vector<Entry> entries_;
  std::vector<std::int32_t> spring_ids_;  // the id of each spring's entries, in table order
  // Name -> index: a lookup stays O(log n) however many names a request (or a client) sends.
  std::map<std::string, std::size_t, std::less<>> index_;
};

// Applies a value the table accepted to a scene definition (initial values, before the World
// exists), to a live world (at a step boundary) or to run settings. Settings targets are ignored
// by the first two, scene targets by the last.
void apply(const ParameterTarget& target, const ParameterValue& value, WorldDef& def);
[[nodiscard]] Status apply(const ParameterTarget& target, const ParameterValue& value, World& world);
void apply(const ParameterTarget& target, const ParameterValue& value, RunSettings& settings);
bool is_setting(const ParameterTarget& target);

// A parameter given before the run (--ros-args -p, --params-file) and where it came from, for
// errors: "params.yaml:4" or "-p".
struct ParameterOverride {
  Parameter parameter;
  std::string origin;
  // From a wildcard node key of a parameters file (/**): a name this node does not declare is
  // skipped with a warning, since a file shared by several nodes holds the others' parameters.
  // Elsewhere (-p, /NS:) an unknown name is an error.
  bool wildcard = false;
};
// Applies overrides in order (the last of a name wins) to the scene and the settings, as one
// atomic batch: the first refused one is the error, "ORIGIN: parameter 'NAME': REASON", and
// nothing changes. Skipped wildcard names are added to `warnings` (when given).
[[nodiscard]] Status apply_overrides(const std::vector<ParameterOverride>& overrides, Scene& scene,
                                     std::int64_t steps, RunSettings& settings,
                                     std::vector<std::string>* warnings = nullptr);

}  // namespace rbsim::control
