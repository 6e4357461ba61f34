//! rbsim_msgs/msg/Command on /<ns>/commands, declared here from Command.msg (field for field: serde's
//! CDR follows declaration order), read the way a late ROS 2 subscriber reads it: reliable,
//! transient local, keep all, so the node's whole history of commands arrives.
use std::time::Duration;

use futures::StreamExt;
use ros2_client::{
  MessageTypeName, Name, Node, QosProfile,
  builtin_interfaces::Time,
  parameters::raw,
  qos::{Durability, History, Reliability, WhenFull},
};
use serde::{Deserialize, Serialize};

use crate::{json_string, within};

#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Command {
  pub seq: u64,
  pub step: u64,
  pub stamp: Time,
  pub kind: u8,
  pub source: String,
  pub parameters: Vec<raw::Parameter>,
  pub atomic: bool,
  pub steps: u64,
  pub pause_seconds: f64,
  pub body: u32,
  pub jx: f64,
  pub jy: f64,
  pub px: f64,
  pub py: f64,
  pub success: bool,
  pub message: String,
}
impl ros2_client::Message for Command {}

/// `commands /NS/commands COUNT`: prints each command as a JSON line until COUNT arrived.
pub fn take(node: &mut Node, topic: &str, want: usize, timeout: Duration) -> Result<bool, String> {
  let (ns, base) = topic.rsplit_once('/').ok_or(format!("{topic}: not a fully qualified name"))?;
  let name = Name::new(if ns.is_empty() { "/" } else { ns }, base).map_err(|e| format!("{topic}: {e:?}"))?;
  let qos = QosProfile::subscription_default()
    .reliability(Reliability::Reliable { when_full: WhenFull::Block })
    .durability(Durability::TransientLocal)
    .history(History::KeepAll);
  let t = node
    .create_topic(&name, MessageTypeName::new("rbsim_msgs", "Command"), &qos)
    .map_err(|e| format!("topic {topic}: {e:?}"))?;
  let sub = node.create_subscription::<Command>(&t, Some(qos)).map_err(|e| format!("subscription {topic}: {e:?}"))?;
  Ok(within(timeout, async {
    let mut stream = Box::pin(sub.async_stream());
    let mut seen = 0;
    while let Some(m) = stream.next().await {
      let Ok((c, _)) = m else { continue };
      let names: Vec<String> = c.parameters.iter().map(|p| json_string(&p.name)).collect();
      println!(
        "{{\"seq\": {}, \"step\": {}, \"stamp_ns\": {}, \"kind\": {}, \"source\": {}, \"parameters\": [{}], \"atomic\": {}, \"steps\": {}, \"body\": {}, \"j\": [{:?}, {:?}], \"p\": [{:?}, {:?}], \"success\": {}, \"message\": {}}}",
        c.seq, c.step, c.stamp.to_nanos(), c.kind, json_string(&c.source), names.join(", "), c.atomic, c.steps, c.body,
        c.jx, c.jy, c.px, c.py, c.success, json_string(&c.message)
      );
      seen += 1;
      if seen >= want {
        return true;
      }
    }
    false
  }))
}
