//! The Zenoh side of the link (the `link` feature). Conventions: times are wall-clock UNIX s.

use super::HEALTH_PERIOD_S;
use super::health::Health;
use crate::shell::config::ShipcastConfig;
use crate::shell::daemon::wall_s;
use crate::shell::ipc::wire::{
    ForecastHeader, LinkStatus, MotionSample, NavigationSample, Status, check_forecast, check_status,
};
use crate::shell::ipc::{LinkPublisher, Local, LocalSubscriber, Names, Output, OutputPublisher, SensorPublisher};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::time::Duration;
use zenoh::Wait;
use zenoh::qos::CongestionControl;
use zenoh::sample::Locality;

/// One message between the links: its stream's number, the sender's wall clock and what it carries
/// (postcard-encoded).
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Envelope {
    pub seq: u64,
    pub sent_wall_s: f64,
    pub message: Message,
}

#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
#[allow(clippy::large_enum_variant)]
pub enum Message {
    Motion(MotionSample),
    Navigation(NavigationSample),
    Forecast(ForecastHeader, Vec<f64>),
    Status(Status),
}

impl Message {
    fn kind(&self) -> &'static str {
        match self {
            Message::Motion(_) => "motion",
            Message::Navigation(_) => "navigation",
            Message::Forecast(..) => "forecast",
            Message::Status(_) => "status",
        }
    }
}

const KINDS: [&str; 4] = ["motion", "navigation", "forecast", "status"];

/// How long a blocked thread waits before it looks at the stop flag.
const STOP_CHECK: Duration = Duration::from_millis(200);

fn key(cfg: &ShipcastConfig, name: &str, kind: &str) -> String {
    format!("shipcast/{}/{name}/{kind}", cfg.link.namespace)
}

/// The Zenoh session: a peer that listens and connects where `[link]` says, and looks for nobody
/// else (no multicast scouting: the other ship is named).
fn session(cfg: &ShipcastConfig) -> anyhow::Result<zenoh::Session> {
    let l = &cfg.link;
    let mut z = zenoh::Config::default();
    let set = |z: &mut zenoh::Config, k: &str, v: String| {
        z.insert_json5(k, &v)
            .map_err(|e| anyhow::anyhow!("{}: [link] {k} = {v}: {e}", cfg.path.display()))
    };
    set(&mut z, "mode", "\"peer\"".into())?;
    set(&mut z, "scouting/multicast/enabled", "false".into())?;
    set(&mut z, "scouting/gossip/enabled", "false".into())?;
    set(&mut z, "listen/endpoints", serde_json::to_string(&l.listen)?)?;
    set(&mut z, "connect/endpoints", serde_json::to_string(&l.connect)?)?;
    // keep trying the other ship while the radio is down (not only at start)
    set(&mut z, "connect/timeout_ms", "-1".into())?;
    set(&mut z, "connect/exit_on_failure", "false".into())?;
    // ... every second at most (Zenoh's default backs off to 4 s)
    set(
        &mut z,
        "connect/retry",
        "{period_init_ms: 500, period_max_ms: 1000, period_increase_factor: 2}".into(),
    )?;
    // a forecast is hundreds of kB (the demo pair's: 330 kB): room for a few in the queue
    set(&mut z, "transport/link/tx/queue/size/data", "16".into())?;
    zenoh::open(z).wait().map_err(|e| {
        anyhow::anyhow!(
            "opening the Zenoh session ([link] listen {:?}, connect {:?}): {e}",
            l.listen,
            l.connect
        )
    })
}

/// Runs the link until `stop` is set.
pub fn run(cfg: &ShipcastConfig, stop: Arc<AtomicBool>) -> anyhow::Result<()> {
    let session = session(cfg)?;
    let own = Names {
        prefix: cfg.ipc.service_prefix.clone(),
    };
    let peer = Names {
        prefix: cfg.link.peer_prefix_of(&cfg.ipc),
    };
    let sent = Arc::new(AtomicU64::new(0));
    tracing::info!(
        name = %cfg.link.name,
        namespace = %cfg.link.namespace,
        listen = ?cfg.link.listen,
        connect = ?cfg.link.connect,
        own_vessels = ?cfg.link.own_vessels,
        peer_prefix = %peer.prefix,
        "link up: sending own vessels' motion{}, taking the others'",
        if cfg.link.forecasts_out { " and this ship's forecasts" } else { "" }
    );
    let out = {
        let (cfg, session, stop, sent, own) = (cfg.clone(), session.clone(), stop.clone(), sent.clone(), own.clone());
        std::thread::Builder::new()
            .name("shipcast-link-out".into())
            .spawn(move || send_loop(&cfg, &session, &own, &stop, &sent))?
    };
    let r = receive_loop(cfg, &session, &own, &peer, &stop, &sent);
    stop.store(true, Ordering::Relaxed);
    let r_out = out
        .join()
        .map_err(|_| anyhow::anyhow!("the link's sending thread panicked"))?;
    let _ = session.close().wait();
    r.and(r_out)
}

/// Local services to Zenoh.
fn send_loop(
    cfg: &ShipcastConfig,
    session: &zenoh::Session,
    own: &Names,
    stop: &AtomicBool,
    sent: &AtomicU64,
) -> anyhow::Result<()> {
    let local = LocalSubscriber::new(own).map_err(|e| anyhow::anyhow!("iceoryx2 ({}): {e}", own.prefix))?;
    let mut publishers = vec![];
    for kind in KINDS {
        // motion and navigation: the newest counts, a sample that cannot go now is dropped; forecasts
        // and status wait for room (a forecast's fragments must all go)
        let congestion = match kind {
            "motion" | "navigation" => CongestionControl::Drop,
            _ => CongestionControl::Block,
        };
        let p = session
            .declare_publisher(key(cfg, &cfg.link.name, kind))
            .express(true)
            .congestion_control(congestion)
            .wait()
            .map_err(|e| anyhow::anyhow!("Zenoh publisher: {e}"))?;
        publishers.push(p);
    }
    let mut seq = [0u64; 4];
    let mut got = vec![];
    while !stop.load(Ordering::Relaxed) {
        got.clear();
        local
            .wait(STOP_CHECK, &mut got)
            .map_err(|e| anyhow::anyhow!("iceoryx2 ({}): {e}", own.prefix))?;
        for l in got.drain(..) {
            let message = match l {
                Local::Motion(m) if cfg.link.own_vessels.contains(&m.vessel) => Message::Motion(m),
                Local::Navigation(n) if cfg.link.own_vessels.contains(&n.vessel) => Message::Navigation(n),
                Local::Output(Output::Forecast(h, v)) if cfg.link.forecasts_out => Message::Forecast(h, v),
                Local::Output(Output::Status(s)) if cfg.link.forecasts_out => Message::Status(s),
                _ => continue,
            };
            let k = KINDS.iter().position(|k| *k == message.kind()).unwrap_or(0);
            let env = Envelope {
                seq: seq[k],
                sent_wall_s: wall_s(),
                message,
            };
            seq[k] += 1;
            let bytes = postcard::to_stdvec(&env)?;
            // a put while the other ship is away goes nowhere: that is the loss the other side counts
            if let Err(e) = publishers[k].put(bytes).wait() {
                tracing::warn!("sending {} over Zenoh: {e}", KINDS[k]);
            } else {
                sent.fetch_add(1, Ordering::Relaxed);
            }
        }
    }
    Ok(())
}

/// The link's health, published on this ship's services; the link's coming up or going down logged.
fn tell_health(s: &LinkStatus, health_out: &LinkPublisher, was_up: &mut Option<bool>, stale_s: f64) {
    if let Err(e) = health_out.publish(s) {
        tracing::warn!("publishing the link's health: {e}");
    }
    let up = s.up == 1;
    if *was_up != Some(up) {
        if up {
            tracing::info!(latency_ms = s.latency_ms, "the other ship is heard");
        } else if was_up.is_some() {
            tracing::warn!(
                last_message_age_s = s.last_message_age_s,
                "nothing from the other ship for {stale_s} s: link down"
            );
        }
        *was_up = Some(up);
    }
}

/// The other ship's forecast or status, checked as every consumer here checks them
/// ([`check_forecast`], [`check_status`]: the header against the payload, the schema) before it is
/// republished on this ship's services; Err: why it is dropped.
fn peer_output(message: Message) -> Result<Output, String> {
    match message {
        Message::Forecast(h, v) => check_forecast(&h, v.len()).map(|()| Output::Forecast(h, v)),
        Message::Status(s) => check_status(&s).map(|()| Output::Status(s)),
        other => Err(format!("{} is not an output", other.kind())),
    }
}

/// Zenoh to local services, and the link's health.
fn receive_loop(
    cfg: &ShipcastConfig,
    session: &zenoh::Session,
    own: &Names,
    peer: &Names,
    stop: &AtomicBool,
    sent: &AtomicU64,
) -> anyhow::Result<()> {
    let iox = |e: crate::shell::ipc::Error| anyhow::anyhow!("iceoryx2: {e}");
    let sensors = SensorPublisher::new(own).map_err(iox)?;
    let outputs = OutputPublisher::new(peer).map_err(iox)?;
    let health_out = LinkPublisher::new(own).map_err(iox)?;
    let sub = session
        .declare_subscriber(format!("shipcast/{}/*/*", cfg.link.namespace))
        // the other ship's only: not this link's own puts
        .allowed_origin(Locality::Remote)
        .wait()
        .map_err(|e| anyhow::anyhow!("Zenoh subscriber: {e}"))?;
    let mut health = Health::new(cfg.link.window_s, cfg.link.stale_s);
    let mut next_health = wall_s();
    let mut was_up: Option<bool> = None;
    let (mut refused, mut foreign, mut dropped) = (0u64, 0u64, 0u64);
    let mut same_name_said = false;
    while !stop.load(Ordering::Relaxed) {
        let now = wall_s();
        if now >= next_health {
            let s = health.status(now, sent.load(Ordering::Relaxed));
            tell_health(&s, &health_out, &mut was_up, cfg.link.stale_s);
            next_health = now + HEALTH_PERIOD_S;
        }
        let wait = Duration::from_secs_f64((next_health - wall_s()).clamp(0.001, HEALTH_PERIOD_S));
        let Some(sample) = sub
            .recv_timeout(wait.min(STOP_CHECK))
            .map_err(|e| anyhow::anyhow!("Zenoh: {e}"))?
        else {
            continue;
        };
        let k = sample.key_expr().as_str();
        let mut parts = k.rsplit('/');
        let (kind, from) = (parts.next().unwrap_or(""), parts.next().unwrap_or(""));
        if from == cfg.link.name && !same_name_said {
            same_name_said = true;
            tracing::warn!("the other ship's link is also named {from:?}: give each ship its own [link] name");
        }
        let env: Envelope = match postcard::from_bytes(&sample.payload().to_bytes()) {
            Ok(e) => e,
            Err(e) => {
                refused += 1;
                if refused.is_power_of_two() {
                    tracing::warn!(refused, "a message on {k} not understood: {e}");
                }
                continue;
            }
        };
        health.received(&format!("{from}/{kind}"), env.seq, env.sent_wall_s, wall_s());
        let r = match env.message {
            Message::Motion(m) if !cfg.link.own_vessels.contains(&m.vessel) => sensors.motion(&m),
            Message::Navigation(n) if !cfg.link.own_vessels.contains(&n.vessel) => sensors.navigation(&n),
            m @ (Message::Forecast(..) | Message::Status(..)) => match peer_output(m) {
                Ok(out) => outputs.publish(&out),
                Err(why) => {
                    dropped += 1;
                    if dropped.is_power_of_two() {
                        tracing::warn!(dropped, "{from}'s {why}: dropped");
                    }
                    Ok(())
                }
            },
            // the other ship says it measures a vessel this one measures: not taken
            _ => {
                foreign += 1;
                if foreign.is_power_of_two() {
                    tracing::warn!(
                        foreign,
                        "{from} sends a vessel this ship measures itself (link.own_vessels {:?}): not taken",
                        cfg.link.own_vessels
                    );
                }
                Ok(())
            }
        };
        if let Err(e) = r {
            tracing::warn!("publishing what came from {from}: {e}");
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::message::{FORECAST_SCHEMA_VERSION, STATUS_SCHEMA_VERSION};

    /// Was: the other ship's forecasts were republished here unchecked (a header that does not fit
    /// its payload reached every consumer of this ship's services).
    #[test]
    fn a_peer_forecast_or_status_that_does_not_fit_its_header_is_dropped() {
        let h = ForecastHeader {
            schema_version: FORECAST_SCHEMA_VERSION,
            n_vessels: 1,
            n_series: 6,
            steps: 10,
            dt_s: 0.1,
            ..ForecastHeader::default()
        };
        assert!(peer_output(Message::Forecast(h, vec![0.0; 2 * 11 * 6])).is_ok());
        // the standard deviations missing, a vessel count beyond the payload's, another schema
        assert!(peer_output(Message::Forecast(h, vec![0.0; 11 * 6])).is_err());
        let many = ForecastHeader {
            n_vessels: 9,
            n_series: 54,
            ..h
        };
        assert!(peer_output(Message::Forecast(many, vec![0.0; 2 * 11 * 54])).is_err());
        let old = ForecastHeader { schema_version: 1, ..h };
        assert!(peer_output(Message::Forecast(old, vec![0.0; 2 * 11 * 6])).is_err());
        let s = Status {
            schema_version: STATUS_SCHEMA_VERSION,
            ..Status::default()
        };
        assert!(peer_output(Message::Status(s)).is_ok());
        assert!(peer_output(Message::Status(Status::default())).is_err());
    }
}
