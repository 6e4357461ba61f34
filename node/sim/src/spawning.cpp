// simulation_interfaces' spawning services on the node (simulation_services.hpp): SpawnEntity,
// SpawnEntities, DeleteEntity and GetSpawnables; ResetSimulation's SCOPE_SPAWNED is the state
// services'. A spawn is checked, its fragment read (a uri: a file of the spawnables folder, through
// resource_folder.hpp's one policy) and parsed here, off the loop's thread, within FragmentLimits;
// then it is a spawn_entity command carrying the fragment's text, applied at the next boundary
// (while paused, at once), so a recording re-simulates it without the file.
#include <algorithm>
#include <map>
#include <memory>
#include <optional>

#include "rbsim/counts.hpp"
#include "rbsim/scene.hpp"
#include "simulation_services.hpp"

namespace rbsim::node {

namespace {

namespace sim = msgs::simulation;
using control::Command;
using control::CommandKind;
using control::CommandResult;
using sim::Result;
using simulation_detail::failure;
using simulation_detail::ok;
using simulation_detail::refuse_malformed;
using Codes = sim::SpawnResult;  // SpawnEntity's and SpawnEntities' per-entity codes

// SpawnEntities: more entities in one call are refused whole; the fragments' texts of one call
// (each a command's copy) add up to at most this. The request itself may be this large.
constexpr std::size_t kMaxSpawnsPerCall = 1000;
constexpr std::size_t kMaxCallFragmentBytes = 16u << 20;
// GetSpawnables: at most this many fragments listed (a folder with more is refused); the entries
// looked at and bytes read are simulation_detail's listing bounds.
constexpr std::size_t kMaxSpawnables = 10000;
using simulation_detail::kMaxFolderEntries;
using simulation_detail::kMaxListingBytes;
constexpr std::string_view kFragmentSuffix = ".xml";

// ROS 2's name rules for a spawned entity's name and namespace: tokens of letters, digits and
// '_', not starting with a digit, joined by '/' (a namespace may start with one; a name may not).
bool valid_name(std::string_view name, bool is_namespace) {
  if (is_namespace && name.starts_with('/')) name.remove_prefix(1);
  if (name.empty() || name.size() > 255) return false;
  std::size_t token = 0;
  for (std::size_t k = 0; k <= name.size(); ++k) {
    if (k == name.size() || name[k] == '/') {
      if (k == token || (name[token] >= '0' && name[token] <= '9')) return false;
      token = k + 1;
      continue;
    }
    const char c = name[k];
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_'))
      return false;
  }
  return true;
}

// A fragment's text and its parse, or the code and message refusing it.
struct Loaded {
  std::string text;
  std::shared_ptr<const Fragment> fragment;  // null: refused
  Result refused;
};
// The uris one call read, each read and parsed once.
using Loads = std::map<std::string, Loaded, std::less<>>;

Loaded parse(std::string text, const std::string& source) {
  Loaded l;
  rbsim::Result<Fragment> f = parse_fragment(text, source);
  if (!f) {
    l.refused = failure(Codes::kResourceParseError, f.error().message);
    return l;
  }
  l.fragment = std::make_shared<const Fragment>(std::move(f.value()));
  l.text = std::move(text);
  return l;
}

// The fragment a uri names in the spawnables folders: a file that is not there or not allowed is
// NO_RESOURCE, one too large or that does not parse RESOURCE_PARSE_ERROR (as a resource_string
// over the fragment limit is); the parse's errors name the uri and the line.
Loaded read_uri(const std::string& uri, const ResourceFolders& folders) {
  Loaded l;
  if (folders.empty()) {
    l.refused =
        failure(Codes::kNoResource, "entity_resource.uri '" + uri +
                                        "': this node reads no files (start rbsim node with "
                                        "--spawnables DIR to spawn a folder's fragments by uri), "
                                        "or give the fragment's text as entity_resource.resource_string");
    return l;
  }
  const std::size_t limit = FragmentLimits{}.max_bytes;
  ResourceFolders::Text t = folders.read(uri, limit);
  switch (t.refusal) {
    case ResourceFolders::Refusal::None:
      return parse(std::move(t.text), uri);
    case ResourceFolders::Refusal::TooLarge:
      l.refused =
          failure(Codes::kResourceParseError, "entity_resource." + t.message + " (the fragment limit)");
      return l;
    default:
      l.refused = failure(Codes::kNoResource, "entity_resource." + t.message);
      return l;
  }
}

// One spawn checked, its fragment read and parsed: a command, or the result refusing it.
struct Prepared {
  std::optional<Command> command;
  Result refused;
};

Prepared refuse(std::uint8_t code, std::string message) {
  return Prepared{std::nullopt, failure(code, std::move(message))};
}

// The checks of SpawnEntity.srv's request (the fields of SpawnEntity.msg), in the order the codes
// are given: name, namespace, resource, pose, then the fragment. The full name is NAMESPACE/NAME.
Prepared prepare(const sim::SpawnEntity& req, const ResourceFolders& folders, Loads& loads) {
  // SpawnEntity.srv: an empty name without allow_renaming is NAME_INVALID (a fragment names no
  // entity); with it, a name is generated.
  if (req.name.empty() && !req.allow_renaming)
    return refuse(Codes::kNameInvalid,
                  "name: empty, and allow_renaming is false (give a name, or allow one to be "
                  "generated)");
  if (!req.name.empty() && (!valid_name(req.name, false) || scene_body_id(req.name)))
    return refuse(Codes::kNameInvalid, "name '" + req.name +
                                           "': letters, digits and '_' in '/'-separated tokens, none "
                                           "starting with a digit, and not body_<id> (a scene body's)");
  std::string ns = req.entity_namespace;
  if (!ns.empty() && !valid_name(ns, true))
    return refuse(Codes::kNamespaceInvalid,
                  "entity_namespace '" + ns + "': ROS 2 name rules, as for the name");
  if (ns.starts_with('/')) ns.erase(0, 1);
  const sim::Resource& res = req.entity_resource;
  if (res.uri.empty() && res.resource_string.empty())
    return refuse(Codes::kNoResource,
                  "entity_resource: uri and resource_string are empty (a FOSSSim scene fragment of one body, "
                  "or a uri naming one in the spawnables folder)");
  if (!req.initial_pose.frame_id.empty() && req.initial_pose.frame_id != "world")
    return refuse(Codes::kInvalidPose, "initial_pose.header.frame_id '" + req.initial_pose.frame_id +
                                           "': only 'world' (or empty)");
  Command c;
  c.kind = CommandKind::Spawn;
  if (std::optional<Result> bad = planar_pose(req.initial_pose.position, req.initial_pose.orientation,
                                              Codes::kInvalidPose, c.spawn.position, c.spawn.theta))
    return Prepared{std::nullopt, *bad};
  // A uri's file (resource_string is then ignored, as Resource.msg says), read once per call.
  Loaded own;
  const Loaded* fragment = &own;
  if (!res.uri.empty()) {
    auto it = loads.find(res.uri);
    if (it == loads.end()) it = loads.emplace(res.uri, read_uri(res.uri, folders)).first;
    fragment = &it->second;
  } else {
    own = parse(res.resource_string, "resource_string");
  }
  if (!fragment->fragment) return Prepared{std::nullopt, fragment->refused};
  c.spawn.resource = fragment->text;
  c.spawn.uri = res.uri;
  c.spawn.fragment = fragment->fragment;
  const std::string name = req.name.empty() && !ns.empty() ? "entity" : req.name;
  c.spawn.name = ns.empty() || name.empty() ? name : ns + "/" + name;
  c.spawn.allow_renaming = req.allow_renaming;
  return Prepared{std::move(c), ok()};
}

// A spawn command's outcome in SpawnEntity's codes.
Result outcome(const CommandResult& r) {
  if (r.successful) return ok();
  switch (r.refusal) {
    case control::Refusal::NameTaken:
      return failure(Codes::kNameNotUnique, r.message);
    case control::Refusal::NoSuchEntity:
      return failure(Codes::kMissingAssets, r.message);  // a spring names a body the world does not have
    case control::Refusal::BadResource:
      return failure(Codes::kResourceParseError, r.message);
    case control::Refusal::NoWorld:  // no world to spawn into: the operation, not the request
    case control::Refusal::Other:
      break;
  }
  return failure(Result::kOperationFailed, r.message);
}

sim::SpawnEntity as_entity(const sim::SpawnEntityRequest& r) {
  return sim::SpawnEntity{r.name, r.allow_renaming, r.entity_resource, r.entity_namespace, r.initial_pose};
}

// A fragment's hull box as GetEntityBounds gives a body's: TYPE_BOX in its own frame, about its
// centre of mass (where initial_pose puts it), upper right corner first.
sim::Bounds hull_box(const BodyDef& body) {
  Vec2 centre{0.0, 0.0};
  double mass = 0.0;
  for (std::size_t i = 0; i < body.hull.size(); ++i) {
    centre += body.masses[i] * body.hull[i];
    mass += body.masses[i];
  }
  centre /= mass;
  Vec2 lo = body.hull[0] - centre, hi = lo;
  for (const Vec2& v : body.hull) {
    lo = lo.cwiseMin(v - centre);
    hi = hi.cwiseMax(v - centre);
  }
  return sim::Bounds{static_cast<std::uint8_t>(sim::BoundsType::Box),
                     {sim::Vector3{hi.x(), hi.y(), 0.0}, sim::Vector3{lo.x(), lo.y(), 0.0}}};
}

}  // namespace

// The requests a spawn service reads: a call's fragments (spawn_entities), or one fragment at its
// limit and the request's other fields (spawn_entity), so a fragment over the limit is answered in
// words rather than dropped unread as a larger request to another service is.
std::size_t SimulationServices::max_request_bytes(std::string_view service) {
  if (service == "spawn_entities") return kMaxCallFragmentBytes;
  if (service == "spawn_entity") return 2 * FragmentLimits{}.max_bytes;
  if (service == "load_world")
    return simulation_detail::kMaxWorldBytes + (64u << 10);  // and the other fields
  return ServiceOptions{}.max_request_bytes;
}

// SpawnEntity: one spawn, applied at the next boundary.
sim::SpawnEntityResponse SimulationServices::spawn_entity(const sim::SpawnEntityRequest& req) {
  Loads loads;
  Prepared p = prepare(as_entity(req), spawnables_, loads);
  if (!p.command) return sim::SpawnEntityResponse{p.refused, {}};
  const CommandResult r = apply_(std::move(*p.command));
  return sim::SpawnEntityResponse{outcome(r), r.successful ? r.entity : std::string{}};
}

// SpawnEntities: each entity checked as SpawnEntity's request, those that pass applied together at
// one step boundary (in order: a fragment's spring may name an entity spawned before it in the same
// call), a result each; ENTITIES_SPAWN_FAILED when any failed. More than kMaxSpawnsPerCall
// entities, or fragments adding up to more than kMaxCallFragmentBytes, are refused whole
// (RESULT_OPERATION_FAILED, no results): nothing is spawned.
sim::SpawnEntitiesResponse SimulationServices::spawn_entities(const sim::SpawnEntitiesRequest& req) {
  using Res = sim::SpawnEntitiesResponse;
  const std::size_t n = req.spawn_requests.size();
  if (n > kMaxSpawnsPerCall)
    return Res{failure(Result::kOperationFailed,
                       "spawn_requests: " + group_digits(n) + " entities in one call, at most " +
                           group_digits(kMaxSpawnsPerCall) + ": nothing was spawned (split the call)"),
               {}};
  Loads loads;
  std::vector<Prepared> prepared;
  std::size_t bytes = 0;
  for (const sim::SpawnEntity& e : req.spawn_requests) {
    prepared.push_back(prepare(e, spawnables_, loads));
    if (prepared.back().command) bytes += prepared.back().command->spawn.resource.size();
    if (bytes > kMaxCallFragmentBytes)
      return Res{
          failure(Result::kOperationFailed, "spawn_requests: the fragments of one call add up to more than " +
                                                group_digits(kMaxCallFragmentBytes) +
                                                " bytes: nothing was spawned (split the call)"),
          {}};
  }
  std::vector<Command> commands;
  std::vector<std::size_t> applied;  // the request index of each command
  for (std::size_t k = 0; k < n; ++k) {
    if (!prepared[k].command) continue;
    applied.push_back(k);
    commands.push_back(std::move(*prepared[k].command));
  }
  const std::vector<CommandResult> results =
      commands.empty() ? std::vector<CommandResult>{} : apply_all_(std::move(commands));
  Res res{ok(), std::vector<sim::SpawnResult>(n)};
  for (std::size_t k = 0; k < n; ++k)
    res.results[k].result =
        prepared[k].command ? failure(Result::kOperationFailed, "not applied") : prepared[k].refused;
  for (std::size_t i = 0; i < applied.size() && i < results.size(); ++i) {
    sim::SpawnResult& r = res.results[applied[i]];
    r.result = outcome(results[i]);
    if (results[i].successful) r.entity_name = results[i].entity;
  }
  const auto failed = static_cast<std::size_t>(
      std::count_if(res.results.begin(), res.results.end(),
                    [](const sim::SpawnResult& r) { return r.result.result != Result::kOk; }));
  if (failed > 0)
    res.result =
        failure(Res::kEntitiesSpawnFailed, group_digits(failed) + " of " + group_digits(n) + " " +
                                               plural(n, "spawn", "spawns") + " failed (results say which)");
  return res;
}

// GetSpawnables: the fragments of the spawnables folder (its *.xml regular files that parse), by
// name, each with the uri to give back, its <description> and its hull box. `sources` are not
// searched (the folder is all the node reads): named in the message, the call still RESULT_OK, as
// the definition says. Without a folder: RESULT_FEATURE_UNSUPPORTED (SPAWNABLES is not listed).
sim::GetSpawnablesResponse SimulationServices::get_spawnables(const sim::GetSpawnablesRequest& req) const {
  using Res = sim::GetSpawnablesResponse;
  if (spawnables_.empty())
    return Res{
        failure(Result::kFeatureUnsupported,
                "no spawnables folder: start rbsim node with --spawnables DIR (SPAWNABLES is not listed)"),
        {}};
  const ResourceFolders::Listing listing =
      spawnables_.list(kFragmentSuffix, kMaxSpawnables, kMaxFolderEntries);
  if (!listing.refused.empty()) return Res{failure(Result::kOperationFailed, listing.refused), {}};
  Res res{ok(), {}};
  std::vector<std::string> notes;
  std::size_t read = 0, unread = 0;
  for (const ResourceFolders::Entry& e : listing.files) {
    sim::Spawnable s;
    s.entity_resource.uri = e.uri;
    if (read >= kMaxListingBytes) {
      ++unread;
      res.spawnables.push_back(std::move(s));
      continue;
    }
    ResourceFolders::Text t = spawnables_.read(e.uri, FragmentLimits{}.max_bytes);
    read += t.text.size();
    rbsim::Result<Fragment> f = t.refusal == ResourceFolders::Refusal::None
                                    ? parse_fragment(t.text, e.uri)
                                    : rbsim::Result<Fragment>(Error{t.message});
    if (!f) {
      notes.push_back("left out " + f.error().message);
      continue;
    }
    s.description = f.value().description;
    s.spawn_bounds = hull_box(f.value().body);
    res.spawnables.push_back(std::move(s));
  }
  if (unread > 0)
    notes.push_back(group_digits(unread) + " " + plural(unread, "file", "files") +
                    " listed without description or bounds (a call reads at most " +
                    group_digits(kMaxListingBytes) + " bytes of fragments)");
  if (!req.sources.empty()) {
    std::string sources;
    for (const std::string& src : req.sources) sources += (sources.empty() ? "'" : ", '") + src + "'";
    notes.push_back("sources " + sources + " not searched: only the spawnables folder is");
  }
  for (const std::string& note : notes)
    res.result.error_message += (res.result.error_message.empty() ? "" : "; ") + note;
  return res;
}

// SpawnEntity, SpawnEntities, DeleteEntity and GetSpawnables.
void SimulationServices::add_spawning(std::vector<Entry>& out) {
  out.emplace_back(
      "spawn_entity", std::string(sim::SpawnEntityRequest::kService),
      typed_handler<sim::SpawnEntityRequest, sim::SpawnEntityResponse>(
          [this](const RequestHeader&, const sim::SpawnEntityRequest& req) { return spawn_entity(req); },
          refuse_malformed<sim::SpawnEntityResponse>()));
  out.emplace_back(
      "spawn_entities", std::string(sim::SpawnEntitiesRequest::kService),
      typed_handler<sim::SpawnEntitiesRequest, sim::SpawnEntitiesResponse>(
          [this](const RequestHeader&, const sim::SpawnEntitiesRequest& req) { return spawn_entities(req); },
          refuse_malformed<sim::SpawnEntitiesResponse>()));
  // The reply's message names the springs removed with the body.
  out.emplace_back(
      "delete_entity", std::string(sim::DeleteEntityRequest::kService),
      typed_handler<sim::DeleteEntityRequest, sim::DeleteEntityResponse>(
          [this](const RequestHeader&, const sim::DeleteEntityRequest& req) {
            if (req.entity.empty())  // names nothing: no command
              return sim::DeleteEntityResponse{failure(Result::kNotFound, "entity: empty, names no entity")};
            Command c;
            c.kind = CommandKind::Delete;
            c.entity = req.entity;
            const CommandResult r = apply_(std::move(c));
            if (r.successful) return sim::DeleteEntityResponse{failure(Result::kOk, r.message)};
            return sim::DeleteEntityResponse{failure(
                r.refusal == control::Refusal::NoSuchEntity ? Result::kNotFound : Result::kOperationFailed,
                r.message)};
          },
          refuse_malformed<sim::DeleteEntityResponse>()));
  out.emplace_back(
      "get_spawnables", std::string(sim::GetSpawnablesRequest::kService),
      typed_handler<sim::GetSpawnablesRequest, sim::GetSpawnablesResponse>(
          [this](const RequestHeader&, const sim::GetSpawnablesRequest& req) { return get_spawnables(req); },
          refuse_malformed<sim::GetSpawnablesResponse>()));
}

}  // namespace rbsim::node
