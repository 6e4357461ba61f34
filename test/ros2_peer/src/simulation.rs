//! simulation_interfaces 2.1.0 (services and the SimulateSteps action) and type_description_interfaces'
//! GetTypeDescription, called the way an rclcpp tool calls them (ServiceMapping::Cyclone; the
//! action through ros2-client's own ActionClient, rcl_action's protocol). The types are declared
//! here from the .msg/.srv/.action files, field for field (serde's CDR follows declaration order):
//! none of rbsim's code.
//!
//!   sim NODE OP ARGS [, OP ARGS]...   the ops in order, in one process (one ros2-client node, each
//!                                     client made once), one JSON line per op ("op": its index)
//! OPs: features | state | set-state S | reset SCOPE | step N | entities FILTER | states FILTER
//!    | info NAME | entity NAME | bounds NAME
//!    | set-entity NAME [pose X Y QX QY QZ QW] [twist VX VY OMEGA] [accel]
//!    | spawn NAME string|uri FILE X Y THETA [rename] [ns NAMESPACE]
//!                                       SpawnEntity: the fragment FILE's text as resource_string,
//!                                       or FILE as the uri; the pose (X, Y, 0) and yaw THETA
//!    | delete NAME
//!    | load-world string|uri FILE        LoadWorld: the scene FILE's text as resource_string, or FILE as
//!                                       the uri
//!    | current-world | available-worlds
//!    | goal N [cancel-after K]          the action: accepted, feedback, (cancel,) result, status
//!    | typedesc DDS_TOPIC TYPE          the hash in USER_DATA of the node's endpoint on DDS_TOPIC
//!                                       (rt/..., rq/...Request, rr/...Reply) as RustDDS's discovery
//!                                       reports it, the description the node gives for it, and
//!                                       that description's REP 2011 hash, computed here
//!    | typedesc-hash HASH TYPE          the node's answer for a hash of our choosing; with either, the
//!                                       hashes of a service's or action's parts (their own descriptions
//!                                       cut out of it), to compare with what their endpoints announce
//!    | announced DDS_TOPIC              the hash in USER_DATA alone
//! FILTER: all | regex R | category C | box X0 Y0 Z0 X1 Y1 Z1 | sphere X Y Z R | tags T | hull
use std::{
  any::Any,
  collections::HashMap,
  io::Write,
  time::{Duration, Instant},
};

use futures::{FutureExt, StreamExt};
use ros2_client::{
  ActionTypeName, Context, Message, Node, QosProfile, ServiceMapping,
  action::{ActionClient, ActionClientQosPolicies, GoalStatusEnum, SendGoalRequest},
  builtin_interfaces::Time,
  qos::{Durability, History, Reliability, WhenFull},
};
use serde::{Deserialize, Serialize, de::DeserializeOwned};

use crate::{
  json_string,
  services::{client, service_name, service_qos, wait_for_server},
};

// --- simulation_interfaces/msg and the geometry_msgs / std_msgs they use

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Vector3 {
  pub x: f64,
  pub y: f64,
  pub z: f64,
}
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Quaternion {
  pub x: f64,
  pub y: f64,
  pub z: f64,
  pub w: f64,
}
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Header {
  pub stamp: Time,
  pub frame_id: String,
}
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Pose {
  pub position: Vector3,
  pub orientation: Quaternion,
}
/// geometry_msgs/Twist and geometry_msgs/Accel: the same layout.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Twist {
  pub linear: Vector3,
  pub angular: Vector3,
}
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EntityState {
  pub header: Header,
  pub pose: Pose,
  pub twist: Twist,
  pub acceleration: Twist,
}
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SimResult {
  pub result: u8,
  pub error_message: String,
}
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Bounds {
  pub r#type: u8,
  pub points: Vec<Vector3>,
}
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct TagsFilter {
  pub tags: Vec<String>,
  pub filter_mode: u8,
}
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct EntityCategory {
  pub category: u8,
}
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct EntityFilters {
  pub filter: String,
  pub categories: Vec<EntityCategory>,
  pub tags: TagsFilter,
  pub bounds: Bounds,
}
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct EntityInfo {
  pub category: EntityCategory,
  pub description: String,
  pub tags: Vec<String>,
}
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
pub struct Resource {
  pub uri: String,
  pub resource_string: String,
}
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct PoseStamped {
  pub header: Header,
  pub pose: Pose,
}
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct SimulatorFeatures {
  pub features: Vec<u16>,
  pub spawn_formats: Vec<String>,
  pub custom_info: String,
}

// --- the services' requests and responses (an empty request has rosidl's one placeholder byte)

macro_rules! messages {
  ($($name:ident { $($field:ident : $ty:ty),* $(,)? })*) => {
    $(
      #[derive(Debug, Clone, Serialize, Deserialize)]
      pub struct $name { $(pub $field: $ty),* }
      impl Message for $name {}
    )*
  };
}
messages! {
  Empty { structure_needs_at_least_one_member: u8 }
  FeaturesResponse { features: SimulatorFeatures }
  StateResponse { state: u8, result: SimResult }
  SetStateRequest { state: u8 }
  ResultResponse { result: SimResult }
  ResetRequest { scope: u8 }
  StepRequest { steps: u64 }
  FiltersRequest { filters: EntityFilters }
  EntitiesResponse { result: SimResult, entities: Vec<String> }
  StatesResponse { result: SimResult, entities: Vec<String>, states: Vec<EntityState> }
  EntityRequest { entity: String }
  InfoResponse { result: SimResult, info: EntityInfo }
  EntityStateResponse { result: SimResult, state: EntityState }
  BoundsResponse { result: SimResult, bounds: Bounds }
  SetEntityRequest { entity: String, state: EntityState, set_pose: bool, set_twist: bool, set_acceleration: bool }
  SpawnRequest {
    name: String, allow_renaming: bool, entity_resource: Resource, entity_namespace: String, initial_pose: PoseStamped
  }
  SpawnResponse { result: SimResult, entity_name: String }
  WorldResource { name: String, world_resource: Resource, description: String, tags: Vec<String> }
  LoadWorldRequest { world_resource: Resource, fail_on_unsupported_element: bool, ignore_missing_or_unsupported_assets: bool }
  WorldResponse { result: SimResult, world: WorldResource }
  AvailableWorldsRequest { additional_sources: Vec<String>, filter: TagsFilter, offline_only: bool, continue_on_error: bool }
  AvailableWorldsResponse { result: SimResult, worlds: Vec<WorldResource> }
  Goal { steps: u64 }
  Feedback { completed_steps: u64, remaining_steps: u64 }
  FieldType { type_id: u8, capacity: u64, string_capacity: u64, nested_type_name: String }
  Field { name: String, r#type: FieldType, default_value: String }
  IndividualTypeDescription { type_name: String, fields: Vec<Field> }
  TypeDescription { type_description: IndividualTypeDescription, referenced_type_descriptions: Vec<IndividualTypeDescription> }
  TypeSource { type_name: String, encoding: String, raw_file_contents: String }
  KeyValue { key: String, value: String }
  TypeDescriptionRequest { type_name: String, type_hash: String, include_type_sources: bool }
  TypeDescriptionResponse {
    successful: bool, failure_reason: String, type_description: TypeDescription, type_sources: Vec<TypeSource>,
    extra_information: Vec<KeyValue>
  }
}

/// The sequence's state: one client per service, made on first use and kept (each new client
/// waits for discovery and matching once), and the deadline every call is bounded by.
struct Session<'a> {
  context: &'a Context,
  node: &'a mut Node,
  ns: String,
  clients: HashMap<String, Box<dyn Any>>,
  deadline: Instant,
}

/// Runs `work` until the deadline; Err naming `what` when it passed.
fn bounded<T>(deadline: Instant, what: &str, work: impl std::future::Future<Output = Result<T, String>>) -> Result<T, String> {
  let left = deadline.saturating_duration_since(Instant::now());
  smol::block_on(smol::future::or(work, async {
    smol::Timer::after(left).await;
    Err(format!("{what}: no answer before the deadline"))
  }))
}

/// Calls `make()`'s request until one is answered (each try bounded to 1 s), bounded by the
/// deadline: a client's first call. Discovery says the server is there; whether our request writer
/// is matched with its reader, and its reply writer with our reader, only an answer says (a
/// volatile writer drops what it wrote before matching, and a request or a reply lost that way
/// would never come). So the first request is one that changes nothing.
async fn answered<T, E, F: std::future::Future<Output = Result<T, E>>>(call: impl Fn() -> F) -> Result<(), String> {
  loop {
    let reply = smol::future::or(async { call().await.ok().map(|_| ()) }, async {
      smol::Timer::after(Duration::from_secs(1)).await;
      None
    });
    if reply.await.is_some() {
      return Ok(());
    }
  }
}

impl Session<'_> {
  /// Calls `service` (type `ty`, pkg/Name) with `request`; a client made on first use is first
  /// probed with `probe`, a request of the same type that changes nothing.
  fn call_probed<Req, Resp>(&mut self, service: &str, ty: &str, request: Req, probe: Req) -> Result<(Resp, Duration), String>
  where
    Req: Message + Clone + 'static,
    Resp: Message + DeserializeOwned + 'static,
  {
    let full = format!("{}/{service}", self.ns);
    let (pkg, name) = ty.split_once('/').ok_or("pkg/Name")?;
    if !self.clients.contains_key(&full) {
      let c = client::<Req, Resp>(self.node, &full, pkg, name, service_qos())?;
      let context = self.context;
      bounded(self.deadline, &full, async {
        wait_for_server(context, &full).await;
        answered(|| c.async_call_service(probe.clone())).await
      })?;
      self.clients.insert(full.clone(), Box::new(c));
    }
    let c = self.clients[&full]
      .downcast_ref::<ros2_client::Client<Req, Resp>>()
      .ok_or(format!("{full}: called with another type"))?;
    bounded(self.deadline, &full, async {
      let t0 = Instant::now();
      let r = c.async_call_service(request).await.map_err(|e| format!("{full}: {e:?}"))?;
      Ok((r, t0.elapsed()))
    })
  }

  /// A call that changes nothing (a read): its own request is the probe.
  fn call<Req, Resp>(&mut self, service: &str, ty: &str, request: Req) -> Result<(Resp, Duration), String>
  where
    Req: Message + Clone + 'static,
    Resp: Message + DeserializeOwned + 'static,
  {
    let probe = request.clone();
    self.call_probed(service, ty, request, probe)
  }
}

fn num<T: std::str::FromStr>(w: Option<&String>, what: &str) -> Result<T, String> {
  let w = w.ok_or(format!("{what}: missing"))?;
  w.parse().map_err(|_| format!("{what}: not a number: {w}"))
}

fn result_json(r: &SimResult) -> String {
  format!("\"result\": {}, \"message\": {}", r.result, json_string(&r.error_message))
}

fn v3(v: &Vector3) -> String {
  format!("[{:?}, {:?}, {:?}]", v.x, v.y, v.z)
}

fn state_json(s: &EntityState) -> String {
  let q = &s.pose.orientation;
  format!(
    "{{\"stamp_ns\": {}, \"frame\": {}, \"position\": {}, \"orientation\": [{:?}, {:?}, {:?}, {:?}], \"linear\": {}, \
     \"angular\": {}, \"linear_acceleration\": {}, \"angular_acceleration\": {}}}",
    s.header.stamp.to_nanos(), json_string(&s.header.frame_id), v3(&s.pose.position), q.x, q.y, q.z, q.w,
    v3(&s.twist.linear), v3(&s.twist.angular), v3(&s.acceleration.linear), v3(&s.acceleration.angular))
}

fn strings_json(v: &[String]) -> String {
  format!("[{}]", v.iter().map(|s| json_string(s)).collect::<Vec<_>>().join(", "))
}

/// FILTER words -> EntityFilters.
fn filters(words: &[String]) -> Result<EntityFilters, String> {
  let mut f = EntityFilters::default();
  let p = |i: usize| num::<f64>(words.get(i), "filter value");
  match words.first().map(String::as_str) {
    Some("all") | None => {}
    Some("regex") => f.filter = words.get(1).cloned().unwrap_or_default(),
    Some("category") => f.categories.push(EntityCategory { category: num(words.get(1), "category")? }),
    Some("box") => {
      f.bounds = Bounds { r#type: 1, points: vec![Vector3 { x: p(1)?, y: p(2)?, z: p(3)? }, Vector3 { x: p(4)?, y: p(5)?, z: p(6)? }] }
    }
    Some("sphere") => {
      f.bounds = Bounds { r#type: 3, points: vec![Vector3 { x: p(1)?, y: p(2)?, z: p(3)? }, Vector3 { x: p(4)?, y: 0.0, z: 0.0 }] }
    }
    Some("tags") => f.tags.tags.push(words.get(1).cloned().unwrap_or_default()),
    Some("hull") => {
      let v = |x, y| Vector3 { x, y, z: 0.0 };
      f.bounds = Bounds { r#type: 2, points: vec![v(-10.0, -10.0), v(10.0, -10.0), v(0.0, 10.0)] };
    }
    Some(other) => return Err(format!("unknown filter {other} (all, regex, category, box, sphere, tags, hull)")),
  }
  Ok(f)
}

/// set-entity NAME [pose X Y QX QY QZ QW] [twist VX VY OMEGA] [accel]
fn set_entity_request(words: &[String]) -> Result<SetEntityRequest, String> {
  let entity = words.first().ok_or("set-entity NAME ...")?.clone();
  let mut r = SetEntityRequest {
    entity,
    state: EntityState {
      header: Header { stamp: Time::ZERO, frame_id: "world".into() },
      pose: Pose::default(),
      twist: Twist::default(),
      acceleration: Twist::default(),
    },
    set_pose: false,
    set_twist: false,
    set_acceleration: false,
  };
  let mut i = 1;
  while i < words.len() {
    let f = |k: usize| num::<f64>(words.get(i + k), &words[i]);
    match words[i].as_str() {
      "pose" => {
        r.set_pose = true;
        r.state.pose.position = Vector3 { x: f(1)?, y: f(2)?, z: 0.0 };
        r.state.pose.orientation = Quaternion { x: f(3)?, y: f(4)?, z: f(5)?, w: f(6)? };
        i += 7;
      }
      "twist" => {
        r.set_twist = true;
        r.state.twist.linear = Vector3 { x: f(1)?, y: f(2)?, z: 0.0 };
        r.state.twist.angular = Vector3 { x: 0.0, y: 0.0, z: f(3)? };
        i += 4;
      }
      "accel" => {
        r.set_acceleration = true;
        i += 1;
      }
      other => return Err(format!("set-entity: unknown word {other} (pose, twist, accel)")),
    }
  }
  Ok(r)
}

/// A WorldResource as JSON: its name, uri and description.
fn world_json(w: &WorldResource) -> String {
  format!(
    "{{\"name\": {}, \"uri\": {}, \"description\": {}}}",
    json_string(&w.name), json_string(&w.world_resource.uri), json_string(&w.description))
}

/// spawn NAME string|uri FILE X Y THETA [rename] [ns NAMESPACE]: the SpawnEntity request.
fn spawn_request(words: &[String]) -> Result<SpawnRequest, String> {
  let usage = "spawn NAME string|uri FILE X Y THETA [rename] [ns NAMESPACE]";
  let [name, how, file, x, y, theta, more @ ..] = words else { return Err(usage.to_string()) };
  let entity_resource = match how.as_str() {
    "string" => Resource {
      uri: String::new(),
      resource_string: std::fs::read_to_string(file).map_err(|e| format!("{file}: {e}"))?,
    },
    "uri" => Resource { uri: file.clone(), resource_string: String::new() },
    _ => return Err(usage.to_string()),
  };
  let theta: f64 = num(Some(theta), "theta")?;
  let mut r = SpawnRequest {
    name: name.clone(),
    allow_renaming: false,
    entity_resource,
    entity_namespace: String::new(),
    initial_pose: PoseStamped {
      header: Header { stamp: Time::ZERO, frame_id: String::new() },
      pose: Pose {
        position: Vector3 { x: num(Some(x), "x")?, y: num(Some(y), "y")?, z: 0.0 },
        orientation: Quaternion { x: 0.0, y: 0.0, z: (0.5 * theta).sin(), w: (0.5 * theta).cos() },
      },
    },
  };
  let mut i = 0;
  while i < more.len() {
    match more[i].as_str() {
      "rename" => r.allow_renaming = true,
      "ns" => {
        i += 1;
        r.entity_namespace = more.get(i).cloned().ok_or(usage)?;
      }
      _ => return Err(usage.to_string()),
    }
    i += 1;
  }
  Ok(r)
}

/// One op: its JSON fields (without the braces), or an error that ends the sequence.
fn op(s: &mut Session, words: &[String]) -> Result<String, String> {
  const SIM: &str = "simulation_interfaces";
  let (verb, rest) = words.split_first().ok_or("an empty op")?;
  let ty = |name: &str| format!("{SIM}/{name}");
  let took = |d: Duration| format!("\"took_ms\": {:.3}", d.as_secs_f64() * 1e3);
  Ok(match verb.as_str() {
    "features" => {
      let (r, d): (FeaturesResponse, _) =
        s.call("get_simulator_features", &ty("GetSimulatorFeatures"), Empty { structure_needs_at_least_one_member: 0 })?;
      format!(
        "\"features\": {:?}, \"spawn_formats\": {}, \"custom_info\": {}, {}",
        r.features.features, strings_json(&r.features.spawn_formats), json_string(&r.features.custom_info), took(d))
    }
    "state" => {
      let (r, d): (StateResponse, _) =
        s.call("get_simulation_state", &ty("GetSimulationState"), Empty { structure_needs_at_least_one_member: 0 })?;
      format!("\"state\": {}, {}, {}", r.state, result_json(&r.result), took(d))
    }
    "set-state" => {
      let (r, d): (ResultResponse, _) =
        // The probe: NO_WORLD, refused (INCORRECT_TRANSITION) and changing nothing.
        s.call_probed(
          "set_simulation_state", &ty("SetSimulationState"), SetStateRequest { state: num(rest.first(), "state")? },
          SetStateRequest { state: 4 })?;
      format!("{}, {}", result_json(&r.result), took(d))
    }
    "reset" => {
      let (r, d): (ResultResponse, _) =
        // The probe: SCOPE_TIME alone, unsupported.
        s.call_probed("reset_simulation", &ty("ResetSimulation"), ResetRequest { scope: num(rest.first(), "scope")? }, ResetRequest {
          scope: 1,
        })?;
      format!("{}, {}", result_json(&r.result), took(d))
    }
    "step" => {
      let (r, d): (ResultResponse, _) =
        // The probe: 0 steps, refused.
        s.call_probed("step_simulation", &ty("StepSimulation"), StepRequest { steps: num(rest.first(), "steps")? }, StepRequest {
          steps: 0,
        })?;
      format!("{}, {}", result_json(&r.result), took(d))
    }
    "entities" => {
      let (r, d): (EntitiesResponse, _) =
        s.call("get_entities", &ty("GetEntities"), FiltersRequest { filters: filters(rest)? })?;
      format!("{}, \"entities\": {}, {}", result_json(&r.result), strings_json(&r.entities), took(d))
    }
    "states" => {
      let (r, d): (StatesResponse, _) =
        s.call("get_entities_states", &ty("GetEntitiesStates"), FiltersRequest { filters: filters(rest)? })?;
      let states: Vec<String> = r.states.iter().map(state_json).collect();
      format!(
        "{}, \"entities\": {}, \"states\": [{}], {}",
        result_json(&r.result), strings_json(&r.entities), states.join(", "), took(d))
    }
    "info" => {
      let req = EntityRequest { entity: rest.first().cloned().unwrap_or_default() };
      let (r, d): (InfoResponse, _) = s.call("get_entity_info", &ty("GetEntityInfo"), req)?;
      format!(
        "{}, \"category\": {}, \"description\": {}, \"tags\": {}, {}",
        result_json(&r.result), r.info.category.category, json_string(&r.info.description), strings_json(&r.info.tags),
        took(d))
    }
    "entity" => {
      let req = EntityRequest { entity: rest.first().cloned().unwrap_or_default() };
      let (r, d): (EntityStateResponse, _) = s.call("get_entity_state", &ty("GetEntityState"), req)?;
      format!("{}, \"state\": {}, {}", result_json(&r.result), state_json(&r.state), took(d))
    }
    "bounds" => {
      let req = EntityRequest { entity: rest.first().cloned().unwrap_or_default() };
      let (r, d): (BoundsResponse, _) = s.call("get_entity_bounds", &ty("GetEntityBounds"), req)?;
      let points: Vec<String> = r.bounds.points.iter().map(v3).collect();
      format!("{}, \"type\": {}, \"points\": [{}], {}", result_json(&r.result), r.bounds.r#type, points.join(", "), took(d))
    }
    "set-entity" => {
      // The probe: nothing to set (set_pose and set_twist false).
      let probe = SetEntityRequest { set_pose: false, set_twist: false, set_acceleration: false, ..set_entity_request(rest)? };
      let (r, d): (ResultResponse, _) =
        s.call_probed("set_entity_state", &ty("SetEntityState"), set_entity_request(rest)?, probe)?;
      format!("{}, {}", result_json(&r.result), took(d))
    }
    "spawn" => {
      // The probe: a name no entity may have (a digit first), refused before it is a command.
      let probe = SpawnRequest { name: "0probe".into(), allow_renaming: false, ..spawn_request(rest)? };
      let (r, d): (SpawnResponse, _) = s.call_probed("spawn_entity", &ty("SpawnEntity"), spawn_request(rest)?, probe)?;
      format!("{}, \"entity_name\": {}, {}", result_json(&r.result), json_string(&r.entity_name), took(d))
    }
    "delete" => {
      let req = EntityRequest { entity: rest.first().cloned().unwrap_or_default() };
      // The probe: no name at all, refused before it is a command.
      let probe = EntityRequest { entity: String::new() };
      let (r, d): (ResultResponse, _) = s.call_probed("delete_entity", &ty("DeleteEntity"), req, probe)?;
      format!("{}, {}", result_json(&r.result), took(d))
    }
    "load-world" => {
      let [how, file] = rest else { return Err("load-world string|uri FILE".into()) };
      let world_resource = match how.as_str() {
        "string" => Resource { uri: String::new(), resource_string: std::fs::read_to_string(file).map_err(|e| format!("{file}: {e}"))? },
        "uri" => Resource { uri: file.clone(), resource_string: String::new() },
        _ => return Err("load-world string|uri FILE".into()),
      };
      let req = LoadWorldRequest { world_resource, fail_on_unsupported_element: false, ignore_missing_or_unsupported_assets: false };
      // The probe: no resource at all, refused (NO_RESOURCE) before it is a command.
      let probe = LoadWorldRequest { world_resource: Resource { uri: String::new(), resource_string: String::new() }, ..req.clone() };
      let (r, d): (WorldResponse, _) = s.call_probed("load_world", &ty("LoadWorld"), req, probe)?;
      format!("{}, \"world\": {}, {}", result_json(&r.result), world_json(&r.world), took(d))
    }
    "current-world" => {
      let (r, d): (WorldResponse, _) =
        s.call("get_current_world", &ty("GetCurrentWorld"), Empty { structure_needs_at_least_one_member: 0 })?;
      format!("{}, \"world\": {}, {}", result_json(&r.result), world_json(&r.world), took(d))
    }
    "available-worlds" => {
      let req = AvailableWorldsRequest {
        additional_sources: vec![],
        filter: TagsFilter { tags: vec![], filter_mode: 0 },
        offline_only: false,
        continue_on_error: false,
      };
      let (r, d): (AvailableWorldsResponse, _) = s.call("get_available_worlds", &ty("GetAvailableWorlds"), req)?;
      let worlds: Vec<String> = r.worlds.iter().map(world_json).collect();
      format!("{}, \"worlds\": [{}], {}", result_json(&r.result), worlds.join(", "), took(d))
    }
    "goal" => goal(s, rest)?,
    "announced" => {
      let topic = rest.first().ok_or("announced DDS_TOPIC")?;
      format!("\"announced\": {}", json_string(&announced_hash(s, topic)?))
    }
    "typedesc" | "typedesc-hash" => {
      let [target, type_name] = rest else { return Err(format!("{verb} DDS_TOPIC|HASH TYPE")) };
      let announced = if verb == "typedesc" { announced_hash(s, target)? } else { target.clone() };
      let req = TypeDescriptionRequest { type_name: type_name.clone(), type_hash: announced.clone(), include_type_sources: true };
      let (r, d): (TypeDescriptionResponse, _) =
        s.call("get_type_description", "type_description_interfaces/GetTypeDescription", req)?;
      let td = &r.type_description;
      let subs: Vec<String> = td
        .referenced_type_descriptions
        .iter()
        .filter(|t| t.type_name.contains("/srv/") || t.type_name.contains("/action/"))
        .map(|t| format!("{}: {}", json_string(&t.type_name), json_string(&sub_hash(td, &t.type_name))))
        .collect();
      let sources: Vec<String> = r.type_sources.iter().map(|t| format!("[{}, {}]", json_string(&t.type_name), json_string(&t.encoding))).collect();
      format!(
        "\"announced\": {}, \"successful\": {}, \"failure_reason\": {}, \"type_name\": {}, \"fields\": {}, \
         \"referenced\": {}, \"sources\": [{}], \"description_hash\": {}, \"part_hashes\": {{{}}}, {}",
        json_string(&announced), r.successful, json_string(&r.failure_reason), json_string(&td.type_description.type_name),
        td.type_description.fields.len(),
        strings_json(&td.referenced_type_descriptions.iter().map(|t| t.type_name.clone()).collect::<Vec<_>>()),
        sources.join(", "), json_string(&rep2011_hash(td)), subs.join(", "), took(d))
    }
    other => return Err(format!("unknown op {other}")),
  })
}

/// The RIHS01 hash in the USER_DATA ("typehash=RIHS01_...;") of the node's endpoint on `topic` (its
/// DDS name) as RustDDS's discovery reports it: a writer for rt/ and rr/, a reader for rq/.
fn announced_hash(s: &Session, topic: &str) -> Result<String, String> {
  let dds = s.context.domain_participant();
  bounded(s.deadline, topic, async {
    loop {
      let data: Vec<Vec<u8>> = if topic.starts_with("rq") {
        dds.discovered_readers().into_iter().filter(|r| r.subscription_topic_data.topic_name == topic).map(|r| r.user_data).collect()
      } else {
        dds.discovered_writers().into_iter().filter(|w| w.publication_topic_data.topic_name == topic).map(|w| w.user_data).collect()
      };
      // The parameter's value as RustDDS keeps it; find the text in it (whatever its framing).
      for d in data {
        let text = String::from_utf8_lossy(&d).into_owned();
        if let Some(at) = text.find("typehash=") {
          let hash = &text[at + "typehash=".len()..];
          if let Some(end) = hash.find(';') {
            return Ok(hash[..end].to_string());
          }
        }
      }
      smol::Timer::after(Duration::from_millis(50)).await;
    }
  })
}

/// The hash of `name`, one of the types `td` refers to (a service's _Request, _Response, _Event;
/// an action's parts), as its own description: it at the root, the types it refers to, directly
/// or not, sorted by name (as rosidl_generator_type_description lists them).
fn sub_hash(td: &TypeDescription, name: &str) -> String {
  let all: HashMap<&str, &IndividualTypeDescription> = std::iter::once(&td.type_description)
    .chain(td.referenced_type_descriptions.iter())
    .map(|t| (t.type_name.as_str(), t))
    .collect();
  let mut seen: Vec<&str> = Vec::new();
  let mut todo = vec![name];
  while let Some(n) = todo.pop() {
    for f in all.get(n).map(|t| t.fields.as_slice()).unwrap_or_default() {
      let nested = f.r#type.nested_type_name.as_str();
      if !nested.is_empty() && !seen.contains(&nested) {
        seen.push(nested);
        todo.push(nested);
      }
    }
  }
  seen.sort();
  let clone = |t: &IndividualTypeDescription| IndividualTypeDescription { type_name: t.type_name.clone(), fields: t.fields.clone() };
  let root = all.get(name).map(|t| clone(t)).unwrap_or(IndividualTypeDescription { type_name: name.into(), fields: vec![] });
  let referenced = seen.iter().filter_map(|n| all.get(n)).map(|t| clone(t)).collect();
  rep2011_hash(&TypeDescription { type_description: root, referenced_type_descriptions: referenced })
}

/// REP 2011's hash of a type description, as rosidl_generator_type_description makes it: the
/// description as JSON without default values (separators ", " and ": "), then SHA-256.
fn rep2011_hash(td: &TypeDescription) -> String {
  fn individual(d: &IndividualTypeDescription) -> String {
    let fields: Vec<String> = d
      .fields
      .iter()
      .map(|f| {
        format!(
          "{{\"name\": {}, \"type\": {{\"type_id\": {}, \"capacity\": {}, \"string_capacity\": {}, \"nested_type_name\": {}}}}}",
          json_string(&f.name), f.r#type.type_id, f.r#type.capacity, f.r#type.string_capacity,
          json_string(&f.r#type.nested_type_name))
      })
      .collect();
    format!("{{\"type_name\": {}, \"fields\": [{}]}}", json_string(&d.type_name), fields.join(", "))
  }
  let refs: Vec<String> = td.referenced_type_descriptions.iter().map(individual).collect();
  let text = format!(
    "{{\"type_description\": {}, \"referenced_type_descriptions\": [{}]}}",
    individual(&td.type_description), refs.join(", "));
  let digest = sha256(text.as_bytes());
  format!("RIHS01_{}", digest.iter().map(|b| format!("{b:02x}")).collect::<String>())
}

/// SHA-256 (FIPS 180-4): no crate for it among the locked ones.
pub fn sha256(data: &[u8]) -> [u8; 32] {
  const K: [u32; 64] = [
    0x428a2f98, 0x71374491, 0xb5c0fbcf, 0xe9b5dba5, 0x3956c25b, 0x59f111f1, 0x923f82a4, 0xab1c5ed5, 0xd807aa98,
    0x12835b01, 0x243185be, 0x550c7dc3, 0x72be5d74, 0x80deb1fe, 0x9bdc06a7, 0xc19bf174, 0xe49b69c1, 0xefbe4786,
    0x0fc19dc6, 0x240ca1cc, 0x2de92c6f, 0x4a7484aa, 0x5cb0a9dc, 0x76f988da, 0x983e5152, 0xa831c66d, 0xb00327c8,
    0xbf597fc7, 0xc6e00bf3, 0xd5a79147, 0x06ca6351, 0x14292967, 0x27b70a85, 0x2e1b2138, 0x4d2c6dfc, 0x53380d13,
    0x650a7354, 0x766a0abb, 0x81c2c92e, 0x92722c85, 0xa2bfe8a1, 0xa81a664b, 0xc24b8b70, 0xc76c51a3, 0xd192e819,
    0xd6990624, 0xf40e3585, 0x106aa070, 0x19a4c116, 0x1e376c08, 0x2748774c, 0x34b0bcb5, 0x391c0cb3, 0x4ed8aa4a,
    0x5b9cca4f, 0x682e6ff3, 0x748f82ee, 0x78a5636f, 0x84c87814, 0x8cc70208, 0x90befffa, 0xa4506ceb, 0xbef9a3f7,
    0xc67178f2,
  ];
  let mut h: [u32; 8] =
    [0x6a09e667, 0xbb67ae85, 0x3c6ef372, 0xa54ff53a, 0x510e527f, 0x9b05688c, 0x1f83d9ab, 0x5be0cd19];
  let mut msg = data.to_vec();
  msg.push(0x80);
  while msg.len() % 64 != 56 {
    msg.push(0);
  }
  msg.extend_from_slice(&((data.len() as u64) * 8).to_be_bytes());
  for block in msg.chunks(64) {
    let mut w = [0u32; 64];
    for i in 0..16 {
      w[i] = u32::from_be_bytes([block[4 * i], block[4 * i + 1], block[4 * i + 2], block[4 * i + 3]]);
    }
    for i in 16..64 {
      let s0 = w[i - 15].rotate_right(7) ^ w[i - 15].rotate_right(18) ^ (w[i - 15] >> 3);
      let s1 = w[i - 2].rotate_right(17) ^ w[i - 2].rotate_right(19) ^ (w[i - 2] >> 10);
      w[i] = w[i - 16].wrapping_add(s0).wrapping_add(w[i - 7]).wrapping_add(s1);
    }
    let [mut a, mut b, mut c, mut d, mut e, mut f, mut g, mut hh] = h;
    for i in 0..64 {
      let s1 = e.rotate_right(6) ^ e.rotate_right(11) ^ e.rotate_right(25);
      let ch = (e & f) ^ (!e & g);
      let t1 = hh.wrapping_add(s1).wrapping_add(ch).wrapping_add(K[i]).wrapping_add(w[i]);
      let s0 = a.rotate_right(2) ^ a.rotate_right(13) ^ a.rotate_right(22);
      let maj = (a & b) ^ (a & c) ^ (b & c);
      let t2 = s0.wrapping_add(maj);
      hh = g;
      g = f;
      f = e;
      e = d.wrapping_add(t1);
      d = c;
      c = b;
      b = a;
      a = t1.wrapping_add(t2);
    }
    for (x, y) in h.iter_mut().zip([a, b, c, d, e, f, g, hh]) {
      *x = x.wrapping_add(y);
    }
  }
  let mut out = [0u8; 32];
  for (i, x) in h.iter().enumerate() {
    out[4 * i..4 * i + 4].copy_from_slice(&x.to_be_bytes());
  }
  out
}

fn status_name(s: GoalStatusEnum) -> &'static str {
  match s {
    GoalStatusEnum::Unknown => "UNKNOWN",
    GoalStatusEnum::Accepted => "ACCEPTED",
    GoalStatusEnum::Executing => "EXECUTING",
    GoalStatusEnum::Canceling => "CANCELING",
    GoalStatusEnum::Succeeded => "SUCCEEDED",
    GoalStatusEnum::Canceled => "CANCELED",
    GoalStatusEnum::Aborted => "ABORTED",
  }
}

type StepsClient = ActionClient<Goal, ResultResponse, Feedback>;

/// The action client, made once: its three services' servers and its feedback and status writers
/// discovered before the first goal (feedback is volatile: a subscription matched late misses it).
fn action_client<'a>(s: &'a mut Session) -> Result<&'a StepsClient, String> {
  let key = format!("{}/simulate_steps", s.ns);
  if !s.clients.contains_key(&key) {
    // rcl_action's defaults: the services' profile, feedback reliable volatile keep last 10,
    // status reliable transient local keep last 1.
    let status = QosProfile::subscription_default()
      .reliability(Reliability::Reliable { when_full: WhenFull::Block })
      .durability(Durability::TransientLocal)
      .history(History::KeepLast { depth: 1 });
    let feedback = service_qos();
    let qos = ActionClientQosPolicies {
      goal_service: service_qos(),
      result_service: service_qos(),
      cancel_service: service_qos(),
      feedback_subscription: feedback,
      status_subscription: status,
    };
    let c: StepsClient = s
      .node
      .create_action_client(
        ServiceMapping::Cyclone, &service_name(&key)?, &ActionTypeName::new("simulation_interfaces", "SimulateSteps"), qos)
      .map_err(|e| format!("action client {key}: {e:?}"))?;
    let context = s.context;
    let base = format!("{key}/_action");
    bounded(s.deadline, &key, async {
      for service in ["send_goal", "cancel_goal", "get_result"] {
        wait_for_server(context, &format!("{base}/{service}")).await;
      }
      // Each service answered once (see `answered`), with requests that change nothing: a goal
      // of 0 steps (rejected), a cancel and a result of a goal that never was.
      let none = ros2_client::unique_identifier_msgs::UUID::new_random();
      answered(|| c.goal_client().async_call_service(SendGoalRequest { goal_id: none, goal: Goal { steps: 0 } })).await?;
      answered(|| c.async_cancel_goal(none, Time::ZERO)).await?;
      answered(|| c.async_request_result(none)).await?;
      let dds = context.domain_participant();
      for topic in ["feedback", "status"] {
        let name = format!("rt{base}/{topic}");
        while !dds.discovered_writers().iter().any(|w| w.publication_topic_data.topic_name == name) {
          smol::Timer::after(Duration::from_millis(50)).await;
        }
      }
      Ok(())
    })?;
    s.clients.insert(key.clone(), Box::new(c));
  }
  s.clients[&key].downcast_ref::<StepsClient>().ok_or(format!("{key}: another type"))
}

/// `goal N [cancel-after K]`: sends the goal; when accepted, reads its feedback (and, with
/// cancel-after, cancels once K steps are reported done), then asks for its result.
fn goal(s: &mut Session, words: &[String]) -> Result<String, String> {
  let steps: u64 = num(words.first(), "goal steps")?;
  let cancel_after: Option<u64> = match words.get(1).map(String::as_str) {
    Some("cancel-after") => Some(num(words.get(2), "cancel-after")?),
    None => None,
    Some(other) => return Err(format!("goal N [cancel-after K] (got {other})")),
  };
  let deadline = s.deadline;
  let c = action_client(s)?;
  bounded(deadline, "simulate_steps", async {
    let t0 = Instant::now();
    let (id, accepted) = c.async_send_goal(Goal { steps }).await.map_err(|e| format!("send_goal: {e:?}"))?;
    let goal_ms = t0.elapsed().as_secs_f64() * 1e3;
    if !accepted.accepted {
      return Ok(format!("\"accepted\": false, \"goal_ms\": {goal_ms:.3}"));
    }
    // The result is asked for at once (as rclcpp's client does); feedback read meanwhile.
    let mut feedback: Vec<(u64, u64)> = Vec::new();
    let mut cancel = String::new();
    {
      let mut stream = Box::pin(c.feedback_stream(id));
      let result = c.async_request_result(id).fuse();
      futures::pin_mut!(result);
      let outcome = loop {
        futures::select! {
          r = result => break r,
          f = stream.next() => {
            let Some(Ok(f)) = f else { continue };
            feedback.push((f.completed_steps, f.remaining_steps));
            if cancel.is_empty() && cancel_after.is_some_and(|k| f.completed_steps >= k) {
              let r = c.async_cancel_goal(id, Time::ZERO).await.map_err(|e| format!("cancel_goal: {e:?}"))?;
              cancel = format!(
                ", \"cancel\": {{\"return_code\": {:?}, \"canceling\": {}, \"after\": {}}}",
                r.return_code as i8, r.goals_canceling.len(), f.completed_steps);
            }
          }
        }
      };
      let (status, result) = outcome.map_err(|e| format!("get_result: {e:?}"))?;
      // Feedback written before the result may still be on its way (another topic): what arrived
      // by now, and for a goal that succeeded, up to the last one (none remaining), bounded.
      let until = Instant::now() + Duration::from_secs(5);
      loop {
        while let Ok(Some(f)) = c.receive_feedback(id) {
          feedback.push((f.completed_steps, f.remaining_steps));
        }
        let last_in = status != GoalStatusEnum::Succeeded || feedback.last().is_some_and(|f| f.1 == 0);
        if last_in || Instant::now() >= until {
          break;
        }
        smol::Timer::after(Duration::from_millis(10)).await;
      }
      let fb: Vec<String> = feedback.iter().map(|(a, b)| format!("[{a}, {b}]")).collect();
      // The status topic: the goal's status as the server last published it. rclcpp_action sends
      // the result before the status that ends the goal, on another topic: wait (bounded) for the
      // goal's terminal status to arrive.
      let mut last_status = None;
      let until = Instant::now() + Duration::from_secs(5);
      while Instant::now() < until && last_status != Some(status_name(status)) {
        let next = smol::future::or(async { c.async_receive_status().await.ok() }, async {
          smol::Timer::at(until).await;
          None
        });
        let Some(arr) = next.await else { break };
        if let Some(g) = arr.status_list.iter().find(|g| g.goal_info.goal_id == id) {
          last_status = Some(status_name(g.status));
        }
      }
      Ok(format!(
        "\"accepted\": true, \"goal_ms\": {goal_ms:.3}, \"status\": {}, {}, \"feedback\": [{}]{cancel}, \"status_topic\": {}",
        json_string(status_name(status)), result_json(&result.result), fb.join(", "),
        last_status.map(json_string).unwrap_or("null".into())))
    }
  })
}

/// `sim NODE OP ARGS [, OP ARGS]...`
pub fn sim(context: &Context, node: &mut Node, ns: &str, words: &[String], timeout: Duration) -> Result<(), String> {
  let mut s = Session { context, node, ns: ns.to_string(), clients: HashMap::new(), deadline: Instant::now() + timeout };
  for (i, words) in words.split(|w| w == ",").enumerate() {
    let fields = op(&mut s, words).map_err(|e| format!("op {i} ({}): {e}", words.join(" ")))?;
    println!("{{\"op\": {i}, \"verb\": {}, {fields}}}", json_string(words.first().map(String::as_str).unwrap_or("")));
    let _ = std::io::stdout().flush();
  }
  Ok(())
}

/// A GetEntitiesStates reply of `n` entities as rbsim answers one for n bodies (names body_<i>,
/// frame world, an empty error message: the same size to the byte), values made up.
pub fn canned_states(n: usize) -> StatesResponse {
  let v = |x: f64| Vector3 { x, y: -x, z: 0.0 };
  StatesResponse {
    result: SimResult { result: 1, error_message: String::new() },
    entities: (0..n).map(|i| format!("body_{i}")).collect(),
    states: (0..n)
      .map(|i| EntityState {
        header: Header { stamp: Time::from_nanos(1_000_000), frame_id: "world".into() },
        pose: Pose { position: v(i as f64), orientation: Quaternion { x: 0.0, y: 0.0, z: 0.0, w: 1.0 } },
        twist: Twist { linear: v(0.5), angular: Vector3 { x: 0.0, y: 0.0, z: 0.25 } },
        acceleration: Twist { linear: v(-9.81), angular: Vector3::default() },
      })
      .collect(),
  }
}
