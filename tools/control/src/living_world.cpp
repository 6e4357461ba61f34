// The living world: bodies spawned from fragments and deleted at step boundaries, by name.
//
// A spawn appends a body (and its springs) to the world, a delete removes one with the springs
// attached to it (World::add_body, remove_body: dense arrays in a stable order), so a run with
// these commands steps bit for bit as a run of the scene edited the same way, set to the same
// state at the same step. Names: the scene's bodies are body_<id>; a spawned body has its own
// name, and no name is given twice in a session (the ids are never reused either).
#include <cmath>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "rbsim/control.hpp"
#include "wording.hpp"

namespace rbsim::control {

namespace {

using detail::refuse;

// The name a spawn takes: as asked if never used in the session; else (renaming allowed, or none
// asked) the first unused of <name>_1, <name>_2, ... A scene body's name (body_<id>) is never
// given. `refused` is set when no name is.
std::string spawn_name(const SpawnArgs& a, const std::set<std::string, std::less<>>& used, bool taken_now,
                       std::optional<CommandResult>& refused) {
  if (scene_body_id(a.name)) {
    refused = refuse(Refusal::Other,
                     "spawn_entity: '" + a.name + "' is reserved for the scene's bodies (body_<id>)");
    return {};
  }
  if (!a.name.empty() && !used.contains(a.name)) return a.name;
  if (!a.name.empty() && !a.allow_renaming) {
    refused = refuse(Refusal::NameTaken, "spawn_entity: the name '" + a.name + "' is " +
                                             (taken_now ? "taken" : "used earlier in the session") +
                                             " and renaming is not allowed");
    return {};
  }
  const std::string stem = a.name.empty() ? "entity" : a.name;
  for (std::uint64_t k = 1;; ++k) {
    std::string name = stem + "_" + std::to_string(k);
    if (!used.contains(name) && !scene_body_id(name)) return name;
  }
}

std::string id_list(const std::vector<std::int32_t>& ids) {
  std::string out;
  for (std::size_t k = 0; k < ids.size(); ++k) out += (k > 0 ? ", " : "") + std::to_string(ids[k]);
  return out;
}

}  // namespace

std::optional<std::int32_t> Controller::find_entity(std::string_view name) const {
  if (const auto it = spawned_ids_.find(name); it != spawned_ids_.end()) return it->second;
  const std::optional<std::int32_t> id = scene_body_id(name);
  // body_<id> names a scene body only: a spawned body of that id has its own name.
  if (id && !spawned_names_.contains(*id)) return id;
  return std::nullopt;
}

std::string Controller::entity_name(std::int32_t id) const {
  if (const auto it = spawned_names_.find(id); it != spawned_names_.end()) return it->second;
  return scene_body_name(id);
}

void Controller::follow_structure(const World& world, CommandResult* r) {
  table_.follow_structure(world, r != nullptr ? &r->added : nullptr, r != nullptr ? &r->removed : nullptr);
  next_body_id_ = world.next_body_id();
  next_spring_id_ = world.next_spring_id();
}

void Controller::renew(World& world, std::int32_t next_body_id, std::int32_t next_spring_id) {
  world.continue_ids(next_body_id, next_spring_id);
  spawned_names_.clear();
  spawned_ids_.clear();
  spawned_springs_.clear();
  structure_edited_ = false;
  const std::uint32_t epoch = entities_.epoch;
  entities_ = entities_of(*scene_);
  entities_.epoch = epoch;
  entities_.world = world_info_.number;
}

Status Controller::remove_dense(World& world, std::int32_t dense,
                                std::vector<std::int32_t>& removed_springs) {
  // The springs attached to it, by dense index, so their colours go with them.
  std::vector<std::int32_t> attached;
  for (std::int32_t k = 0; k < world.spring_count(); ++k) {
    const SpringDef& sp = world.spring(SpringId{k});
    if (sp.body_i == dense || sp.body_j == dense) attached.push_back(k);
  }
  if (Status st = world.remove_body(world.handle(BodyId{dense}), &removed_springs); !st) return st;
  for (auto it = attached.rbegin(); it != attached.rend(); ++it) {
    entities_.spring_colors.erase(entities_.spring_colors.begin() + *it);
  }
  entities_.body_names.erase(entities_.body_names.begin() + dense);
  entities_.body_colors.erase(entities_.body_colors.begin() + dense);
  for (const std::int32_t s : removed_springs) spawned_springs_.erase(s);
  return Ok{};
}

CommandResult Controller::spawn(const Command& command, World& world) {
  const SpawnArgs& a = command.spawn;
  const std::int64_t now = world.step_index();
  std::shared_ptr<const Fragment> fragment = a.fragment;
  if (!fragment) {
    Result<Fragment> parsed = parse_fragment(a.resource, a.uri.empty() ? "<resource>" : a.uri);
    if (!parsed) return refuse(Refusal::BadResource, "spawn_entity: " + parsed.error().message);
    fragment = std::make_shared<const Fragment>(std::move(parsed.value()));
  }

  std::optional<CommandResult> refused;
  const std::string name = spawn_name(a, used_names_, spawned_ids_.contains(a.name), refused);
  if (refused) return *refused;

  // Every spring end named must be a body of the world now.
  std::vector<SpringDef> springs;
  const std::int32_t self = world.body_count();
  for (std::size_t k = 0; k < fragment->springs.size(); ++k) {
    const FragmentSpring& fs = fragment->springs[k];
    SpringDef def;
    def.anchor_i = fs.end_i.anchor;
    def.anchor_j = fs.end_j.anchor;
    def.stiffness = fs.stiffness;
    def.rest_length = fs.rest_length;
    for (auto [end, body] : {std::pair{&fs.end_i, &def.body_i}, {&fs.end_j, &def.body_j}}) {
      if (end->kind == FragmentSpringEnd::Kind::Self) *body = self;
      if (end->kind == FragmentSpringEnd::Kind::Fixed) *body = kFixed;
      if (end->kind != FragmentSpringEnd::Kind::Named) continue;
      const std::optional<std::int32_t> id = find_entity(end->body);
      const std::optional<BodyId> dense = id ? world.find_body_id(*id) : std::nullopt;
      if (!dense) {
        return refuse(Refusal::NoSuchEntity, "spawn_entity: spring " + std::to_string(k) + " names '" +
                                                 end->body + "', which is no body of the world at " +
                                                 detail::at(now));
      }
      *body = dense->index;
    }
    springs.push_back(def);
  }

  const BodyState state{a.position, a.theta, fragment->body.velocity, fragment->body.omega};
  const double bound = world.finite_bound();
  for (double v : {state.position.x(), state.position.y(), state.theta, state.velocity.x(),
                   state.velocity.y(), state.omega}) {
    if (!std::isfinite(v) || (bound > 0.0 && std::abs(v) > bound)) {
      return refuse(Refusal::Other,
                    "spawn_entity: the pose and the fragment's velocities must be finite and "
                    "within the range the run can report");
    }
  }
  Result<BodyHandle> added = world.add_body(fragment->body, state);
  if (!added) return refuse(Refusal::BadResource, "spawn_entity: " + added.error().message);
  std::vector<std::int32_t> spring_ids;
  for (const SpringDef& def : springs) {
    Result<std::int32_t> id = world.add_spring(def);
    if (!id) {
      // The parser's checks are the world's: this is a bug, but the world is left as it was.
      for (const std::int32_t s : spring_ids) (void)world.remove_spring(s);
      (void)world.remove_body(added.value());
      return refuse(Refusal::BadResource, "spawn_entity: " + id.error().message);
    }
    spring_ids.push_back(id.value());
  }

  const std::int32_t body_id = world.body_id(*world.find(added.value()));
  entities_.body_names.push_back(name);
  entities_.body_colors.push_back(fragment->color.value_or(default_body_color(body_id)));
  for (const FragmentSpring& fs : fragment->springs) {
    entities_.spring_colors.push_back(fs.color.value_or(default_spring_color()));
  }
  ++entities_.epoch;
  structure_edited_ = true;
  spawned_names_.emplace(body_id, name);
  spawned_ids_.emplace(name, body_id);
  used_names_.insert(name);
  spawned_springs_.insert(spring_ids.begin(), spring_ids.end());
  CommandResult r;
  r.successful = true;
  r.entity = name;
  r.body_id = body_id;
  r.message = "spawned '" + name + "' (body " + std::to_string(body_id) + ")" +
              (spring_ids.empty() ? std::string() : " with springs " + id_list(spring_ids)) + " at " +
              detail::at(now);
  follow_structure(world, &r);
  return r;
}

CommandResult Controller::remove(const Command& command, World& world) {
  const std::int64_t now = world.step_index();
  const std::optional<std::int32_t> id = find_entity(command.entity);
  const std::optional<BodyId> dense = id ? world.find_body_id(*id) : std::nullopt;
  if (!dense) {
    return refuse(Refusal::NoSuchEntity,
                  "delete_entity: no body named '" + command.entity + "' at " + detail::at(now));
  }
  CommandResult r;
  const Status st = remove_dense(world, dense->index, r.removed_springs);
  if (!st) return refuse(Refusal::Other, "delete_entity: " + st.error().message);
  ++entities_.epoch;
  structure_edited_ = true;
  if (const auto it = spawned_names_.find(*id); it != spawned_names_.end()) {
    spawned_ids_.erase(it->second);
    spawned_names_.erase(it);
  }
  r.successful = true;
  r.entity = command.entity;
  r.body_id = *id;
  r.message = "deleted '" + command.entity + "' (body " + std::to_string(*id) + ")" +
              (r.removed_springs.empty() ? std::string(" (no springs)")
                                         : " and the springs attached to it: " + id_list(r.removed_springs)) +
              " at " + detail::at(now);
  follow_structure(world, &r);
  return r;
}

CommandResult Controller::reset_spawned(World& world) {
  const std::int64_t now = world.step_index();
  CommandResult r;
  std::size_t bodies = 0;
  // Last spawned first; each body takes its springs with it, then the spawned springs left
  // (between scene bodies) go.
  const std::map<std::int32_t, std::string> spawned = std::move(spawned_names_);
  spawned_names_.clear();
  spawned_ids_.clear();
  for (auto it = spawned.rbegin(); it != spawned.rend(); ++it) {
    const std::optional<BodyId> dense = world.find_body_id(it->first);
    if (dense && remove_dense(world, dense->index, r.removed_springs).ok()) ++bodies;
  }
  const std::set<std::int32_t> springs = std::move(spawned_springs_);
  spawned_springs_.clear();
  for (auto it = springs.rbegin(); it != springs.rend(); ++it) {
    const std::optional<SpringId> k = world.find_spring_id(*it);
    if (!k || !world.remove_spring(*it).ok()) continue;
    entities_.spring_colors.erase(entities_.spring_colors.begin() + k->index);
    r.removed_springs.push_back(*it);
  }
  if (bodies > 0 || !r.removed_springs.empty()) {
    ++entities_.epoch;
    structure_edited_ = true;  // a scene body deleted earlier stays deleted: only a reset brings it back
  }
  r.successful = true;
  r.message = "removed " + std::to_string(bodies) + " spawned bodies and " +
              std::to_string(r.removed_springs.size()) + " springs at " + detail::at(now);
  follow_structure(world, &r);
  return r;
}

}  // namespace rbsim::control
