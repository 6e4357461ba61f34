//! Clients that do not play nice, a ros2-client server, and round-trip timing:
//!   flood SERVICE KIND N   N requests back to back, then the replies for a bounded time
//!   send SERVICE KIND N    N requests, "sent", then sleep without reading a reply (to be killed)
//! Both first make one call and wait for its reply (a probe, not counted in N): requests written
//! before our writer matched the server's reader would never reach it (volatile), and a test could
//! not tell that loss from the server's.
//!   serve SERVICE [states N]  a std_srvs/srv/Trigger server (or GetEntitiesStates, a canned reply of N
//!                             entities) answering at once, until the timeout
//!   bench SERVICE N W [states]  W warm-up calls, then N sequential Trigger (GetEntitiesStates) calls timed
//! KIND: trigger (std_srvs/srv/Trigger), get (rcl_interfaces/srv/GetParameters of "rate"), step
//! (rbsim_msgs/srv/Step of 1 step). Every request goes out with ServiceMapping::Cyclone.
use std::{
  collections::HashSet,
  io::Write,
  time::{Duration, Instant, SystemTime, UNIX_EPOCH},
};

use futures::StreamExt;
use ros2_client::{
  Context, Message, Node, QosProfile, ServiceMapping, ServiceTypeName,
  qos::{History, Reliability, WhenFull},
  rcl_interfaces::{GetParametersRequest, GetParametersResponse},
};
use serde::de::DeserializeOwned;

use crate::{
  json_string,
  simulation::{self, FiltersRequest, StatesResponse},
  services::{StepReply, StepRequest, TriggerRequest, TriggerResponse, client, service_qos, wait_for_server},
};

/// Wall-clock nanoseconds (the test's clock: namespaces share it).
pub fn wall_ns() -> u128 {
  SystemTime::now().duration_since(UNIX_EPOCH).map(|d| d.as_nanos()).unwrap_or(0)
}

/// Service QoS deep enough to hold a whole flood on our side: every request reaches the server,
/// every reply it sends is kept until read, so any drop is the server's.
fn deep_qos(n: usize) -> QosProfile {
  service_qos()
    .reliability(Reliability::Reliable { when_full: WhenFull::Wait(Duration::from_secs(1)) })
    .history(History::KeepLast { depth: n + 16 })
}

struct Tally {
  sent: HashSet<i64>,
  answered: HashSet<i64>,
  successes: usize,
  duplicates: usize,
  unknown: usize,
  foreign: usize,
  send_errors: usize,
  read_errors: usize,
}

/// `flood`/`send` of one request type: `ok` tells a successful reply.
fn flood_with<Req, Resp>(
  context: &Context, node: &mut Node, service: &str, (pkg, ty): (&str, &str), request: impl Fn() -> Req,
  ok: impl Fn(&Resp) -> bool, n: usize, hold: bool, timeout: Duration,
) -> Result<(), String>
where
  Req: Message + Clone + 'static,
  Resp: Message + DeserializeOwned + 'static,
{
  let client = client::<Req, Resp>(node, service, pkg, ty, deep_qos(n))?;
  // Discovery, then one call answered: our request writer and reply reader are matched with the
  // server's (a volatile writer sends nothing to a reader it has not matched yet).
  let mut probes = HashSet::new();
  let matched = smol::block_on(smol::future::or(
    async {
      wait_for_server(context, service).await;
      loop {
        let Ok(id) = client.async_send_request(request()).await else { return false };
        probes.insert(id.sequence_number);
        let reply = smol::future::or(async { client.async_receive_response(id).await.ok() }, async {
          smol::Timer::after(Duration::from_secs(1)).await;
          None
        });
        if reply.await.is_some() {
          return true;
        }
      }
    },
    async {
      smol::Timer::after(timeout).await;
      false
    },
  ));
  if !matched {
    return Err(format!("{service}: no server answered within {timeout:?}"));
  }
  let mut t = Tally {
    sent: HashSet::new(), answered: HashSet::new(), successes: 0, duplicates: 0, unknown: 0, foreign: 0,
    send_errors: 0, read_errors: 0,
  };
  let start_ns = wall_ns();
  let mut me = None;
  for _ in 0..n {
    match client.send_request(request()) {
      Ok(id) => {
        me = Some(id.writer_gid);
        t.sent.insert(id.sequence_number);
      }
      Err(_) => t.send_errors += 1,
    }
  }
  let sent_ns = wall_ns();
  if hold {
    println!("{{\"sent\": {}, \"probes\": {}, \"service\": {}}}", t.sent.len(), probes.len(), json_string(service));
    let _ = std::io::stdout().flush();
    std::thread::sleep(timeout);
    return Ok(());
  }
  // Replies until all came, nothing came for 2 s, or the timeout.
  let deadline = Instant::now() + timeout;
  let quiet = Duration::from_secs(2);
  let mut last = Instant::now();
  let mut last_reply_ns = sent_ns;
  while t.answered.len() < t.sent.len() && Instant::now() < deadline && last.elapsed() < quiet {
    match client.receive_response() {
      Ok(Some((id, reply))) => {
        if Some(id.writer_gid) != me {
          t.foreign += 1;  // another client's reply on the shared reply topic
          continue;
        }
        if probes.contains(&id.sequence_number) {
          continue;  // a late reply to a probe
        }
        last = Instant::now();
        last_reply_ns = wall_ns();
        if !t.sent.contains(&id.sequence_number) {
          t.unknown += 1;
        } else if !t.answered.insert(id.sequence_number) {
          t.duplicates += 1;
        } else if ok(&reply) {
          t.successes += 1;
        }
      }
      Ok(None) => std::thread::sleep(Duration::from_millis(1)),
      Err(_) => t.read_errors += 1,
    }
  }
  println!(
    "{{\"flood\": {}, \"probes\": {}, \"sent\": {}, \"answered\": {}, \"successes\": {}, \"duplicates\": {}, \"unknown\": {}, \
     \"foreign\": {}, \"send_errors\": {}, \"read_errors\": {}, \"start_ns\": {start_ns}, \"sent_ns\": {sent_ns}, \
     \"last_reply_ns\": {last_reply_ns}, \"end_ns\": {}}}",
    json_string(service), probes.len(), t.sent.len(), t.answered.len(), t.successes, t.duplicates, t.unknown, t.foreign,
    t.send_errors, t.read_errors, wall_ns());
  Ok(())
}

/// `flood SERVICE KIND N` (hold = false) and `send SERVICE KIND N` (hold = true).
pub fn flood(context: &Context, node: &mut Node, service: &str, words: &[String], hold: bool, timeout: Duration) -> Result<(), String> {
  let [kind, n] = words else { return Err("flood|send SERVICE trigger|get|step N".into()) };
  let n: usize = n.parse().ok().filter(|&n| n > 0 && n <= 100_000).ok_or(format!("N: 1..100000 (got {n})"))?;
  match kind.as_str() {
    "trigger" => flood_with(
      context, node, service, ("std_srvs", "Trigger"), || TriggerRequest { structure_needs_at_least_one_member: 0 },
      |r: &TriggerResponse| r.success, n, hold, timeout),
    "get" => flood_with(
      context, node, service, ("rcl_interfaces", "GetParameters"), || GetParametersRequest { names: vec!["rate".into()] },
      |r: &GetParametersResponse| r.values.len() == 1, n, hold, timeout),
    "step" => flood_with(
      context, node, service, ("rbsim_msgs", "Step"), || StepRequest { steps: 1 }, |r: &StepReply| r.success, n, hold,
      timeout),
    other => Err(format!("flood: unknown kind {other} (trigger, get, step)")),
  }
}

/// `serve SERVICE [states N]`: answers every request at once ("served N" on stdout), until the
/// timeout: a std_srvs/srv/Trigger server, or with `states N` a simulation_interfaces/srv/
/// GetEntitiesStates server whose reply is a canned one of N entities (named body_<i>, frame world:
/// byte for byte the size of rbsim's reply for N bodies), made once.
pub fn serve(node: &mut Node, service: &str, words: &[String], timeout: Duration) -> Result<(), String> {
  match words {
    [] => serve_with(node, service, ("std_srvs", "Trigger"), timeout, |_: TriggerRequest| TriggerResponse {
      success: true,
      message: "ok".into(),
    }),
    [kind, n] if kind == "states" => {
      let n: usize = n.parse().ok().filter(|&n| n <= 1_000_000).ok_or(format!("states N: 0..1000000 (got {n})"))?;
      let reply = simulation::canned_states(n);
      serve_with(node, service, ("simulation_interfaces", "GetEntitiesStates"), timeout, move |_: FiltersRequest| {
        reply.clone()
      })
    }
    _ => Err("serve SERVICE [states N]".into()),
  }
}

fn serve_with<Req, Resp>(
  node: &mut Node, service: &str, (pkg, ty): (&str, &str), timeout: Duration, answer: impl Fn(Req) -> Resp,
) -> Result<(), String>
where
  Req: Message + Clone + DeserializeOwned + 'static,
  Resp: Message + 'static,
{
  let name = crate::services::service_name(service)?;
  let server = node
    .create_server::<Req, Resp>(ServiceMapping::Cyclone, &name, &ServiceTypeName::new(pkg, ty), service_qos(), service_qos())
    .map_err(|e| format!("server {service}: {e:?}"))?;
  println!("{{\"serving\": {}}}", json_string(service));
  let _ = std::io::stdout().flush();
  let mut served = 0u64;
  smol::block_on(smol::future::or(
    async {
      let mut requests = Box::pin(server.receive_request_stream());
      while let Some(r) = requests.next().await {
        let Ok((id, request)) = r else { continue };
        if server.async_send_response(id, answer(request)).await.is_ok() {
          served += 1;
        }
      }
    },
    async {
      smol::Timer::after(timeout).await;
    },
  ));
  println!("{{\"served\": {served}}}");
  Ok(())
}

/// `bench SERVICE N W [states]`: W warm-up calls, then N calls one after the other, each timed
/// from sending the request to taking its reply: std_srvs/srv/Trigger, or with `states`
/// simulation_interfaces/srv/GetEntitiesStates without filters (every entity).
pub fn bench(context: &Context, node: &mut Node, service: &str, words: &[String], timeout: Duration) -> Result<(), String> {
  let (n, warmup, kind) = match words {
    [n, w] => (n, w, "trigger"),
    [n, w, k] if k == "states" => (n, w, "states"),
    _ => return Err("bench SERVICE N WARMUP [states]".into()),
  };
  let n: usize = n.parse().ok().filter(|&n| n > 0 && n <= 1_000_000).ok_or(format!("N: 1..1000000 (got {n})"))?;
  let warmup: usize = warmup.parse().map_err(|_| format!("WARMUP: not a count: {warmup}"))?;
  if kind == "states" {
    bench_with(
      context, node, service, ("simulation_interfaces", "GetEntitiesStates"), || FiltersRequest { filters: Default::default() },
      |r: &StatesResponse| format!("{} entities, result {}", r.states.len(), r.result.result), n, warmup, timeout)
  } else {
    bench_with(
      context, node, service, ("std_srvs", "Trigger"), || TriggerRequest { structure_needs_at_least_one_member: 0 },
      |r: &TriggerResponse| r.message.clone(), n, warmup, timeout)
  }
}

#[allow(clippy::too_many_arguments)]
fn bench_with<Req, Resp>(
  context: &Context, node: &mut Node, service: &str, (pkg, ty): (&str, &str), request: impl Fn() -> Req,
  describe: impl Fn(&Resp) -> String, n: usize, warmup: usize, timeout: Duration,
) -> Result<(), String>
where
  Req: Message + Clone + 'static,
  Resp: Message + DeserializeOwned + 'static,
{
  let client = client::<Req, Resp>(node, service, pkg, ty, service_qos())?;
  let deadline = Instant::now() + timeout;
  let mut times = Vec::with_capacity(n);
  let mut message = String::new();
  let done = smol::block_on(smol::future::or(
    async {
      wait_for_server(context, service).await;
      for k in 0..warmup + n {
        let t0 = Instant::now();
        let r = client.async_call_service(request()).await;
        let took = t0.elapsed();
        let Ok(r) = r else { return false };
        if k >= warmup {
          times.push(took.as_secs_f64() * 1e6);
        }
        message = describe(&r);
        if Instant::now() >= deadline {
          return false;
        }
      }
      true
    },
    async {
      smol::Timer::after(timeout).await;
      false
    },
  ));
  if !done {
    return Err(format!("{service}: {} of {} calls within {timeout:?}", times.len(), n));
  }
  times.sort_by(|a, b| a.total_cmp(b));
  let at = |q: f64| times[((q * (times.len() - 1) as f64).round() as usize).min(times.len() - 1)];
  println!(
    "{{\"bench\": {}, \"calls\": {}, \"median_us\": {:.1}, \"p99_us\": {:.1}, \"min_us\": {:.1}, \"max_us\": {:.1}, \
     \"last_message\": {}}}",
    json_string(service), times.len(), at(0.5), at(0.99), times[0], times[times.len() - 1], json_string(&message));
  Ok(())
}
