// The field layout of a ros2msg schema, for rbsim check's comparer: every scalar that
// msgs::MessageDecoder produces for a message maps to a field group, its path with array indices
// collapsed ("bodies[].x", "bodies.length"). The schema is parsed by the decoder's own rules.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "rbsim/msgs.hpp"

namespace rbsim::check {

struct FieldGroup {
  std::string path;
  msgs::Scalar::Kind kind;
  bool operator==(const FieldGroup&) const = default;
};

// The group of each scalar of one message layout, and the sequence lengths that fix the layout:
// another message with the same scalar count and the same lengths at the same places has the same
// plan.
struct Plan {
  std::vector<std::uint32_t> group;
  std::vector<std::pair<std::uint32_t, std::uint64_t>> lengths;  // (scalar index, value)
  std::ptrdiff_t step = -1;  // scalar index of a top-level "step" field, or -1
  bool fits(std::span<const msgs::Scalar> s) const {
    if (s.size() != group.size()) return false;
    for (const auto& [index, value] : lengths) {
      if (s[index].kind != msgs::Scalar::Kind::Length || s[index].u != value) return false;
    }
    return true;
  }
};

// A value pair of two messages whose layouts differ (a: run index, b: golden index).
struct Pair {
  std::size_t a = 0, b = 0;
  std::uint32_t group = 0;
};

class Layout {
 public:
  static Result<Layout> create(std::string_view type, std::string_view schema);

  const std::vector<FieldGroup>& groups() const { return groups_; }
  bool has_step() const { return has_step_; }
  bool same_fields(const Layout& other) const { return groups_ == other.groups_; }

  // Fills `plan` for the scalars of one decoded message; false when they do not fit the schema.
  bool map(std::span<const msgs::Scalar> s, Plan& plan) const;
  // Pairs the values two messages have in common (elements past the shorter sequence are left
  // out; the differing lengths themselves are paired). False when either does not fit.
  bool pair(std::span<const msgs::Scalar> a, std::span<const msgs::Scalar> b, std::vector<Pair>& out) const;
  // Walks one CDR message without decoding it (the structure only: lengths are read, values
  // skipped) and adds the number of values of every group to counts[group]. For a message pair
  // with identical bytes, whose values all match. False when the data does not fit the schema.
  bool count(std::span<const std::byte> cdr, std::vector<std::uint64_t>& counts) const;

  // One value of a flat element: its byte offset from the element's start.
  struct Op {
    std::uint32_t offset = 0;
    std::uint8_t size = 0;
    msgs::Scalar::Kind kind = msgs::Scalar::Kind::Float;
    std::uint32_t group = 0;
  };

  struct Field {
    std::string name;
    bool primitive = false;
    msgs::Scalar::Kind kind = msgs::Scalar::Kind::Float;
    std::uint8_t size = 0;  // primitives: bytes on the wire (0: string)
    using Array = msgs::MsgField::Array;
    Array array = Array::None;
    std::uint32_t fixed = 0;
    std::uint32_t group = 0;         // primitives: the group of every element
    std::uint32_t length_group = 0;  // sequences: the group of the length
    std::vector<Field> children;     // nested types
    // Nested types of fixed size (no strings or sequences inside): the bytes one element takes
    // when it starts at offset % 8 == r (alignment included), and the values it holds per group.
    bool flat = false;
    std::uint32_t flat_size[8] = {};
    std::vector<std::pair<std::uint32_t, std::uint64_t>> flat_groups;
    std::vector<Op> flat_ops[8];  // the values of one element starting at offset % 8 == r
  };
  const std::vector<Field>& root() const { return root_; }

 private:
  std::vector<Field> root_;
  std::vector<FieldGroup> groups_;
  bool has_step_ = false;
};

}  // namespace rbsim::check
