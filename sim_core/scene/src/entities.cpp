// The cold data of a world's bodies and springs: names and colours (rbsim/scene.hpp's Entities).
#include <charconv>
#include <string>

#include "rbsim/scene.hpp"

namespace rbsim {

Color default_spring_color() {
  return {0.25, 0.25, 0.25};
}

std::string scene_body_name(std::int32_t id) {
  return "body_" + std::to_string(id);
}

std::optional<std::int32_t> scene_body_id(std::string_view name) {
  constexpr std::string_view kBody = "body_";
  if (!name.starts_with(kBody)) return std::nullopt;
  const std::string_view digits = name.substr(kBody.size());
  if (digits.empty() || digits.front() < '0' || digits.front() > '9' ||
      (digits.size() > 1 && digits.front() == '0'))
    return std::nullopt;
  std::int32_t id = 0;
  const char* end = digits.data() + digits.size();
  const auto [ptr, ec] = std::from_chars(digits.data(), end, id);
  if (ec != std::errc{} || ptr != end) return std::nullopt;
  return id;
}

Entities entities_of(const Scene& scene) {
  Entities e;
  const auto n = static_cast<std::int32_t>(scene.world.bodies.size());
  e.body_names.reserve(static_cast<std::size_t>(n));
  for (std::int32_t b = 0; b < n; ++b) e.body_names.push_back(scene_body_name(b));
  e.body_colors = scene.body_colors;
  e.spring_colors = scene.spring_colors;
  e.scene = &scene;
  return e;
}

}  // namespace rbsim
