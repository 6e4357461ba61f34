// type_description_interfaces (Jazzy) as plain structs with CDR codecs: the REP 2011 type
// description messages (TypeDescription, IndividualTypeDescription, Field, FieldType, TypeSource,
// KeyValue) and the service every rclcpp node serves on ~/get_type_description
// (type_description_interfaces/srv/GetTypeDescription). Field order and types follow the .msg/.srv
// definitions (tools/msgs/definitions/type_description_interfaces); the bytes are msgs.hpp's CDR, as
// for rbsim/interfaces.hpp. What fills them, a type's description from the shipped definitions, is
// rbsim/type_hash.hpp's; which types a node answers for is the node's (rbsim/node_types.hpp).
//
// decode() reads untrusted bytes: a truncated message, a length past the data, a bounded string
// (string<=255) over its bound or a wrong encapsulation header is an error naming the type and the
// byte offset; sequence lengths are checked against the bytes left before anything is allocated.
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/msgs.hpp"

namespace rbsim::msgs {

// type_description_interfaces/msg/FieldType: type_id is one of its FIELD_TYPE_* constants (a
// primitive's id, 1 for a nested type, plus 48 for a fixed array, 96 for a bounded and 144 for an
// unbounded sequence); capacity the array size or sequence bound, string_capacity a bounded
// string's bound, nested_type_name "pkg/msg/Name" for a nested type (string<=255).
struct FieldType {
  static constexpr std::string_view kType = "type_description_interfaces/msg/FieldType";
  static constexpr std::size_t kMaxNameLength = 255;  // string<=255 nested_type_name
  std::uint8_t type_id = 0;
  std::uint64_t capacity = 0;
  std::uint64_t string_capacity = 0;
  std::string nested_type_name;
  bool operator==(const FieldType&) const = default;
};
// type_description_interfaces/msg/Field: default_value as rosidl writes it (see type_hash.hpp).
struct Field {
  static constexpr std::string_view kType = "type_description_interfaces/msg/Field";
  std::string name;
  FieldType type;
  std::string default_value;
  bool operator==(const Field&) const = default;
};
struct IndividualTypeDescription {
  static constexpr std::string_view kType = "type_description_interfaces/msg/IndividualTypeDescription";
  std::string type_name;  // string<=255
  std::vector<Field> fields;
  bool operator==(const IndividualTypeDescription&) const = default;
};
// A type and every type it refers to, directly or not, sorted by name.
struct TypeDescription {
  static constexpr std::string_view kType = "type_description_interfaces/msg/TypeDescription";
  IndividualTypeDescription type_description;
  std::vector<IndividualTypeDescription> referenced_type_descriptions;
  bool operator==(const TypeDescription&) const = default;
};
// The text a type was defined in: encoding "msg", "srv" or "action" with the file's text, or
// "implicit" (no text) for a type rosidl derives from a service or an action.
struct TypeSource {
  static constexpr std::string_view kType = "type_description_interfaces/msg/TypeSource";
  std::string type_name;
  std::string encoding;
  std::string raw_file_contents;
  bool operator==(const TypeSource&) const = default;
};
struct KeyValue {
  static constexpr std::string_view kType = "type_description_interfaces/msg/KeyValue";
  std::string key;
  std::string value;
  bool operator==(const KeyValue&) const = default;
};

struct GetTypeDescriptionRequest {
  static constexpr std::string_view kService = "type_description_interfaces/srv/GetTypeDescription";
  std::string type_name;  // "pkg/msg/Name"
  std::string type_hash;  // "RIHS01_<64 hex>"
  bool include_type_sources = true;
  bool operator==(const GetTypeDescriptionRequest&) const = default;
};
struct GetTypeDescriptionResponse {
  static constexpr std::string_view kService = GetTypeDescriptionRequest::kService;
  bool successful = false;
  std::string failure_reason;
  TypeDescription type_description;
  std::vector<TypeSource> type_sources;  // the type's, then its referenced types' (when asked for)
  std::vector<KeyValue> extra_information;
  bool operator==(const GetTypeDescriptionResponse&) const = default;
};

// Codecs, as rbsim/interfaces.hpp's: encode() replaces `out` with the message's CDR; decode() fills
// `out` (replaced whole) or fails naming the type and the offset, `out` then unspecified.
#define RBSIM_TYPE_DESCRIPTION_CODEC(T)      \
  void encode(const T& message, Bytes& out); \
  [[nodiscard]] Status decode(std::span<const std::byte> cdr, T& out);
RBSIM_TYPE_DESCRIPTION_CODEC(TypeDescription)
RBSIM_TYPE_DESCRIPTION_CODEC(TypeSource)
RBSIM_TYPE_DESCRIPTION_CODEC(GetTypeDescriptionRequest)
RBSIM_TYPE_DESCRIPTION_CODEC(GetTypeDescriptionResponse)
#undef RBSIM_TYPE_DESCRIPTION_CODEC

}  // namespace rbsim::msgs
