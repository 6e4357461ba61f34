// libFuzzer target: the CDR decoders. The first input byte picks one of rbsim's seven message
// types; the rest is the CDR payload given to the schema-driven decoder (what `rbsim check`
// uses), to its field-path naming, and for the scene and body states to the typed decoders
// (what export and render use). Each returns a value or a clean error on any bytes.
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "rbsim/msgs.hpp"

namespace {
struct Decoders {
  std::array<std::optional<rbsim::msgs::MessageDecoder>, rbsim::msgs::kTopicCount> by_topic;
  Decoders() {
    for (const rbsim::msgs::TopicSpec& spec : rbsim::msgs::topics()) {
      auto schema = rbsim::msgs::ros2msg_schema(spec.type);
      if (!schema) __builtin_trap();
      auto decoder = rbsim::msgs::MessageDecoder::create(spec.type, schema.value());
      if (!decoder) __builtin_trap();
      by_topic[static_cast<std::size_t>(spec.id)].emplace(std::move(decoder.value()));
    }
  }
};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const Decoders decoders;
  if (size == 0) return 0;
  const auto id = static_cast<rbsim::msgs::TopicId>(data[0] % rbsim::msgs::kTopicCount);
  const std::span<const std::byte> cdr(reinterpret_cast<const std::byte*>(data + 1), size - 1);
  std::vector<rbsim::msgs::Scalar> scalars;
  const auto& decoder = *decoders.by_topic[static_cast<std::size_t>(id)];
  if (decoder.decode(cdr, scalars)) {
    // Field paths are computed by a second walk over the same bytes: ask for a few.
    for (std::size_t i : {std::size_t{0}, scalars.size() / 2, scalars.size() - 1}) {
      if (i < scalars.size()) (void)decoder.path(cdr, i);
    }
  }
  if (id == rbsim::msgs::TopicId::SceneDescription) (void)rbsim::msgs::decode_scene(cdr);
  if (id == rbsim::msgs::TopicId::BodyStates) {
    rbsim::msgs::BodyStatesMessage states;
    (void)rbsim::msgs::decode_body_states(cdr, states);
  }
  return 0;
}
