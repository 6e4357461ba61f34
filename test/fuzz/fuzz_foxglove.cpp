// libFuzzer target: the Foxglove server's client-message handler (ClientProtocol, with the
// parameter ops, 5 services and clientPublish on /f/command_in offered) and the queue its replies
// go into. The input is a sequence
// of client frames separated by a 0x00 byte; a frame whose first byte is 0x01 is handed over as a
// binary frame without that byte (a service call when it then starts with 0x02, a client message
// when 0x01), any other as a
// text frame, all to one ClientProtocol, so subscribe/unsubscribe sequences build up state. After
// every frame the bookkeeping must agree with itself, every reply must be a JSON status or
// serviceCallFailure, a service call handed over must name an offered service and encoding, a
// client message an advertised channel's encoding, and the client channels stay within bounds;
// the replies and a message per subscription go through a small ClientQueue, whose limits must
// hold.
#include <nlohmann/json.hpp>

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "rbsim/foxglove.hpp"

namespace fox = rbsim::foxglove;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  constexpr std::uint32_t kChannels = 7;
  constexpr std::uint32_t kServices = 5;
  fox::ClientProtocol protocol(kChannels, true, kServices);
  protocol.accept_publish("/f/command_in");
  fox::ClientQueue queue(fox::QueueLimits{8, 4096});
  fox::ClientProtocol::Outcome out;
  fox::ClientQueue::Frame frame;
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  std::size_t start = 0;
  std::uint64_t step = 0;
  // At most 64 frames an input: more only repeats the same paths, slower.
  for (int frames = 0; frames < 64 && start <= input.size(); ++frames) {
    std::size_t end = input.find('\0', start);
    if (end == std::string_view::npos) end = input.size();
    const std::string_view f = input.substr(start, end - start);
    if (!f.empty() && f[0] == '\x01') {
      protocol.handle_binary(f.substr(1), out);
    } else {
      protocol.handle_text(f, out);
    }
    // Bookkeeping: the count is the number of channels with a subscription, ids unique.
    std::size_t count = 0;
    for (fox::ChannelId ch = 1; ch <= kChannels; ++ch) {
      const auto sub = protocol.subscription(ch);
      if (!sub) continue;
      ++count;
      for (fox::ChannelId other = ch + 1; other <= kChannels; ++other) {
        if (protocol.subscription(other) == sub) __builtin_trap();
      }
    }
    if (count != protocol.subscription_count()) __builtin_trap();
    for (const auto& s : out.subscribed) {
      if (protocol.subscription(s.channel) != s.id) __builtin_trap();
    }
    for (const auto& s : out.unsubscribed) queue.remove_subscription(s.id);
    if (out.replies.size() > 1) __builtin_trap();  // one status per frame at most
    for (const std::string& r : out.replies) {
      const auto j = nlohmann::json::parse(r, nullptr, false);
      if (j.is_discarded()) __builtin_trap();
      const std::string op = j.value("op", "");
      if (op != "status" && op != "serviceCallFailure") __builtin_trap();
      queue.push_text(r);
    }
    if (out.call) {
      if (out.call->service == 0 || out.call->service > kServices) __builtin_trap();
      if (out.call->encoding != "cdr" && out.call->encoding != "json") __builtin_trap();
      if (!out.replies.empty()) __builtin_trap();  // a call is carried out or refused, not both
    }
    if (protocol.client_channel_count() > fox::kMaxClientChannels) __builtin_trap();
    if (out.published) {
      if (out.published->encoding != "cdr" && out.published->encoding != "json") __builtin_trap();
      if (!out.replies.empty() || out.call) __builtin_trap();
    }
    if (out.parameters && out.parameters->values.size() != out.parameters->untyped_integer.size())
      __builtin_trap();
    for (fox::ChannelId ch = 1; ch <= kChannels; ++ch) {
      if (const auto sub = protocol.subscription(ch)) {
        const std::byte payload[64]{};
        queue.push_message(ch == 1 ? fox::ClientQueue::Kind::Latched : fox::ClientQueue::Kind::PerStep, *sub,
                           step, payload);
      }
    }
    queue.push_time(step++);
    if (step % 3 == 0) queue.pop(frame);
    if (end == input.size()) break;
    start = end + 1;
  }
  while (queue.pop(frame)) {
  }
  if (queue.bytes() != 0 || queue.size() != 0) __builtin_trap();
  return 0;
}
