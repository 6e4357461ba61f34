// simulation_interfaces' services on the node (the ROS 2 standard simulator interfaces, served
// under the node's name as Gazebo serves them under /gzserver/): simulator features, simulation
// state, reset, stepping, and the entities (every body is one, named body_<i> as its /tf child
// frame without the namespace), spawning and deleting them (spawning.cpp; a spawn's uri read from
// the spawnables folders, resource_folder.hpp), and worlds (world_services.cpp: loaded from the
// worlds folders or as text). State changes go through control::Commands, as the
// node's own services do, so they are recorded on <node>/commands and re-simulated; reads of the
// world run on the loop's thread at a step boundary (Controller::read).
#pragma once

#include <atomic>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <string_view>
#include <tuple>
#include <vector>

#include "rbsim/control.hpp"
#include "rbsim/service.hpp"
#include "rbsim/simulation_interfaces.hpp"
#include "resource_folder.hpp"

namespace rbsim::node {

// What the simulation_interfaces services' files share (simulation_services.cpp, spawning.cpp).
namespace simulation_detail {
// A world's text, as a file or a resource_string: larger ones are refused before they are parsed.
constexpr std::size_t kMaxWorldBytes = 64u << 20;
// A folder listing (get_spawnables, get_available_worlds): at most this many entries of any kind
// looked at, and bytes of files read for their descriptions in one call (past it, files are listed
// by uri alone).
constexpr std::size_t kMaxFolderEntries = 100000;
constexpr std::size_t kMaxListingBytes = 16u << 20;
inline msgs::simulation::Result ok() {
  return msgs::simulation::Result{msgs::simulation::Result::kOk, {}};
}
inline msgs::simulation::Result failure(std::uint8_t code, std::string message) {
  return msgs::simulation::Result{code, std::move(message)};
}
// A request that does not decode: answered RESULT_OPERATION_FAILED with the decoder's words.
template <class Res>
auto refuse_malformed() {
  return [](const Error& e) {
    Res r;
    r.result = failure(msgs::simulation::Result::kOperationFailed, e.message);
    return std::optional<Res>(std::move(r));
  };
}
}  // namespace simulation_detail

// A pose in the plane: the position (x, y, 0) and a rotation about +z as theta (rad, CCW > 0), or
// a Result with code `invalid` when it is not one.
std::optional<msgs::simulation::Result> planar_pose(const msgs::simulation::Vector3& p,
                                                    const msgs::Quaternion& q, std::uint8_t invalid,
                                                    Vec2& position, double& theta);

class SimulationServices {
 public:
  using Apply = std::function<control::CommandResult(control::Command)>;
  // Several commands applied at one step boundary (Controller::submit_all), a result each.
  using ApplyAll = std::function<std::vector<control::CommandResult>(std::vector<control::Command>)>;
  // `apply` submits a command and waits (bounded) for its result, as NodeServices does for its own
  // services, `apply_all` several at one boundary; reads wait up to `timeout_s` for their boundary.
  // `spawnables`: the folders a spawn's uri may name and GetSpawnables lists (none: uris refused,
  // GetSpawnables unsupported); `worlds` the same for LoadWorld and GetAvailableWorlds. `quit`
  // ends the node (STATE_QUITTING); empty: QUITTING is unsupported.
  SimulationServices(control::Controller& controller, Apply apply, ApplyAll apply_all, double timeout_s,
                     ResourceFolders spawnables, ResourceFolders worlds, std::function<void()> quit = {})
      : controller_(controller),
        apply_(std::move(apply)),
        apply_all_(std::move(apply_all)),
        timeout_s_(timeout_s),
        spawnables_(std::move(spawnables)),
        worlds_(std::move(worlds)),
        quit_(std::move(quit)) {}

  // The services, as (name under the node, type, handler).
  using Entry = std::tuple<std::string, std::string, ServiceServer::Handler>;
  void add(std::vector<Entry>& out);
  // The largest request a service takes (larger ones are dropped unread by the middleware): the
  // middleware's default, but for spawn_entities, whose calls of more entities than it spawns at
  // once must arrive to be refused in words.
  static std::size_t max_request_bytes(std::string_view service);

 private:
  control::Controller& controller_;
  Apply apply_;
  ApplyAll apply_all_;
  double timeout_s_;
  ResourceFolders spawnables_;
  ResourceFolders worlds_;
  std::atomic<bool> loading_{false};  // a load_world read, parsed or applied: STATE_LOADING_WORLD
  // STOPPED: set by a stop (and at start), cleared by a play or a pause; the state reads STOPPED
  // while it is set and the world is paused at step 0.
  std::atomic<bool> stopped_{true};
  std::function<void()> quit_;
  std::atomic<bool> quitting_{false};  // QUITTING asked: the state reads QUITTING from then on
  using StateNow = std::function<std::optional<msgs::simulation::State>()>;
  using Run = std::function<control::CommandResult(control::CommandKind)>;
  void add_state(std::vector<Entry>& out);
  msgs::simulation::Result set_state(std::uint8_t target, const StateNow& state_now, const Run& command);
  msgs::simulation::Result step(std::uint64_t steps);
  msgs::simulation::Result set_entity_state(const msgs::simulation::SetEntityStateRequest& req);
  void add_entities(std::vector<Entry>& out);
  void add_entity(std::vector<Entry>& out);
  // Spawning (spawning.cpp).
  void add_spawning(std::vector<Entry>& out);
  msgs::simulation::SpawnEntityResponse spawn_entity(const msgs::simulation::SpawnEntityRequest& req);
  msgs::simulation::SpawnEntitiesResponse spawn_entities(const msgs::simulation::SpawnEntitiesRequest& req);
  msgs::simulation::GetSpawnablesResponse get_spawnables(
      const msgs::simulation::GetSpawnablesRequest& req) const;
  // Worlds (world_services.cpp).
  void add_worlds(std::vector<Entry>& out);
  msgs::simulation::LoadWorldResponse load_world(const msgs::simulation::LoadWorldRequest& req);
  msgs::simulation::UnloadWorldResponse unload_world();
  msgs::simulation::GetCurrentWorldResponse current_world() const;
  msgs::simulation::GetAvailableWorldsResponse available_worlds(
      const msgs::simulation::GetAvailableWorldsRequest& req) const;
};

}  // namespace rbsim::node
