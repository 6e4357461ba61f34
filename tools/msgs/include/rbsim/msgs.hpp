// rbsim's ROS 2 messages: the topics a run publishes and records, their ros2msg definitions
// (tools/msgs/definitions, the one source of truth, embedded at build time), rosbag2-style schema
// texts, and CDR encoders that turn a world snapshot into message bytes.
//
// CDR here is what ROS 2 over DDS puts on the wire: a 4-byte encapsulation header
// (00 01 00 00 = plain CDR, little endian) followed by XCDR1 data, every primitive aligned to its
// size relative to the end of that header, strings as uint32 length (with the NUL) + bytes + NUL,
// sequences as uint32 count + elements; the message is zero-padded to a multiple of 4 bytes with
// the pad count in the header's last byte (options), exactly as Cyclone DDS serialises it.
#pragma once

#include <array>
#include <bitset>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/bytes.hpp"
#include "rbsim/core.hpp"
#include "rbsim/scene.hpp"

namespace rbsim::msgs {

// ---------------------------------------------------------------------------------------------
// Topics

// In publishing order: the latched topics first, so every sink that walks topics() in order sends
// the scene description and the body shapes before the first per-step message. The last one,
// commands, is an event topic: what the node's controller did (rbsim_msgs/msg/Command), never
// encoded from a World, so no sink's --topics selects it; the node publishes it, the recorder,
// replay and bridge carry it like any topic.
enum class TopicId : std::uint8_t {
  SceneDescription,
  Markers,
  BodyStates,
  SpringStates,
  Energy,
  Tf,
  Springs,
  Clock,
  Poses,
  Commands
};
inline constexpr std::size_t kTopicCount = 10;

struct TopicSpec {
  TopicId id;
  std::string_view suffix;  // "body_states": the ROS name is /<namespace>/<suffix>
  std::string_view type;    // "rbsim_msgs/msg/BodyStates"
  bool transient_local;     // late subscribers get the last sample (every sample, for an event topic)
  bool per_step;            // published every (published) step
  bool event = false;       // published as things happen, kept all (transient local, keep all)
  // Latched: transient local, keep last 1, sent once at the start of a run (scene, markers).
  constexpr bool latched() const { return transient_local && !event; }
};
std::span<const TopicSpec> topics();
const TopicSpec& topic(TopicId id);
// The topic of topics() whose type is `type` ("pkg/msg/Name", or "pkg/Name" as older tools write
// it); null when it is none of ours.
const TopicSpec* topic_for_type(std::string_view type);
// Whether a topic name given on a command line names `topic`: the whole name
// ("/rbsim/body_states") or its trailing part(s) after a '/' ("body_states", "rbsim/body_states").
bool names_topic(std::string_view requested, std::string_view topic);
// Why `ns` is not a ROS 2 namespace as rbsim uses it ("rbsim", "robots/arm_1"; a leading '/' is
// allowed): tokens of letters, digits and underscores, none starting with a digit, separated by
// single '/', no trailing '/', no repeated underscores (the ROS 2 topic and namespace name
// rules). Empty when it is one.
std::string ros_namespace_problem(std::string_view ns);
// "/rbsim/body_states" for namespace "rbsim"; "/clock" and "/tf" always live at the root.
std::string topic_name(const TopicSpec& spec, std::string_view ns);

// A selection of topics, indexed by TopicId.
using TopicSet = std::bitset<kTopicCount>;
// What a run publishes and records unless told otherwise: everything but the PoseArray (poses),
// which /tf replaces for viewers.
TopicSet default_topics();
// A comma-separated --topics list of the topics a World publishes (no event topic): each name as
// select_topics() takes it against the topics' names in namespace `ns` ("body_states",
// "/rbsim/body_states", "tf", "/tf", "rbsim/markers"). The scene description is always included
// (every reader needs it). Fails on an empty list ("no topic given") or an unknown name
// (unknown_topic(), listing the valid names).
Result<TopicSet> parse_topic_set(std::string_view list, std::string_view ns = "rbsim");

// ---------------------------------------------------------------------------------------------
// Selecting topics by name or pattern: the one rule of every command's --topics, --exclude-topics,
// --regex and --exclude-regex (run, node, record, replay, log cat, log filter, check, Python's
// and rbsim::testing's topic lists), as MCAP's topicFilter and rosbag2's topic_filter are one.

// A topic a selection chooses from: its name, and its TopicSpec when its type is one of ours.
struct TopicCandidate {
  std::string name;
  const TopicSpec* spec = nullptr;
};
// Our topics in namespace `ns` as candidates, in topics() order; the event topic (commands) only
// when `events`.
std::vector<TopicCandidate> topic_candidates(std::string_view ns, bool events);
// Whether a name given on a command line selects `topic`: names_topic() against its name ("/rbsim/
// body_states", "rbsim/body_states", "body_states"), or, for one of our types, the topic's suffix
// ("body_states" selects a BodyStates channel recorded under any name).
bool selects_topic(std::string_view requested, const TopicCandidate& topic);
// What to select. Nothing to keep (no names, no regex) keeps every topic.
struct TopicFilter {
  std::vector<std::string> topics;          // keep the topics these name (selects_topic())
  std::string regex;                        // and those whose whole name this matches (ECMAScript)
  std::vector<std::string> exclude_topics;  // but never the topics these name
  std::string exclude_regex;                // nor those whose whole name this matches
};
// The candidates `filter` selects, as indices into `candidates`, in their order. Empty names are
// skipped. Fails on a name of `topics` or `exclude_topics` that selects no candidate
// (unknown_topic()), or on a pattern that is not a regular expression ("--regex \"(\": not a
// regular expression (...)", ErrorCode::InvalidArgument).
Result<std::vector<std::size_t>> select_topics(const TopicFilter& filter,
                                               std::span<const TopicCandidate> candidates);
// The one wording of a name that selects no topic: unknown topic "/rbsim/nope" (topics:
// /rbsim/a, /rbsim/b), the candidates' names sorted, each once ("(topics: none)" without any).
Error unknown_topic(std::string_view requested, std::span<const TopicCandidate> candidates);
// The topics of a set in topics() order.
std::vector<TopicId> topic_ids(const TopicSet& set);
// DDS names per ROS 2 conventions: "rt/rbsim/body_states", "rbsim_msgs::msg::dds_::BodyStates_".
std::string dds_topic_name(std::string_view ros_topic);
std::string dds_type_name(std::string_view ros_type);
// What a writer of a topic offers (reliability is always reliable).
struct OfferedQos {
  bool transient_local = false;  // late joiners get the last sample (the scene description)
  bool keep_all = false;         // keep all (wait for slow readers) instead of keep last
  std::int32_t depth = 1;        // keep-last depth
};
// What rbsim's node and replay offer: the scene description transient local, keep last 1;
// per-step topics keep all, or keep last `keep_last` when it is positive (the writer then never
// waits, and a reader that falls more than `keep_last` samples behind loses the oldest).
OfferedQos offered_qos(const TopicSpec& spec, std::int32_t keep_last = 0);
// The YAML rosbag2 stores in a channel's "offered_qos_profiles" metadata for one publisher.
std::string offered_qos_yaml(const OfferedQos& qos);

// ---------------------------------------------------------------------------------------------
// Definitions and schemas

// The .msg text of a type ("rbsim_msgs/msg/BodyStates" or "rbsim_msgs/BodyStates"), or the .srv
// text of a service ("std_srvs/srv/Trigger": request, a "---" line, response) or the .action text
// of an action ("simulation_interfaces/action/SimulateSteps": goal, result, feedback); empty when
// unknown.
std::string_view definition(std::string_view type);
// Every message type name we carry, "pkg/msg/Name", sorted (services are not messages: their
// request and response are, under rosidl's names, in rbsim/type_hash.hpp).
std::vector<std::string_view> definition_types();
// Every service type we carry, "pkg/srv/Name", sorted.
std::vector<std::string_view> service_types();
// Every action type we carry, "pkg/action/Name", sorted (the messages and services rosidl derives
// from each are in rbsim/type_hash.hpp).
std::vector<std::string_view> action_types();
// The schema rosbag2 writes for a type with encoding "ros2msg": its .msg text followed by each
// dependency, depth first, once, as "\n" + 80 '=' + "\nMSG: pkg/Name\n" + text. Also for the
// messages rosidl makes of a service we carry: "pkg/srv/Name_Request", "_Response" (the parts of
// its .srv text) and "_Event" (service_msgs/ServiceEventInfo info, then the request and the
// response as sequences of at most one, named in full: "pkg/srv/Name_Request[<=1] request").
Result<std::string> ros2msg_schema(std::string_view type);
// The suffixes of those messages' names.
inline constexpr std::string_view kServiceRequestSuffix = "_Request";
inline constexpr std::string_view kServiceResponseSuffix = "_Response";
inline constexpr std::string_view kServiceEventSuffix = "_Event";
// The EnergyTerms layouts this build reads: the current one, and the one before
// potential_gravity / potential_spring were appended.
enum class EnergyTermsVersion : std::uint8_t { Current, WithoutSplit };
// The EnergyTerms layout a recorded schema text describes: this build's, or the one older builds
// recorded (before the potential split). nullopt for any other text.
std::optional<EnergyTermsVersion> energy_terms_version(std::string_view schema);

// ---------------------------------------------------------------------------------------------
// Encoding a world snapshot

struct Time {
  std::int32_t sec = 0;
  std::uint32_t nanosec = 0;
  bool operator==(const Time&) const = default;
};
// Simulated time of the world's current step, t = step * dt, rounded to the nanosecond (base's
// seconds_to_ns_clamped()).
Time sim_time(const World& world);
std::uint64_t sim_time_ns(const World& world);
// A count of ns (since the epoch, or simulated) as builtin_interfaces/Time: the one split into
// seconds and nanoseconds.
Time time_from_ns(std::uint64_t ns);
// The same for step `step` of a world stepping `dt` (t = step * dt, as World::time()).
Time sim_time(std::int64_t step, double dt);
std::uint64_t sim_time_ns(std::int64_t step, double dt);

using rbsim::Bytes;

// The quaternion of a rotation by theta about +z (a planar body's orientation).
struct Quaternion {
  double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
  bool operator==(const Quaternion&) const = default;
};
Quaternion quaternion_z(double theta);

// Triangulates a simple polygon (convex or not, either winding) by ear clipping: index triples
// into `polygon`, each triangle counter-clockwise, n - 2 of them for n vertices with no three
// collinear (a collinear vertex adds no triangle). A polygon that is not simple (self-crossing,
// which no scene body should be) is still covered by triangles, not necessarily exactly.
std::vector<std::uint32_t> triangulate(std::span<const Vec2> polygon);

// The TF frame of body `index` in namespace `ns`: "rbsim/body_3" (no leading slash, as tf2 wants).
std::string body_frame(std::string_view ns, std::int32_t index);
// The frame of a body by name (a spawned body's own, scene_body_name(id) for a scene's): ns/name.
std::string body_frame(std::string_view ns, std::string_view name);

// Encodes the messages of one step into reused buffers: after the first step of a world, no
// per-step call allocates. The frame id of every header is "world", but for the body shapes,
// which live in their body's TF frame (body_frame(ns, i)).
class Encoder {
 public:
  explicit Encoder(const Scene& scene, std::string_view ns = "rbsim");

  void scene(const World& world, Bytes& out) const;  // rbsim_msgs/msg/SceneDescription
  void body_states(const World& world, Bytes& out) const;
  void spring_states(const World& world, Bytes& out) const;
  void energy(const World& world, Bytes& out) const;
  void tf(const World& world, Bytes& out) const;       // tf2_msgs/msg/TFMessage: world -> each body
  void springs(const World& world, Bytes& out) const;  // visualization_msgs/msg/Marker, LINE_LIST
  void poses(const World& world, Bytes& out) const;    // geometry_msgs/msg/PoseArray
  // visualization_msgs/msg/MarkerArray, latched: the body shapes in their frames (they move with
  // /tf) and the fixed spring anchors in "world".
  void markers(const World& world, Bytes& out) const;
  void clock(const World& world, Bytes& out) const;  // rosgraph_msgs/msg/Clock: encode_clock
  void encode(TopicId id, const World& world, Bytes& out) const;
  // The world's bodies or springs changed (Sink::restructure): their names and colours from now on.
  // The ids messages carry are the world's (World::body_id); after a change (epoch > 0) the
  // markers start with a DELETEALL, so a viewer drops the bodies that went. A loaded world's
  // entities bring its scene (Entities::scene), described from then on.
  void restructure(const Entities& entities);

 private:
  const Scene* scene_;
  std::string ns_;
  Entities entities_;
  std::vector<std::string> frames_;  // body_frame(ns, name) per body
  // Every spring's colour when they all share one: the springs marker then carries it once.
  std::optional<Color> spring_color_;
};

// The one /clock message (rosgraph_msgs/msg/Clock) at `t_ns` nanoseconds into `out`, returned:
// the simulator's for a world's time (Encoder::clock), rbsim replay's for a recording's log time.
const Bytes& encode_clock(std::uint64_t t_ns, Bytes& out);

// The messages of the world's current step, each encoded once however many sinks send it (the
// node's DDS and Foxglove sinks share one): get() encodes a topic at its first request in a step.
// Encoding is deterministic, so a step seen again (a --loop pass) gives the same bytes.
class StepMessages {
 public:
  explicit StepMessages(const Scene& scene, std::string_view ns = "rbsim");
  const Bytes& get(TopicId id, const World& world);
  // The world's bodies or springs changed at this step: what was encoded for it is stale. Every
  // sink sharing these messages is told the same change; only the first telling re-encodes.
  void restructure(const Entities& entities);

 private:
  Encoder encoder_;
  std::uint32_t epoch_ = 0;  // Entities::epoch the encoder holds (each change has its own)
  std::array<Bytes, kTopicCount> bytes_;
  std::array<const World*, kTopicCount> world_{};
  std::array<std::int64_t, kTopicCount> step_{};
};

// ---------------------------------------------------------------------------------------------
// Typed decoding of our own messages (for tools that draw or export a recording). Colours come
// back as the float32 the message carries.

struct SceneMessage {
  Time stamp;
  std::string name, description, integrator;
  double dt = 0.0, duration = 0.0;
  std::uint64_t step_count = 0;
  struct Body {
    double mass = 0.0, inertia = 0.0, radius = 0.0;
    Color color;
    std::vector<Vec2> hull;  // body space
  };
  std::vector<Body> bodies;
  std::vector<SpringDef> springs;
  std::vector<Color> spring_colors;
  std::vector<GravityDef> gravity;
  std::vector<WindDef> winds;
  std::optional<Viewport> viewport;
  Color background;
};
struct BodyStatesMessage {
  Time stamp;
  std::uint64_t step = 0;
  struct Body {
    std::int32_t id = 0;
    BodyState state;
  };
  std::vector<Body> bodies;
};
struct SpringStatesMessage {
  Time stamp;
  std::uint64_t step = 0;
  struct Spring {
    std::int32_t id = 0;
    Vec2 end_i{0.0, 0.0}, end_j{0.0, 0.0};  // world endpoints
    double length = 0.0, rest_length = 0.0, potential = 0.0;
  };
  std::vector<Spring> springs;
};
struct EnergyTermsMessage {
  Time stamp;
  std::uint64_t step = 0;
  struct Body {
    std::int32_t id = 0;
    Vec2 momentum{0.0, 0.0};
    double l_point = 0.0, l_spin = 0.0, t_point = 0.0, t_spin = 0.0;
  };
  std::vector<Body> bodies;
  // ForcePotential.kind: each gravity field (index among the fields), then each spring.
  enum class ForceKind : std::uint8_t { Gravity = 0, Spring = 1 };
  struct Force {
    std::uint8_t kind = 0;  // a ForceKind; other values are carried as recorded
    std::int32_t index = 0;
    double potential = 0.0;
  };
  std::vector<Force> forces;
  Vec2 momentum{0.0, 0.0};  // totals over bodies
  double angular_momentum = 0.0, potential = 0.0, kinetic_point = 0.0, kinetic_spin = 0.0, total = 0.0;
  // U_gravity and U_spring as World::energy() sums them; recordings made before they were added
  // (EnergyTermsVersion::WithoutSplit) lack them: has_split is false and both are 0.
  bool has_split = true;
  double potential_gravity = 0.0, potential_spring = 0.0;
};
// geometry_msgs/msg/PoseArray, as rbsim publishes it (one pose per body, in body order).
struct PosesMessage {
  Time stamp;
  struct Pose {
    double x = 0.0, y = 0.0, z = 0.0;               // position
    double qx = 0.0, qy = 0.0, qz = 0.0, qw = 1.0;  // orientation quaternion
  };
  std::vector<Pose> poses;
};
// tf2_msgs/msg/TFMessage: one transform per body.
struct TfMessage {
  struct Transform {
    Time stamp;
    std::string frame_id, child_frame_id;
    double x = 0.0, y = 0.0, z = 0.0;               // translation
    double qx = 0.0, qy = 0.0, qz = 0.0, qw = 1.0;  // rotation
  };
  std::vector<Transform> transforms;
};
// visualization_msgs/msg/Marker, the fields rbsim sets (the springs' LINE_LIST and each marker of
// the latched MarkerArray).
struct MarkerMessage {
  Time stamp;
  std::string frame_id, ns;
  std::int32_t id = 0, type = 0, action = 0;
  PosesMessage::Pose pose;
  double scale_x = 0.0, scale_y = 0.0, scale_z = 0.0;
  std::array<float, 4> color{};  // r, g, b, a
  Time lifetime;
  bool frame_locked = false;
  std::vector<Vec2> points;  // x, y (rbsim's markers are planar: every z is 0)
  std::vector<std::array<float, 4>> colors;
};
// Marker types rbsim uses (visualization_msgs/msg/Marker constants).
inline constexpr std::int32_t kMarkerLineStrip = 4, kMarkerLineList = 5, kMarkerSphereList = 7,
                              kMarkerTriangleList = 11;
Result<SceneMessage> decode_scene(std::span<const std::byte> cdr);
// These reuse `out`'s storage: decoding a stream of messages does not allocate once warmed up.
// They fail on truncated or malformed data (a sequence longer than the bytes left included).
[[nodiscard]] Status decode_body_states(std::span<const std::byte> cdr, BodyStatesMessage& out);
[[nodiscard]] Status decode_spring_states(std::span<const std::byte> cdr, SpringStatesMessage& out);
[[nodiscard]] Status decode_energy_terms(std::span<const std::byte> cdr, EnergyTermsMessage& out,
                                         EnergyTermsVersion version = EnergyTermsVersion::Current);
[[nodiscard]] Status decode_poses(std::span<const std::byte> cdr, PosesMessage& out);
[[nodiscard]] Status decode_tf(std::span<const std::byte> cdr, TfMessage& out);
[[nodiscard]] Status decode_marker(std::span<const std::byte> cdr, MarkerMessage& out);
[[nodiscard]] Status decode_marker_array(std::span<const std::byte> cdr, std::vector<MarkerMessage>& out);
// The simulated time a message carries: its header stamp, a Clock's clock, a MarkerArray's first
// marker's stamp, a TFMessage's first transform's. nullopt for the scene description, an empty
// MarkerArray or TFMessage, or bytes too short to hold it.
std::optional<Time> decode_stamp(TopicId id, std::span<const std::byte> cdr);
// The one step rule: the simulated step a per-step message belongs to, for every reader (the
// recording reader, rbsim check, the golden verifier). Body states, spring states and energy terms
// carry their step (`uint64 step` after the header); the other per-step topics carry only the
// stamp of their step, t = step * dt, so their step is round(stamp / dt) with the recording's dt
// (from its scene description). The scene description's is the step its header stamp names: the
// world it describes is the one from that step on (rbsim/recording.hpp's epochs). nullopt for a
// message without either (an empty MarkerArray or TFMessage, bytes too short) or, for a stamp, a dt
// that is not finite and > 0.
std::optional<std::uint64_t> message_step(TopicId id, std::span<const std::byte> cdr, double dt);
// The name of that field: schema-driven readers (rbsim check) find a message's step by it.
inline constexpr std::string_view kStepField = "step";
// Whether a field of the scene description (its path, "background.r") is metadata rather than
// physics: the scene's name, description, viewport and background, which rbsim check reports apart.
bool is_scene_metadata(std::string_view field_path);
// Whether a field of a command (rbsim_msgs/msg/Command) is metadata: its source ("ros2 service",
// "script steer.yaml:3") and message text; a re-run of a session has the same commands with
// other sources.
bool is_command_metadata(std::string_view field_path);

// ---------------------------------------------------------------------------------------------
// Schema-driven decoding: any CDR message whose ros2msg schema is known (e.g. read from an MCAP
// file) flattened into scalars in field order. Sequence lengths are scalars too, so two messages
// of one type compare value by value, and a differing length shows up as the first difference.

struct Scalar {
  enum class Kind : std::uint8_t { Bool, Int, UInt, Float, String, Length };
  Kind kind = Kind::Float;
  double f = 0.0;       // Float (float32 widened)
  std::int64_t i = 0;   // Bool, Int
  std::uint64_t u = 0;  // UInt, Length
  std::string_view s;   // String: points into the decoded buffer
  bool operator==(const Scalar&) const = default;
  std::string to_string() const;
};

// The scalar of kind `kind` held in the `size` (1, 2, 4 or 8) little-endian bytes at `p`: float32
// widened, signed integers sign-extended, bool 0 or 1. The one primitive loader of every CDR walker
// (MessageDecoder, rbsim check's comparer); inline, as it runs once per value.
inline Scalar load_scalar(const std::byte* p, std::uint8_t size, Scalar::Kind kind) {
  Scalar s;
  s.kind = kind;
  switch (kind) {
    case Scalar::Kind::Float:
      if (size == 4) {
        float f;
        std::memcpy(&f, p, 4);
        s.f = f;
      } else {
        std::memcpy(&s.f, p, 8);
      }
      break;
    case Scalar::Kind::Int: {
      std::uint64_t u = 0;
      std::memcpy(&u, p, size);
      const unsigned shift = 64u - 8u * size;  // sign-extend
      s.i = static_cast<std::int64_t>(u << shift) >> shift;
      break;
    }
    case Scalar::Kind::Bool:
      s.i = *p != std::byte{0};
      break;
    default:
      std::memcpy(&s.u, p, size);
      break;
  }
  return s;
}

// "pkg/Name" or bare "Name" (in `package`) -> "pkg/msg/Name"; bare "Header" is std_msgs'.
std::string canonical_type(std::string_view type, std::string_view package);
// A rosbag2-style schema split into its definitions, keyed by canonical type (`root` first).
std::map<std::string, std::string> schema_sections(std::string_view root, std::string_view schema);

// A primitive .msg type: its scalar kind and CDR size in bytes (0: string; "string<=N" is one).
struct PrimitiveType {
  Scalar::Kind kind = Scalar::Kind::UInt;
  std::uint8_t size = 0;
};
std::optional<PrimitiveType> primitive_type(std::string_view type);

// One field of a .msg definition.
struct MsgField {
  std::string name;
  std::string type;                        // a primitive's name, or the canonical nested type
  std::optional<PrimitiveType> primitive;  // set for primitives
  enum class Array : std::uint8_t { None, Fixed, Sequence } array = Array::None;
  std::uint32_t fixed_size = 0;       // Array::Fixed
  std::uint32_t sequence_bound = 0;   // Array::Sequence written "[<=N]": N (0: unbounded)
  std::uint32_t string_capacity = 0;  // "string<=N": N (0: an unbounded string or not a string)
  // The default value as written after the name ("1", "[0, 1]", "'text'"), comment cut off; empty
  // when there is none. Kept as text: only the type description (REP 2011's Field.default_value)
  // reads it, and rosidl writes it there in its own spelling (type_hash.cpp).
  std::string default_text;
};
// The fields of the .msg text of `type` ("pkg/msg/Name"; bare nested names resolve in its package),
// constants and comments skipped, default values as text. A message without fields gets rosidl's one uint8
// member. Fails on a malformed line, a bad array or string bound or a wstring.
Result<std::vector<MsgField>> parse_msg_fields(std::string_view type, std::string_view text);

// Appends `text` to `out` as a JSON string: quoted, with '"', '\\' and control characters escaped.
void append_json_string(std::string& out, std::string_view text);

class CdrCursor;  // rbsim/cdr.hpp
namespace detail {
class CdrWriter;  // tools/msgs/src/cdr.hpp: msgs's own writer
}

class MessageDecoder {
 public:
  // `type` names the root ("rbsim_msgs/msg/BodyStates"); `schema` is its ros2msg text with its
  // dependencies appended rosbag2-style. Fails on unknown or unresolvable field types.
  static Result<MessageDecoder> create(std::string_view type, std::string_view schema);

  // Appends the scalars of one message to `out` (cleared first). Fails cleanly on truncated or
  // malformed data: every length is checked against the bytes that remain.
  [[nodiscard]] Status decode(std::span<const std::byte> cdr, std::vector<Scalar>& out) const;
  // Appends one message to `out` as one line of compact JSON: an object per message (nested types
  // nested), an array per array or sequence, field names as in the schema. Floats are written
  // shortest round-trip (float32 as float32), non-finite floats as null (JSON has no NaN or
  // infinity), bool as true/false, strings escaped. On malformed data `out` is left as it was.
  [[nodiscard]] Status to_json(std::span<const std::byte> cdr, std::string& out) const;
  // The inverse: one message given as a JSON object (as to_json writes it, as Foxglove Studio's
  // Service Call panel and rosbridge send it) encoded as CDR into `cdr` (replaced: the
  // encapsulation header and padding as CdrWriter writes them, so cdr -> to_json -> from_json gives
  // the same bytes). The rules, rosbridge's where it has one:
  //  - a missing field takes its zero value (0, false, "", an empty sequence, a fixed array of
  //    zeros, a nested message of zeros; not a default the .msg text gives, such as
  //    geometry_msgs/Quaternion's w 1); a field the type lacks is an error;
  //  - an integer field takes a JSON integer (or a number with an integral value, 2.0, 1e3) within
  //    its primitive's range; bool takes true or false; a string field a JSON string;
  //  - a float field takes any JSON number (float32 rounded to nearest, but not beyond float32's
  //    range) or null, which is NaN (to_json writes every non-finite value as null);
  //  - a fixed array takes exactly its size of elements, a bounded sequence or string at most its
  //    bound; a uint8, byte or char array or sequence also takes a base64 string (rosbridge's
  //    form for bytes; to_json writes them as numbers);
  //  - every error names the field's path ("entities[2].pose.position.x: must be a number"), and
  //    any input is refused cleanly: JSON nested deeper than 100 levels is refused before parsing,
  //    and what is written is bounded by the input's size (each element of a sequence at least
  //    one JSON value) times the type's size with its fields at zero.
  // On failure `cdr` is left as it was.
  [[nodiscard]] Status from_json(std::string_view json, Bytes& cdr) const;
  // The field path of scalar `index` of that message, e.g. "bodies[3].x" or "bodies.length".
  std::string path(std::span<const std::byte> cdr, std::size_t index) const;
  // The one CDR re-aligner: reads one value of the root type where `from` stands (inside a
  // message, its header already checked) and writes it to `to` at the writer's position, each
  // primitive aligned for its new offset (bit for bit otherwise), so a message moved into another
  // at a different offset (a request inside its service's _Event, rbsim/service_event.hpp) keeps
  // CDR's rule. On success `from` is past the value; on malformed data it fails (every length
  // checked against the bytes left) with `to` part-written, for the caller to discard.
  [[nodiscard]] Status copy(CdrCursor& from, detail::CdrWriter& to) const;

  struct Field;
  struct Type;

 private:
  std::vector<Type> types_;  // types_[0] is the root
};

struct MessageDecoder::Field {
  std::string name;
  int primitive = -1;      // index into the primitive table, or -1 for a nested type
  std::size_t nested = 0;  // index into types_ when primitive < 0
  using Array = MsgField::Array;
  Array array = Array::None;
  std::uint32_t fixed_size = 0;
  std::uint32_t sequence_bound = 0;   // Array::Sequence "[<=N]": N (0: unbounded)
  std::uint32_t string_capacity = 0;  // "string<=N": N (0: unbounded)
  PrimitiveType scalar;               // the primitive's kind and size when primitive >= 0
};
struct MessageDecoder::Type {
  std::string name;  // "pkg/msg/Name"
  std::vector<Field> fields;
};

}  // namespace rbsim::msgs
