//! rbsim-ros2-peer: a ROS 2 node written with ros2-client (not ours) that looks at rbsim the way a
//! ROS 2 tool does. One line of JSON per finding on stdout, diagnostics on stderr; exit 0 when
//! the awaited thing was seen, 1 on timeout, 2 on usage errors.
//!
//!   rbsim-ros2-peer graph /rbsim [--timeout S]     wait for the node in ros_discovery_info
//!   rbsim-ros2-peer tf N [--timeout S]             take N /tf messages
//!   rbsim-ros2-peer rosout TEXT [--timeout S]      wait for a /rosout line containing TEXT
//!   rbsim-ros2-peer events NAME [--timeout S]      wait for NAME on /parameter_events
//!   rbsim-ros2-peer params NODE list|get|describe|types|set|set-atomic ARGS...
//!   rbsim-ros2-peer call SERVICE trigger | step N | impulse BODY JX JY PX PY
//!   rbsim-ros2-peer commands /NS/commands COUNT     take COUNT commands (the node's history too)
//!                        | impulse-short BODY | step-short | get-short   (requests shorter than their type)
//!   rbsim-ros2-peer flood SERVICE trigger|get|step N    one call answered, then N requests without waiting;
//!                                                       count the replies (one JSON line: sent, answered, ...)
//!   rbsim-ros2-peer send SERVICE trigger|get|step N     the same N requests, "sent", then sleep unread (to be killed)
//!   rbsim-ros2-peer serve SERVICE [states N]            a Trigger server of our own, answering at once (or a
//!                                                       GetEntitiesStates server with a canned reply of N entities)
//!   rbsim-ros2-peer bench SERVICE N WARMUP [states]     N sequential Trigger (GetEntitiesStates) calls timed: median, p99
//!   rbsim-ros2-peer sim /NS OP ARGS [, OP ARGS]...      simulation_interfaces and get_type_description (simulation.rs)
//! /tf lines carry the wall time of their arrival (wall_ns); flood prints the wall times of its
//! start, last send, last reply and end, so a test can line them up.
use std::{process::ExitCode, time::Duration};

use futures::StreamExt;
use ros2_client::{
  Context, ContextOptions, MessageTypeName, Name, NodeEvent, NodeName, NodeOptions, QosProfile,
  qos::{Durability, History, Reliability, WhenFull},
};
use serde::{Deserialize, Serialize};

mod commands;
mod hostile;
mod services;
mod simulation;

mod tf {
  //! tf2_msgs/msg/TFMessage, field for field (serde's CDR follows declaration order).
  use super::*;
  // geometry_msgs' and std_msgs' types, as simulation_interfaces' states use them too.
  pub use crate::simulation::{Header, Quaternion, Vector3};
  #[derive(Debug, Clone, Serialize, Deserialize)]
  pub struct Transform {
    pub translation: Vector3,
    pub rotation: Quaternion,
  }
  #[derive(Debug, Clone, Serialize, Deserialize)]
  pub struct TransformStamped {
    pub header: Header,
    pub child_frame_id: String,
    pub transform: Transform,
  }
  #[derive(Debug, Clone, Serialize, Deserialize)]
  pub struct TFMessage {
    pub transforms: Vec<TransformStamped>,
  }
  impl ros2_client::Message for TFMessage {}
}

struct Args {
  verb: String,
  operand: String,
  rest: Vec<String>,
  timeout: Duration,
}

fn parse_args() -> Result<Args, String> {
  let mut words: Vec<String> = std::env::args().skip(1).collect();
  let mut timeout = Duration::from_secs(20);
  if let Some(i) = words.iter().position(|w| w == "--timeout") {
    let value = words.get(i + 1).ok_or("--timeout needs seconds")?;
    let s: f64 = value.parse().map_err(|_| format!("--timeout: not a number: {value}"))?;
    if !(s > 0.0 && s < 3600.0) {
      return Err(format!("--timeout: must be in (0, 3600) s (got {value})"));
    }
    timeout = Duration::from_secs_f64(s);
    words.drain(i..i + 2);
  }
  if words.len() < 2 {
    return Err(
      "usage: rbsim-ros2-peer graph NODE | tf COUNT | rosout TEXT | events NAME | params NODE ... | call SERVICE ... \
       | flood|send SERVICE KIND N | serve SERVICE [states N] | bench SERVICE N WARMUP [states] | sim /NS OP ... [--timeout S]"
        .into(),
    );
  }
  Ok(Args { verb: words[0].clone(), operand: words[1].clone(), rest: words[2..].to_vec(), timeout })
}

pub(crate) fn json_string(s: &str) -> String {
  let mut out = String::from("\"");
  for c in s.chars() {
    match c {
      '"' => out.push_str("\\\""),
      '\\' => out.push_str("\\\\"),
      c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
      c => out.push(c),
    }
  }
  out.push('"');
  out
}

/// Runs `work` until it returns true or `timeout` passes.
pub(crate) fn within(timeout: Duration, work: impl std::future::Future<Output = bool>) -> bool {
  smol::block_on(smol::future::or(work, async {
    smol::Timer::after(timeout).await;
    false
  }))
}

fn main() -> ExitCode {
  let args = match parse_args() {
    Ok(a) => a,
    Err(e) => {
      eprintln!("rbsim-ros2-peer: {e}");
      return ExitCode::from(2);
    }
  };
  // ROS_DOMAIN_ID as every ROS 2 tool reads it (ros2-client itself takes the id as an argument).
  let domain: u16 = match std::env::var("ROS_DOMAIN_ID") {
    Ok(v) => match v.parse() {
      Ok(d) if d <= 232 => d,
      _ => {
        eprintln!("rbsim-ros2-peer: ROS_DOMAIN_ID: an integer in [0, 232] (got {v})");
        return ExitCode::from(2);
      }
    },
    Err(_) => 0,
  };
  let context = Context::with_options(ContextOptions::new().domain_id(domain)).expect("DDS participant");
  let mut node = context
    .new_node(NodeName::new("/rbsim_test", "ros2_peer").unwrap(), NodeOptions::new().enable_rosout(false))
    .expect("node");
  // The spinner first: ros2-client hands out graph events only to a node that spins. The graph
  // events receiver only for `graph`: an unread one fills up and stalls the spinner, and with it
  // the matching that wait_for_service waits for.
  let spinner = node.spinner().expect("spinner");
  let events = if args.verb == "graph" { node.status_receiver() } else { None };
  smol::spawn(spinner.spin()).detach();

  let found = match args.verb.as_str() {
    "graph" => within(args.timeout, async {
      let mut events = Box::pin(events.expect("status receiver"));
      while let Some(event) = events.next().await {
        if let NodeEvent::ParticipantEntities(info) = event {
          for n in info.nodes() {
            // ros2-client decoded this from our ros_discovery_info: its name, namespace and
            // endpoint GIDs as it understood them.
            println!(
              "{{\"participant\": \"{:?}\", \"node\": {}, \"namespace\": {}, \"name\": {}, \"entities\": {}}}",
              info.gid(),
              json_string(&n.fully_qualified_name()),
              json_string(n.namespace()),
              json_string(n.name()),
              json_string(&format!("{n:?}"))
            );
            if n.fully_qualified_name() == args.operand {
              return true;
            }
          }
        }
      }
      false
    }),
    "tf" => {
      let want: usize = match args.operand.parse() {
        Ok(n) if n > 0 => n,
        _ => {
          eprintln!("rbsim-ros2-peer: tf COUNT: a positive integer (got {})", args.operand);
          return ExitCode::from(2);
        }
      };
      let qos = QosProfile::subscription_default()
        .reliability(Reliability::Reliable { when_full: WhenFull::Block })
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 100 });
      let topic = node
        .create_topic(&Name::new("/", "tf").unwrap(), MessageTypeName::new("tf2_msgs", "TFMessage"), &qos)
        .expect("topic /tf");
      let sub = node.create_subscription::<tf::TFMessage>(&topic, Some(qos)).expect("subscription /tf");
      within(args.timeout, async {
        let mut stream = Box::pin(sub.async_stream());
        let mut seen = 0;
        while let Some(m) = stream.next().await {
          let Ok((msg, _)) = m else { continue };
          seen += 1;
          let first = msg.transforms.first();
          println!(
            "{{\"tf\": {seen}, \"transforms\": {}, \"stamp_ns\": {}, \"frame\": {}, \"child\": {}, \"x\": {:?}, \"y\": {:?}, \"wall_ns\": {}}}",
            msg.transforms.len(),
            first.map(|t| t.header.stamp.to_nanos()).unwrap_or(-1),
            json_string(first.map(|t| t.header.frame_id.as_str()).unwrap_or("")),
            json_string(first.map(|t| t.child_frame_id.as_str()).unwrap_or("")),
            first.map(|t| t.transform.translation.x).unwrap_or(f64::NAN),
            first.map(|t| t.transform.translation.y).unwrap_or(f64::NAN),
            hostile::wall_ns()
          );
          if seen >= want {
            return true;
          }
        }
        false
      })
    }
    "rosout" => {
      let qos = QosProfile::subscription_default()
        .reliability(Reliability::Reliable { when_full: WhenFull::Block })
        .durability(Durability::TransientLocal)
        .history(History::KeepLast { depth: 1000 });
      let topic = node
        .create_topic(&Name::new("/", "rosout").unwrap(), MessageTypeName::new("rcl_interfaces", "Log"), &qos)
        .expect("topic /rosout");
      let sub = node.create_subscription::<ros2_client::Log>(&topic, Some(qos)).expect("subscription /rosout");
      within(args.timeout, async {
        let mut stream = Box::pin(sub.async_stream());
        while let Some(m) = stream.next().await {
          let Ok((log, _)) = m else { continue };
          println!(
            "{{\"rosout\": {}, \"level\": {}, \"name\": {}, \"file\": {}, \"function\": {}, \"line\": {}, \"stamp_ns\": {}}}",
            json_string(log.get_msg()),
            log.get_level(),
            json_string(log.name()),
            json_string(log.get_file()),
            json_string(&log.function),
            log.line,
            log.stamp.to_nanos()
          );
          if log.get_msg().contains(&args.operand) {
            return true;
          }
        }
        false
      })
    }
    "events" => {
      // rclcpp's parameter events QoS: reliable, volatile, keep last 1000.
      let qos = QosProfile::subscription_default()
        .reliability(Reliability::Reliable { when_full: WhenFull::Block })
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 1000 });
      let topic = node
        .create_topic(
          &Name::new("/", "parameter_events").unwrap(),
          MessageTypeName::new("rcl_interfaces", "ParameterEvent"),
          &qos,
        )
        .expect("topic /parameter_events");
      let sub = node
        .create_subscription::<ros2_client::parameters::raw::ParameterEvent>(&topic, Some(qos))
        .expect("subscription /parameter_events");
      within(args.timeout, async {
        let mut stream = Box::pin(sub.async_stream());
        while let Some(m) = stream.next().await {
          let Ok((event, _)) = m else { continue };
          let mut hit = false;
          for p in event.new_parameters.iter().chain(event.changed_parameters.iter()) {
            println!(
              "{{\"event\": {}, \"node\": {}, \"value\": {}, \"stamp_ns\": {}}}",
              json_string(&p.name),
              json_string(&event.node),
              services::value_json(&p.value),
              event.stamp.to_nanos()
            );
            hit |= p.name == args.operand;
          }
          if hit {
            return true;
          }
        }
        false
      })
    }
    "commands" => {
      let want: usize = args.rest.first().and_then(|w| w.parse().ok()).unwrap_or(0);
      match commands::take(&mut node, &args.operand, want.max(1), args.timeout) {
        Ok(found) => found,
        Err(e) => {
          eprintln!("rbsim-ros2-peer: {e}");
          false
        }
      }
    }
    "params" | "call" | "flood" | "send" | "serve" | "bench" | "sim" => {
      let (target, rest, timeout) = (&args.operand, &args.rest, args.timeout);
      let result = match args.verb.as_str() {
        "params" => services::params(&context, &mut node, target, rest, timeout),
        "call" => services::call_service(&context, &mut node, target, rest, timeout),
        "flood" | "send" => hostile::flood(&context, &mut node, target, rest, args.verb == "send", timeout),
        "serve" => hostile::serve(&mut node, target, rest, timeout),
        "sim" => simulation::sim(&context, &mut node, target, rest, timeout),
        _ => hostile::bench(&context, &mut node, target, rest, timeout),
      };
      if let Err(e) = &result {
        eprintln!("rbsim-ros2-peer: {e}");
      }
      result.is_ok()
    }
    other => {
      eprintln!("rbsim-ros2-peer: unknown verb {other} (graph, tf, rosout, events, commands, params, call, flood, send, serve, bench, sim)");
      return ExitCode::from(2);
    }
  };
  // Leave the graph the way a ROS 2 node does: stop spinning and drop the node and its DDS
  // participant (RustDDS then announces that it left), so the peers do not wait for its lease.
  node.stop_spinner();
  drop(node);
  drop(context);
  std::thread::sleep(Duration::from_millis(200));
  if found {
    ExitCode::SUCCESS
  } else {
    eprintln!("rbsim-ros2-peer: {} {}: not seen within {:?}", args.verb, args.operand, args.timeout);
    ExitCode::from(1)
  }
}
