//! iceoryx2 ports (shell): the service layout shared by every participant, the daemon's input and
//! output threads bridged to tokio, and the small blocking endpoints the simulator and `watch` use.
//!
//! Ports live on threads of their own (iceoryx2 `ipc::Service` ports are not `Send`): the input thread
//! sleeps in a WaitSet on the event services of `motion` and `waves` (woken by the publishers'
//! notifications, plus a slow interval to notice shutdown) and forwards owned copies over a tokio
//! channel; the output thread blocks on a std channel and publishes forecasts and status, notifying
//! after each send. No busy polling. Signal handling is left to tokio (`SignalHandlingMode::Disabled`).

pub mod wire;

pub use crate::engine::message::{Input, Output, Scan};

use crate::waves::field::WaveField;
use iceoryx2::port::listener::Listener;
use iceoryx2::port::notifier::Notifier;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use iceoryx2::prelude::*;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Duration;
use wire::*;

/// Subscriber buffers: a forecast cycle of 1 s at a 50 Hz IMU for 4 vessels fits.
pub const BUFFER: usize = 256;
/// How often blocked threads look at their stop flag.
const STOP_CHECK: Duration = Duration::from_millis(200);

pub type Error = Box<dyn std::error::Error + Send + Sync>;
pub type Result<T> = std::result::Result<T, Error>;

fn err(e: impl std::fmt::Display) -> Error {
    e.to_string().into()
}

/// The service names of one deployment: `<prefix>/motion|navigation|waves|forecast|status`.
#[derive(Debug, Clone, PartialEq)]
pub struct Names {
    pub prefix: String,
}

impl Names {
    fn name(&self, kind: &str) -> Result<ServiceName> {
        ServiceName::new(&format!("{}/{kind}", self.prefix)).map_err(err)
    }
}

pub fn node() -> Result<Node<ipc::Service>> {
    NodeBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(err)
}

fn waitset() -> Result<WaitSet<ipc::Service>> {
    WaitSetBuilder::new()
        .signal_handling_mode(SignalHandlingMode::Disabled)
        .create::<ipc::Service>()
        .map_err(err)
}

fn event(
    node: &Node<ipc::Service>,
    names: &Names,
    kind: &str,
) -> Result<(Notifier<ipc::Service>, Listener<ipc::Service>)> {
    let svc = node
        .service_builder(&names.name(kind)?)
        .event()
        .open_or_create()
        .map_err(err)?;
    Ok((
        svc.notifier_builder().create().map_err(err)?,
        svc.listener_builder().create().map_err(err)?,
    ))
}

type SliceService<H> = iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, [f64], H>;
type F32Service<H> = iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, [f32], H>;
type FixedService<T> = iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, T, ()>;

fn motion_service(node: &Node<ipc::Service>, names: &Names) -> Result<FixedService<MotionSample>> {
    node.service_builder(&names.name("motion")?)
        .publish_subscribe::<MotionSample>()
        .subscriber_max_buffer_size(BUFFER)
        .max_publishers(8)
        .open_or_create()
        .map_err(err)
}

fn navigation_service(node: &Node<ipc::Service>, names: &Names) -> Result<FixedService<NavigationSample>> {
    node.service_builder(&names.name("navigation")?)
        .publish_subscribe::<NavigationSample>()
        .subscriber_max_buffer_size(BUFFER)
        .max_publishers(8)
        .open_or_create()
        .map_err(err)
}

fn elevation_service(node: &Node<ipc::Service>, names: &Names) -> Result<F32Service<ElevationHeader>> {
    node.service_builder(&names.name("elevation")?)
        .publish_subscribe::<[f32]>()
        .user_header::<ElevationHeader>()
        .subscriber_max_buffer_size(8)
        .open_or_create()
        .map_err(err)
}

fn waves_service(node: &Node<ipc::Service>, names: &Names) -> Result<SliceService<WaveHeader>> {
    node.service_builder(&names.name("waves")?)
        .publish_subscribe::<[f64]>()
        .user_header::<WaveHeader>()
        .subscriber_max_buffer_size(8)
        .history_size(1)
        .open_or_create()
        .map_err(err)
}

fn forecast_service(node: &Node<ipc::Service>, names: &Names) -> Result<SliceService<ForecastHeader>> {
    node.service_builder(&names.name("forecast")?)
        .publish_subscribe::<[f64]>()
        .user_header::<ForecastHeader>()
        .subscriber_max_buffer_size(8)
        .history_size(1)
        .open_or_create()
        .map_err(err)
}

fn status_service(node: &Node<ipc::Service>, names: &Names) -> Result<FixedService<Status>> {
    node.service_builder(&names.name("status")?)
        .publish_subscribe::<Status>()
        .subscriber_max_buffer_size(8)
        .history_size(1)
        .open_or_create()
        .map_err(err)
}

fn link_service(node: &Node<ipc::Service>, names: &Names) -> Result<FixedService<LinkStatus>> {
    node.service_builder(&names.name("link")?)
        .publish_subscribe::<LinkStatus>()
        .subscriber_max_buffer_size(8)
        .history_size(1)
        .open_or_create()
        .map_err(err)
}

/// A wave field as it goes on the wire: the header and the payload (the components' rows, then the
/// coverage's ranges if it has one).
pub fn encode_waves(f: &WaveField) -> (WaveHeader, Vec<f64>) {
    let flat = f.flat_header();
    let mut values: Vec<f64> = f.flat_rows().flatten().collect();
    let sectors = flat.ranges_m.map_or(vec![], |r| r.to_vec());
    values.extend_from_slice(&sectors);
    (WaveHeader::of(f.components.len(), sectors.len(), &flat), values)
}

/// A wave field decoded from the wire.
pub fn decode_waves(h: &WaveHeader, payload: &[f64]) -> std::result::Result<WaveField, String> {
    if h.schema_version != WAVES_SCHEMA_VERSION {
        return Err(format!(
            "wave field of schema version {} (this shipcast reads {WAVES_SCHEMA_VERSION})",
            h.schema_version
        ));
    }
    crate::shell::ipc::wire::check_wave_components(h.n_components as usize)?;
    let (n, sectors) = (h.n_components as usize, h.n_sectors as usize);
    if sectors > crate::waves::field::MAX_GIVEN_SECTORS {
        return Err(format!(
            "wave field: coverage in {sectors} sectors, more than {}",
            crate::waves::field::MAX_GIVEN_SECTORS
        ));
    }
    if payload.len() != 4 * n + sectors {
        return Err(format!(
            "wave field: {} values for {n} components (4 each) and {sectors} coverage sectors",
            payload.len(),
        ));
    }
    let ranges =
        crate::waves::field::coverage_from_sectors(&payload[4 * n..]).map_err(|e| format!("wave field: {e}"))?;
    let rows = payload[..4 * n].chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]);
    WaveField::from_flat(h.flat(ranges), rows).map_err(|e| format!("wave field: {e}"))
}

/// A radar scan from the wire, its header checked against its payload.
pub fn decode_elevation(h: &ElevationHeader, payload: &[f32]) -> std::result::Result<Scan, String> {
    if h.schema_version != SCHEMA_VERSION {
        return Err(format!(
            "elevation scan of schema version {} (this shipcast reads {SCHEMA_VERSION})",
            h.schema_version
        ));
    }
    if !(4..=MAX_GRID_CELLS).contains(&h.n_x) || !(4..=MAX_GRID_CELLS).contains(&h.n_y) {
        return Err(format!(
            "elevation scan of {} x {} cells: 4..={MAX_GRID_CELLS} along each axis",
            h.n_x, h.n_y
        ));
    }
    if payload.len() != (h.n_x * h.n_y) as usize {
        return Err(format!(
            "elevation scan: {} values for {} x {} cells",
            payload.len(),
            h.n_x,
            h.n_y
        ));
    }
    let numbers = [h.time_s, h.origin_east_m, h.origin_north_m, h.orientation_deg];
    if numbers.iter().any(|v| !v.is_finite())
        || !(h.spacing_x_m.is_finite() && h.spacing_x_m > 0.0 && h.spacing_y_m.is_finite() && h.spacing_y_m > 0.0)
    {
        return Err(format!(
            "elevation scan with time {} s, origin ({}, {}) m, spacing {} x {} m, orientation {} deg: finite, spacing positive",
            h.time_s, h.origin_east_m, h.origin_north_m, h.spacing_x_m, h.spacing_y_m, h.orientation_deg
        ));
    }
    Ok(Scan {
        grid: crate::waves::observe::Grid {
            x_m: (0..h.n_x).map(|i| i as f64 * h.spacing_x_m).collect(),
            y_m: (0..h.n_y).map(|i| i as f64 * h.spacing_y_m).collect(),
            time_s: h.time_s,
            values: payload.iter().map(|v| *v as f64).collect(),
        },
        frame: crate::waves::observe::GridFrame {
            origin_m: [h.origin_east_m, h.origin_north_m],
            orientation_rad: crate::waves::field::heading_from_compass_deg(h.orientation_deg),
        },
    })
}

/// The wire header and payload of a scan whose grid axes start at 0 (as [`decode_elevation`] gives
/// them), the inverse of it.
pub fn encode_elevation(scan: &Scan) -> (ElevationHeader, Vec<f32>) {
    let g = &scan.grid;
    let step = |v: &[f64]| if v.len() > 1 { v[1] - v[0] } else { 1.0 };
    let origin = scan.frame.to_earth(g.x_m[0], g.y_m[0]);
    (
        ElevationHeader {
            schema_version: SCHEMA_VERSION,
            n_x: g.x_m.len() as u32,
            n_y: g.y_m.len() as u32,
            reserved: 0,
            time_s: g.time_s,
            origin_east_m: origin[0],
            origin_north_m: origin[1],
            spacing_x_m: step(&g.x_m),
            spacing_y_m: step(&g.y_m),
            orientation_deg: (90.0 - scan.frame.orientation_rad.to_degrees()).rem_euclid(360.0),
        },
        g.values.iter().map(|v| *v as f32).collect(),
    )
}

/// What the input thread hands on: each input with the engine clock at its receipt (taken here, so
/// that the daemon's loop being busy does not make an input look late, or its source's clock step).
pub type Arrived = (Input, f64);

/// Spawns the daemon's input thread: each input is stamped with `clock` (the engine clock) as it is
/// received. It ends when `stop` is set or the channel closes.
pub fn spawn_input(
    names: Names,
    tx: tokio::sync::mpsc::Sender<Arrived>,
    clock: impl Fn() -> f64 + Send + 'static,
    stop: Arc<AtomicBool>,
    ready: std::sync::mpsc::Sender<Result<()>>,
) -> std::thread::JoinHandle<()> {
    std::thread::Builder::new()
        .name("shipcast-ipc-in".into())
        .spawn(move || {
            let ports = match InputPorts::open(&names) {
                Ok(s) => {
                    let _ = ready.send(Ok(()));
                    s
                }
                Err(e) => {
                    let _ = ready.send(Err(e));
                    return;
                }
            };
            let ws = match waitset() {
                Ok(w) => w,
                Err(e) => {
                    tracing::error!("input thread: waitset: {e}");
                    return;
                }
            };
            let (Ok(_g1), Ok(_g2), Ok(_g3), Ok(_g4), Ok(_g5)) = (
                ws.attach_notification(&ports.motion_l),
                ws.attach_notification(&ports.waves_l),
                ws.attach_notification(&ports.nav_l),
                ws.attach_notification(&ports.elev_l),
                ws.attach_interval(STOP_CHECK),
            ) else {
                tracing::error!("input thread: cannot attach to the waitset");
                return;
            };
            // whatever was there before we attached (history of the waves service)
            if !ports.drain(&tx, &clock) {
                return;
            }
            loop {
                if stop.load(Ordering::Relaxed) {
                    break;
                }
                let mut alive = true;
                let r = ws.wait_and_process_once(|_| {
                    alive = ports.drain(&tx, &clock);
                    CallbackProgression::Stop
                });
                if r.is_err() || !alive {
                    break;
                }
            }
        })
        .expect("spawning the input thread")
}

/// The input thread's subscribers and the listeners of their event services (the node kept alive
/// with them).
struct InputPorts {
    motion: Subscriber<ipc::Service, MotionSample, ()>,
    nav: Subscriber<ipc::Service, NavigationSample, ()>,
    waves: Subscriber<ipc::Service, [f64], WaveHeader>,
    elev: Subscriber<ipc::Service, [f32], ElevationHeader>,
    link: Subscriber<ipc::Service, LinkStatus, ()>,
    motion_l: Listener<ipc::Service>,
    nav_l: Listener<ipc::Service>,
    waves_l: Listener<ipc::Service>,
    elev_l: Listener<ipc::Service>,
    // last: dropped after the ports
    _node: Node<ipc::Service>,
}

impl InputPorts {
    fn open(names: &Names) -> Result<InputPorts> {
        let node = node()?;
        let motion = motion_service(&node, names)?
            .subscriber_builder()
            .buffer_size(BUFFER)
            .create()
            .map_err(err)?;
        let waves = waves_service(&node, names)?
            .subscriber_builder()
            .create()
            .map_err(err)?;
        let nav = navigation_service(&node, names)?
            .subscriber_builder()
            .buffer_size(BUFFER)
            .create()
            .map_err(err)?;
        let (_, motion_l) = event(&node, names, "motion")?;
        let (_, waves_l) = event(&node, names, "waves")?;
        let (_, nav_l) = event(&node, names, "navigation")?;
        let elev = elevation_service(&node, names)?
            .subscriber_builder()
            .create()
            .map_err(err)?;
        let (_, elev_l) = event(&node, names, "elevation")?;
        let link = link_service(&node, names)?.subscriber_builder().create().map_err(err)?;
        Ok(InputPorts {
            motion,
            nav,
            waves,
            elev,
            link,
            motion_l,
            nav_l,
            waves_l,
            elev_l,
            _node: node,
        })
    }

    /// Forwards everything received (decoded; what cannot be, as a rejection); false when the channel
    /// has closed.
    fn drain(&self, tx: &tokio::sync::mpsc::Sender<Arrived>, clock: &impl Fn() -> f64) -> bool {
        let _ = self.motion_l.try_wait(|_| {});
        let _ = self.waves_l.try_wait(|_| {});
        let _ = self.nav_l.try_wait(|_| {});
        let _ = self.elev_l.try_wait(|_| {});
        while let Ok(Some(s)) = self.elev.receive() {
            let msg = match decode_elevation(s.user_header(), s.payload()) {
                Ok(scan) => Input::Elevation(Box::new(scan)),
                Err(e) => Input::Rejected(e),
            };
            if tx.blocking_send((msg, clock())).is_err() {
                return false;
            }
        }
        while let Ok(Some(s)) = self.motion.receive() {
            if tx.blocking_send((Input::Motion(*s.payload()), clock())).is_err() {
                return false;
            }
        }
        while let Ok(Some(s)) = self.nav.receive() {
            if tx.blocking_send((Input::Navigation(*s.payload()), clock())).is_err() {
                return false;
            }
        }
        while let Ok(Some(s)) = self.waves.receive() {
            let msg = match decode_waves(s.user_header(), s.payload()) {
                Ok(f) => Input::Waves(f),
                Err(e) => Input::Rejected(e),
            };
            if tx.blocking_send((msg, clock())).is_err() {
                return false;
            }
        }
        // the link's health comes a second at a time: read at every wake (the interval's too)
        while let Ok(Some(s)) = self.link.receive() {
            if tx.blocking_send((Input::Link(*s.payload()), clock())).is_err() {
                return false;
            }
        }
        true
    }
}

/// Spawns the daemon's output thread; it ends when the channel closes (after publishing what is left).
pub fn spawn_output(
    names: Names,
    rx: std::sync::mpsc::Receiver<Output>,
    ready: std::sync::mpsc::Sender<Result<()>>,
) -> std::thread::JoinHandle<()> {
    std::thread::Builder::new()
        .name("shipcast-ipc-out".into())
        .spawn(move || {
            let p = match OutputPublisher::new(&names) {
                Ok(p) => {
                    let _ = ready.send(Ok(()));
                    p
                }
                Err(e) => {
                    let _ = ready.send(Err(e));
                    return;
                }
            };
            while let Ok(out) = rx.recv() {
                if let Err(e) = p.publish(&out) {
                    tracing::warn!("publishing failed: {e}");
                }
            }
        })
        .expect("spawning the output thread")
}

/// Publishers of forecasts and status: the daemon's output thread, and the link's for the other
/// ship's daemon (under its own prefix). Blocking.
pub struct OutputPublisher {
    _node: Node<ipc::Service>,
    fc: Publisher<ipc::Service, [f64], ForecastHeader>,
    st: Publisher<ipc::Service, Status, ()>,
    fc_n: Notifier<ipc::Service>,
    st_n: Notifier<ipc::Service>,
}

impl OutputPublisher {
    pub fn new(names: &Names) -> Result<OutputPublisher> {
        let node = node()?;
        let fc = forecast_service(&node, names)?
            .publisher_builder()
            .initial_max_slice_len(6 * MAX_VESSELS * 6001)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(err)?;
        let st = status_service(&node, names)?
            .publisher_builder()
            .create()
            .map_err(err)?;
        let (fc_n, _) = event(&node, names, "forecast")?;
        let (st_n, _) = event(&node, names, "status")?;
        Ok(OutputPublisher {
            _node: node,
            fc,
            st,
            fc_n,
            st_n,
        })
    }

    pub fn publish(&self, out: &Output) -> Result<()> {
        match out {
            Output::Forecast(h, values) => {
                let s = self.fc.loan_slice_uninit(values.len()).map_err(err)?;
                let mut s = s.write_from_slice(values);
                *s.user_header_mut() = *h;
                s.send().map_err(err)?;
                self.fc_n.notify().map_err(err)?;
            }
            Output::Status(status) => {
                let s = self.st.loan_uninit().map_err(err)?;
                s.write_payload(*status).send().map_err(err)?;
                self.st_n.notify().map_err(err)?;
            }
        }
        Ok(())
    }
}

/// The link's health publisher (`shipcast link`), on `<prefix>/link`.
pub struct LinkPublisher {
    _node: Node<ipc::Service>,
    link: Publisher<ipc::Service, LinkStatus, ()>,
}

impl LinkPublisher {
    pub fn new(names: &Names) -> Result<LinkPublisher> {
        let node = node()?;
        let link = link_service(&node, names)?.publisher_builder().create().map_err(err)?;
        Ok(LinkPublisher { _node: node, link })
    }

    pub fn publish(&self, s: &LinkStatus) -> Result<()> {
        self.link
            .loan_uninit()
            .map_err(err)?
            .write_payload(*s)
            .send()
            .map_err(err)?;
        Ok(())
    }
}

/// What the link sends of the local services: own vessels' motion and navigation, the daemon's
/// forecasts and status. A blocking subscriber.
pub struct LocalSubscriber {
    _node: Node<ipc::Service>,
    motion: Subscriber<ipc::Service, MotionSample, ()>,
    nav: Subscriber<ipc::Service, NavigationSample, ()>,
    forecast: Subscriber<ipc::Service, [f64], ForecastHeader>,
    status: Subscriber<ipc::Service, Status, ()>,
    listeners: Vec<Listener<ipc::Service>>,
    ws: WaitSet<ipc::Service>,
}

/// One local message for the link.
#[derive(Debug, Clone)]
#[allow(clippy::large_enum_variant)]
pub enum Local {
    Motion(MotionSample),
    Navigation(NavigationSample),
    Output(Output),
}

impl LocalSubscriber {
    pub fn new(names: &Names) -> Result<LocalSubscriber> {
        let node = node()?;
        let motion = motion_service(&node, names)?
            .subscriber_builder()
            .buffer_size(BUFFER)
            .create()
            .map_err(err)?;
        let nav = navigation_service(&node, names)?
            .subscriber_builder()
            .buffer_size(BUFFER)
            .create()
            .map_err(err)?;
        let forecast = forecast_service(&node, names)?
            .subscriber_builder()
            .create()
            .map_err(err)?;
        let status = status_service(&node, names)?
            .subscriber_builder()
            .create()
            .map_err(err)?;
        let mut listeners = vec![];
        for kind in ["motion", "navigation", "forecast", "status"] {
            listeners.push(event(&node, names, kind)?.1);
        }
        Ok(LocalSubscriber {
            _node: node,
            motion,
            nav,
            forecast,
            status,
            listeners,
            ws: waitset()?,
        })
    }

    /// Waits up to `timeout` for a notification, then everything received; what does not fit its
    /// header is skipped (the link sends nothing a local subscriber would refuse).
    pub fn wait(&self, timeout: Duration, out: &mut Vec<Local>) -> Result<()> {
        let mut guards = vec![];
        for l in &self.listeners {
            guards.push(self.ws.attach_notification(l).map_err(err)?);
        }
        let _ = self
            .ws
            .wait_and_process_once_with_timeout(|_| CallbackProgression::Stop, timeout)
            .map_err(err)?;
        drop(guards);
        for l in &self.listeners {
            let _ = l.try_wait(|_| {});
        }
        while let Some(s) = self.motion.receive().map_err(err)? {
            out.push(Local::Motion(*s.payload()));
        }
        while let Some(s) = self.nav.receive().map_err(err)? {
            out.push(Local::Navigation(*s.payload()));
        }
        while let Some(s) = self.forecast.receive().map_err(err)? {
            if check_forecast(s.user_header(), s.payload().len()).is_ok() {
                out.push(Local::Output(Output::Forecast(*s.user_header(), s.payload().to_vec())));
            }
        }
        while let Some(s) = self.status.receive().map_err(err)? {
            if check_status(s.payload()).is_ok() {
                out.push(Local::Output(Output::Status(*s.payload())));
            }
        }
        Ok(())
    }
}

/// Publishers of a sensor suite (the simulator, or a bridge from real sensors): blocking.
pub struct SensorPublisher {
    _node: Node<ipc::Service>,
    motion: Publisher<ipc::Service, MotionSample, ()>,
    nav: Publisher<ipc::Service, NavigationSample, ()>,
    nav_n: Notifier<ipc::Service>,
    elev: Publisher<ipc::Service, [f32], ElevationHeader>,
    elev_n: Notifier<ipc::Service>,
    waves: Publisher<ipc::Service, [f64], WaveHeader>,
    motion_n: Notifier<ipc::Service>,
    waves_n: Notifier<ipc::Service>,
}

impl SensorPublisher {
    pub fn new(names: &Names) -> Result<SensorPublisher> {
        let node = node()?;
        let motion = motion_service(&node, names)?
            .publisher_builder()
            .create()
            .map_err(err)?;
        let waves = waves_service(&node, names)?
            .publisher_builder()
            .initial_max_slice_len(4 * 4096)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(err)?;
        let nav = navigation_service(&node, names)?
            .publisher_builder()
            .create()
            .map_err(err)?;
        let (motion_n, _) = event(&node, names, "motion")?;
        let (waves_n, _) = event(&node, names, "waves")?;
        let (nav_n, _) = event(&node, names, "navigation")?;
        let elev = elevation_service(&node, names)?
            .publisher_builder()
            .initial_max_slice_len(128 * 128)
            .allocation_strategy(AllocationStrategy::PowerOfTwo)
            .create()
            .map_err(err)?;
        let (elev_n, _) = event(&node, names, "elevation")?;
        Ok(SensorPublisher {
            _node: node,
            motion,
            nav,
            nav_n,
            elev,
            elev_n,
            waves,
            motion_n,
            waves_n,
        })
    }

    pub fn motion(&self, s: &MotionSample) -> Result<()> {
        self.motion
            .loan_uninit()
            .map_err(err)?
            .write_payload(*s)
            .send()
            .map_err(err)?;
        self.motion_n.notify().map_err(err)?;
        Ok(())
    }

    pub fn navigation(&self, s: &NavigationSample) -> Result<()> {
        self.nav
            .loan_uninit()
            .map_err(err)?
            .write_payload(*s)
            .send()
            .map_err(err)?;
        self.nav_n.notify().map_err(err)?;
        Ok(())
    }

    pub fn elevation(&self, scan: &Scan) -> Result<()> {
        let (h, values) = encode_elevation(scan);
        let s = self.elev.loan_slice_uninit(values.len()).map_err(err)?;
        let mut s = s.write_from_slice(&values);
        *s.user_header_mut() = h;
        s.send().map_err(err)?;
        self.elev_n.notify().map_err(err)?;
        Ok(())
    }

    pub fn waves(&self, f: &WaveField) -> Result<()> {
        let (h, values) = encode_waves(f);
        let s = self.waves.loan_slice_uninit(values.len()).map_err(err)?;
        let mut s = s.write_from_slice(&values);
        *s.user_header_mut() = h;
        s.send().map_err(err)?;
        self.waves_n.notify().map_err(err)?;
        Ok(())
    }
}

/// What a forecast subscriber receives.
#[derive(Debug, Clone)]
// one status a period: a box would be an allocation for nothing
#[allow(clippy::large_enum_variant)]
pub enum Received {
    Forecast(ForecastHeader, Vec<f64>),
    Status(Status),
}

/// A blocking subscriber of forecasts and status (`shipcast watch`, consoles, tests).
pub struct ForecastSubscriber {
    refused: std::cell::Cell<u64>,
    _node: Node<ipc::Service>,
    forecast: Subscriber<ipc::Service, [f64], ForecastHeader>,
    status: Subscriber<ipc::Service, Status, ()>,
    fc_l: Listener<ipc::Service>,
    st_l: Listener<ipc::Service>,
    ws: WaitSet<ipc::Service>,
}

impl ForecastSubscriber {
    pub fn new(names: &Names) -> Result<ForecastSubscriber> {
        let node = node()?;
        let forecast = forecast_service(&node, names)?
            .subscriber_builder()
            .create()
            .map_err(err)?;
        let status = status_service(&node, names)?
            .subscriber_builder()
            .create()
            .map_err(err)?;
        let (_, fc_l) = event(&node, names, "forecast")?;
        let (_, st_l) = event(&node, names, "status")?;
        Ok(ForecastSubscriber {
            _node: node,
            forecast,
            status,
            refused: std::cell::Cell::new(0),
            fc_l,
            st_l,
            ws: waitset()?,
        })
    }

    /// Payloads refused so far (their header does not fit their data, or an unknown schema).
    pub fn refused(&self) -> u64 {
        self.refused.get()
    }

    fn refuse(&self, why: String) {
        let n = self.refused.get() + 1;
        self.refused.set(n);
        if n == 1 || n.is_power_of_two() {
            tracing::warn!(refused = n, "{why}: skipped");
        }
    }

    /// Everything received so far, without waiting; a payload whose header does not fit its data
    /// ([`check_forecast`], [`check_status`]) is skipped and counted ([`Self::refused`]).
    pub fn drain(&self, out: &mut Vec<Received>) -> Result<()> {
        let _ = self.fc_l.try_wait(|_| {});
        let _ = self.st_l.try_wait(|_| {});
        while let Some(s) = self.status.receive().map_err(err)? {
            match check_status(s.payload()) {
                Ok(()) => out.push(Received::Status(*s.payload())),
                Err(e) => self.refuse(e),
            }
        }
        while let Some(s) = self.forecast.receive().map_err(err)? {
            match check_forecast(s.user_header(), s.payload().len()) {
                Ok(()) => out.push(Received::Forecast(*s.user_header(), s.payload().to_vec())),
                Err(e) => self.refuse(e),
            }
        }
        Ok(())
    }

    /// Waits up to `timeout` for the next notification, then drains.
    pub fn wait(&self, timeout: Duration, out: &mut Vec<Received>) -> Result<()> {
        let g1 = self.ws.attach_notification(&self.fc_l).map_err(err)?;
        let g2 = self.ws.attach_notification(&self.st_l).map_err(err)?;
        let _ = self
            .ws
            .wait_and_process_once_with_timeout(|_| CallbackProgression::Stop, timeout)
            .map_err(err)?;
        drop((g1, g2));
        self.drain(out)
    }
}

/// A subscriber of the motion stream (the demo's live skill, consoles drawing the measured past).
pub struct MotionSubscriber {
    _node: Node<ipc::Service>,
    motion: Subscriber<ipc::Service, MotionSample, ()>,
}

impl MotionSubscriber {
    pub fn new(names: &Names) -> Result<MotionSubscriber> {
        let node = node()?;
        let motion = motion_service(&node, names)?
            .subscriber_builder()
            .buffer_size(BUFFER)
            .create()
            .map_err(err)?;
        Ok(MotionSubscriber { _node: node, motion })
    }

    /// Every sample received so far.
    pub fn drain(&self, out: &mut Vec<MotionSample>) -> Result<()> {
        while let Some(s) = self.motion.receive().map_err(err)? {
            out.push(*s.payload());
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::waves::observe::{Grid, GridFrame};

    fn scan() -> Scan {
        Scan {
            grid: Grid {
                x_m: (0..6).map(|i| 10.0 * i as f64).collect(),
                y_m: (0..5).map(|i| 12.0 * i as f64).collect(),
                time_s: 1.75e9 + 0.25,
                values: (0..30)
                    .map(|i| if i == 7 { f64::NAN } else { 0.1 * i as f64 })
                    .collect(),
            },
            frame: GridFrame {
                origin_m: [100.0, -40.0],
                orientation_rad: 0.3,
            },
        }
    }

    #[test]
    fn a_scan_goes_over_the_wire_and_into_a_log_and_back() {
        let s = scan();
        let (h, v) = encode_elevation(&s);
        let back = decode_elevation(&h, &v).unwrap();
        assert_eq!(back.grid.x_m, s.grid.x_m);
        assert!((back.frame.orientation_rad - 0.3).abs() < 1e-12);
        assert!(back.grid.values[7].is_nan() && (back.grid.values[8] - 0.8).abs() < 1e-6);
        let rec = crate::shell::record::GridRecord::of_scan(&s).scan().unwrap();
        assert!((rec.frame.origin_m[0] - 100.0).abs() < 1e-9 && (rec.frame.origin_m[1] + 40.0).abs() < 1e-9);
        assert!((rec.frame.orientation_rad - 0.3).abs() < 1e-12);
        assert_eq!(rec.grid.y_m, s.grid.y_m);
        assert!((rec.grid.time_s - s.grid.time_s).abs() < 1e-6);
    }

    fn covered_field() -> WaveField {
        WaveField {
            components: vec![crate::waves::field::FieldComponent {
                omega_rad_s: 0.7,
                direction_rad: 1.0,
                amplitude_m: num_complex::Complex64::new(0.4, -0.3),
            }],
            reference_m: [50.0, 20.0],
            time_s: 1.75e9,
            g_m_s2: 9.81,
            depth_m: None,
            region: crate::waves::field::Region::Coverage {
                centre_m: [50.0, 20.0],
                inner_m: 200.0,
                ranges_m: std::array::from_fn(|j| if j < 10 { 0.0 } else { 990.0 }),
                window_s: 30.0,
            },
        }
    }

    #[test]
    fn a_radar_field_goes_over_the_wire_and_into_a_log_and_back_with_what_it_saw() {
        let f = covered_field();
        let (h, v) = encode_waves(&f);
        assert_eq!((h.n_components, h.n_sectors, v.len()), (1, 72, 4 + 72));
        assert_eq!(decode_waves(&h, &v).unwrap(), f);
        assert_eq!(crate::shell::record::WavesRecord::of(&f).field().unwrap(), f);
        // a field without a coverage sends none
        let disc = WaveField {
            region: crate::waves::field::Region::Disc {
                centre_m: [50.0, 20.0],
                radius_m: 800.0,
            },
            ..f.clone()
        };
        let (h, v) = encode_waves(&disc);
        assert_eq!((h.n_sectors, v.len()), (0, 4));
        assert_eq!(decode_waves(&h, &v).unwrap(), disc);
        // a processor's coverage in 360 sectors of 1 deg
        let (h, mut v) = encode_waves(&disc);
        v.extend((0..360).map(|i| if i < 50 { 0.0 } else { 990.0 }));
        let back = decode_waves(
            &WaveHeader {
                n_sectors: 360,
                inner_m: 200.0,
                window_s: 30.0,
                ..h
            },
            &v,
        )
        .unwrap();
        assert_eq!(back, f);
    }

    #[test]
    fn a_wave_field_whose_header_does_not_fit_its_payload_is_refused() {
        let (h, v) = encode_waves(&covered_field());
        let bad = [
            (WaveHeader { n_sectors: 71, ..h }, "76 values"),
            (WaveHeader { n_sectors: 5000, ..h }, "5000 sectors"),
            (WaveHeader { schema_version: 1, ..h }, "schema version 1"),
            (WaveHeader { inner_m: f64::NAN, ..h }, "blind zone"),
        ];
        for (b, says) in bad {
            let err = decode_waves(&b, &v).unwrap_err();
            assert!(err.contains(says), "{err}");
        }
        let mut v = v;
        v[4 + 3] = -5.0;
        assert!(decode_waves(&h, &v).unwrap_err().contains("coverage sector 3"));
    }

    #[test]
    fn a_scan_whose_header_does_not_fit_its_payload_is_refused() {
        let (h, v) = encode_elevation(&scan());
        assert!(decode_elevation(&h, &v[..29]).unwrap_err().contains("29 values"));
        let bad = [
            ElevationHeader { n_x: 2, ..h },
            ElevationHeader { n_x: 5000, ..h },
            ElevationHeader { spacing_x_m: 0.0, ..h },
            ElevationHeader { time_s: f64::NAN, ..h },
            ElevationHeader { schema_version: 9, ..h },
        ];
        for b in bad {
            assert!(decode_elevation(&b, &v).is_err(), "{b:?}");
        }
    }
}
