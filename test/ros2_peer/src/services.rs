//! Parameter services and rbsim's own services, called the way rmw_cyclonedds_cpp's clients call
//! them: ServiceMapping::Cyclone (its request header: client GUID half and sequence number). A
//! test that passed with ros2-client's default Enhanced mapping would prove the wrong wire format.
use std::time::{Duration, Instant};

use ros2_client::{
  Client, Context, Message, Name, Node, ParameterValue, QosProfile, ServiceMapping, ServiceTypeName,
  parameters::raw,
  qos::{Durability, History, Reliability, WhenFull},
  rcl_interfaces::*,
};
use serde::{Deserialize, Serialize, de::DeserializeOwned};

use crate::json_string;

/// rmw_qos_profile_services_default: reliable, volatile, keep last 10.
pub fn service_qos() -> QosProfile {
  QosProfile::subscription_default()
    .reliability(Reliability::Reliable { when_full: WhenFull::Block })
    .durability(Durability::Volatile)
    .history(History::KeepLast { depth: 10 })
}

/// "/ns/node/get_parameters" -> Name("/ns/node", "get_parameters").
pub fn service_name(full: &str) -> Result<Name, String> {
  let (ns, base) = full.rsplit_once('/').ok_or(format!("{full}: not a fully qualified name"))?;
  Name::new(if ns.is_empty() { "/" } else { ns }, base).map_err(|e| format!("{full}: {e:?}"))
}

/// "rq", "/ns/node/pause", "Request" -> "rq/ns/node/pauseRequest", as rmw names a service's topics.
fn service_topic(prefix: &str, service: &str, suffix: &str) -> String {
  format!("{prefix}{service}{suffix}")
}

/// A client of `service` (type pkg/srv/ty), its request writer and reply reader with `qos`.
pub fn client<Req, Resp>(node: &mut Node, service: &str, pkg: &str, ty: &str, qos: QosProfile) -> Result<Client<Req, Resp>, String>
where
  Req: Message + Clone + 'static,
  Resp: Message + 'static,
{
  node
    .create_client::<Req, Resp>(
      ServiceMapping::Cyclone, &service_name(service)?, &ServiceTypeName::new(pkg, ty), qos.clone(), qos)
    .map_err(|e| format!("client {service}: {e:?}"))
}

/// Waits for a server of `service` as discovery reports it: a reader of its requests and a writer
/// of its replies. (Client::wait_for_service re-checks its match only when a new subscription is
/// declared on the graph, so it never wakes for a server that was discovered before the client
/// existed: the usual case for a test calling a running node.)
pub async fn wait_for_server(context: &Context, service: &str) {
  let dds = context.domain_participant();
  let (rq, rr) = (service_topic("rq", service, "Request"), service_topic("rr", service, "Reply"));
  loop {
    let readers = dds.discovered_readers().iter().filter(|r| r.subscription_topic_data.topic_name == rq).count();
    let writers = dds.discovered_writers().iter().filter(|w| w.publication_topic_data.topic_name == rr).count();
    if readers > 0 && writers > 0 {
      break;
    }
    smol::Timer::after(Duration::from_millis(50)).await;
  }
  // Discovery first, then the local match of our writer and reader: give it a moment.
  smol::Timer::after(Duration::from_millis(300)).await;
}

/// Calls `service` once (bounded by `timeout`, the wait for the server included); the reply and
/// the time from request to reply.
pub fn call_timed<Req, Resp>(
  context: &Context, node: &mut Node, service: &str, pkg: &str, ty: &str, request: Req, timeout: Duration,
) -> Result<(Resp, Duration), String>
where
  Req: Message + Clone + 'static,
  Resp: Message + DeserializeOwned + 'static,
{
  let client = client::<Req, Resp>(node, service, pkg, ty, service_qos())?;
  smol::block_on(smol::future::or(
    async {
      wait_for_server(context, service).await;
      let t0 = Instant::now();
      let r = client.async_call_service(request).await.map_err(|e| format!("{service}: {e:?}"))?;
      Ok((r, t0.elapsed()))
    },
    async {
      smol::Timer::after(timeout).await;
      Err(format!("{service}: no reply within {timeout:?}"))
    },
  ))
}

pub fn call<Req, Resp>(
  context: &Context, node: &mut Node, service: &str, pkg: &str, ty: &str, request: Req, timeout: Duration,
) -> Result<Resp, String>
where
  Req: Message + Clone + 'static,
  Resp: Message + DeserializeOwned + 'static,
{
  call_timed(context, node, service, pkg, ty, request, timeout).map(|(r, _)| r)
}

pub fn value_json(raw: &raw::ParameterValue) -> String {
  match ParameterValue::from(raw.clone()) {
    ParameterValue::NotSet => "null".into(),
    ParameterValue::Boolean(b) => b.to_string(),
    ParameterValue::Integer(i) => i.to_string(),
    ParameterValue::Double(d) => format!("{{\"double\": {d:?}}}"),
    ParameterValue::String(s) => json_string(&s),
    other => json_string(&format!("{other:?}")),
  }
}

/// NAME=VALUE as the ROS 2 command line types it: true/false bool, an integer, a number with a
/// point or exponent double, else a string.
pub fn parse_assignment(item: &str) -> Result<raw::Parameter, String> {
  let (name, text) = item.split_once('=').ok_or(format!("{item}: want NAME=VALUE"))?;
  let value = if text == "true" || text == "false" {
    ParameterValue::Boolean(text == "true")
  } else if let Ok(i) = text.parse::<i64>() {
    ParameterValue::Integer(i)
  } else if let Ok(d) = text.parse::<f64>() {
    ParameterValue::Double(d)
  } else {
    ParameterValue::String(text.to_string())
  };
  Ok(ros2_client::Parameter { name: name.to_string(), value }.into())
}

/// std_srvs/srv/Trigger.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TriggerRequest {
  pub structure_needs_at_least_one_member: u8,
}
impl Message for TriggerRequest {}
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct TriggerResponse {
  pub success: bool,
  pub message: String,
}
impl Message for TriggerResponse {}

/// rbsim_msgs/srv/Step.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StepRequest {
  pub steps: u32,
}
impl Message for StepRequest {}
/// rbsim_msgs/srv/ApplyImpulse: J in world axes (N s) at p in the body frame (m).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ApplyImpulseRequest {
  pub body: u32,
  pub jx: f64,
  pub jy: f64,
  pub px: f64,
  pub py: f64,
}
impl Message for ApplyImpulseRequest {}
/// The reply of both: success, message, the step at which it applied.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StepReply {
  pub success: bool,
  pub message: String,
  pub step: u64,
}
impl Message for StepReply {}

fn number<T: std::str::FromStr>(word: &str) -> Result<T, String> {
  word.parse().map_err(|_| format!("not a number: {word}"))
}

/// `params NODE VERB ARGS...`: one JSON line per answer.
pub fn params(context: &Context, node: &mut Node, target: &str, words: &[String], timeout: Duration) -> Result<(), String> {
  let (verb, rest) = words.split_first().ok_or("params NODE list|get|describe|types|set|set-atomic ...")?;
  let names: Vec<String> = rest.to_vec();
  let svc = |s: &str| format!("{target}/{s}");
  match verb.as_str() {
    "list" => {
      let r: ListParametersResponse = call(
        context, node, &svc("list_parameters"), "rcl_interfaces", "ListParameters",
        ListParametersRequest { prefixes: names, depth: 0 }, timeout)?;
      let list: Vec<String> = r.result.names.iter().map(|n| json_string(n)).collect();
      println!("{{\"list\": [{}]}}", list.join(", "));
    }
    "get" => {
      let r: GetParametersResponse =
        call(context, node, &svc("get_parameters"), "rcl_interfaces", "GetParameters", GetParametersRequest { names: names.clone() }, timeout)?;
      for (n, v) in names.iter().zip(r.values.iter()) {
        println!("{{\"get\": {}, \"type\": {}, \"value\": {}}}", json_string(n), v.ptype, value_json(v));
      }
      if r.values.len() != names.len() {
        println!("{{\"get_count\": {}}}", r.values.len());
      }
    }
    "types" => {
      let r: GetParameterTypesResponse = call(
        context, node, &svc("get_parameter_types"), "rcl_interfaces", "GetParameterTypes",
        GetParameterTypesRequest { names: names.clone() }, timeout)?;
      for (n, t) in names.iter().zip(r.values.iter()) {
        println!("{{\"types\": {}, \"type\": {t}}}", json_string(n));
      }
    }
    "describe" => {
      let r: DescribeParametersResponse = call(
        context, node, &svc("describe_parameters"), "rcl_interfaces", "DescribeParameters",
        DescribeParametersRequest { names }, timeout)?;
      for d in &r.values {
        let fr: Vec<String> = d.floating_point_range.iter()
          .map(|r| format!("[{:?}, {:?}, {:?}]", r.from_value, r.to_value, r.step)).collect();
        let ir: Vec<String> = d.integer_range.iter()
          .map(|r| format!("[{}, {}, {}]", r.from_value, r.to_value, r.step)).collect();
        println!(
          "{{\"describe\": {}, \"type\": {}, \"read_only\": {}, \"description\": {}, \"floating_point_range\": [{}], \"integer_range\": [{}]}}",
          json_string(&d.name), d.r#type, d.read_only, json_string(&d.description), fr.join(", "), ir.join(", "));
      }
    }
    "set" | "set-atomic" => {
      let parameter = rest.iter().map(|w| parse_assignment(w)).collect::<Result<Vec<_>, _>>()?;
      let results = if verb == "set" {
        let r: SetParametersResponse = call(
          context, node, &svc("set_parameters"), "rcl_interfaces", "SetParameters", SetParametersRequest { parameter }, timeout)?;
        r.results
      } else {
        let r: SetParametersAtomicallyResponse = call(
          context, node, &svc("set_parameters_atomically"), "rcl_interfaces", "SetParametersAtomically",
          SetParametersRequest { parameter }, timeout)?;
        vec![r.result]
      };
      for r in results {
        println!("{{\"{verb}\": {}, \"reason\": {}}}", r.successful, json_string(&r.reason));
      }
    }
    other => return Err(format!("params: unknown verb {other}")),
  }
  Ok(())
}

/// Requests shorter than their type, sent under its name: the server receives truncated CDR.
/// On rbsim_msgs/srv/ApplyImpulse: the body and no impulse; on rbsim_msgs/srv/Step: nothing (one
/// to three bytes would not do: a sample is padded with zeros to four, a valid u32); on
/// rcl_interfaces/srv/GetParameters: a list of one name without the name.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShortImpulse {
  pub body: u32,
}
impl Message for ShortImpulse {}
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShortStep {}
impl Message for ShortStep {}
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct ShortGet {
  pub count: u32,
}
impl Message for ShortGet {}

fn print_reply(service: &str, success: bool, message: &str, step: Option<u64>, took: std::time::Duration) {
  let step = step.map(|s| format!(", \"step\": {s}")).unwrap_or_default();
  println!(
    "{{\"call\": {}, \"success\": {success}, \"message\": {}{step}, \"took_ms\": {:.3}}}",
    json_string(service), json_string(message), took.as_secs_f64() * 1e3);
}

/// `call SERVICE trigger | step N | impulse BODY JX JY PX PY | impulse-short BODY | step-short | get-short`.
pub fn call_service(context: &Context, node: &mut Node, service: &str, words: &[String], timeout: Duration) -> Result<(), String> {
  let usage = "call SERVICE trigger|step N|impulse BODY JX JY PX PY|impulse-short BODY|step-short|get-short";
  let (kind, rest) = words.split_first().ok_or(usage)?;
  match (kind.as_str(), rest.len()) {
    ("trigger", 0) => {
      let (r, took): (TriggerResponse, _) = call_timed(
        context, node, service, "std_srvs", "Trigger", TriggerRequest { structure_needs_at_least_one_member: 0 }, timeout)?;
      print_reply(service, r.success, &r.message, None, took);
    }
    ("step", 1) => {
      let (r, took): (StepReply, _) =
        call_timed(context, node, service, "rbsim_msgs", "Step", StepRequest { steps: number(&rest[0])? }, timeout)?;
      print_reply(service, r.success, &r.message, Some(r.step), took);
    }
    ("impulse", 5) => {
      let req = ApplyImpulseRequest {
        body: number(&rest[0])?, jx: number(&rest[1])?, jy: number(&rest[2])?, px: number(&rest[3])?, py: number(&rest[4])?,
      };
      let (r, took): (StepReply, _) = call_timed(context, node, service, "rbsim_msgs", "ApplyImpulse", req, timeout)?;
      print_reply(service, r.success, &r.message, Some(r.step), took);
    }
    ("impulse-short", 1) => {
      let req = ShortImpulse { body: number(&rest[0])? };
      let (r, took): (StepReply, _) = call_timed(context, node, service, "rbsim_msgs", "ApplyImpulse", req, timeout)?;
      print_reply(service, r.success, &r.message, Some(r.step), took);
    }
    ("step-short", 0) => {
      let (r, took): (StepReply, _) = call_timed(context, node, service, "rbsim_msgs", "Step", ShortStep {}, timeout)?;
      print_reply(service, r.success, &r.message, Some(r.step), took);
    }
    ("get-short", 0) => {
      let (r, took): (GetParametersResponse, _) =
        call_timed(context, node, service, "rcl_interfaces", "GetParameters", ShortGet { count: 1 }, timeout)?;
      print_reply(service, true, &format!("{} values", r.values.len()), None, took);
    }
    _ => return Err(format!("{usage} (got {})", words.join(" "))),
  }
  Ok(())
}
