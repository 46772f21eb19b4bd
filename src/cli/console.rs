//! `shipcast console`: the operator's terminal view (shell). The subscriptions run on their own
//! thread (iceoryx2 ports stay where they were made) and forward copies; the terminal loop applies
//! them to [`shipcast::console::Console`], draws, and maps keys. Logs are not written here: they
//! would tear the screen (the daemon's journal has them).

use anyhow::{Context, Result};
use clap::Args;
use shipcast::console::{Action, Console, Forecast, Health, Key, Settings};
use shipcast::shell::ipc::wire::{SCHEMA_VERSION, flags};
use shipcast::shell::ipc::{ForecastSubscriber, MotionSubscriber, Names, Received};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::time::{Duration, Instant, SystemTime, UNIX_EPOCH};

#[derive(Args, Debug)]
pub struct ConsoleArgs {
    #[command(flatten)]
    config: super::ConfigArg,
    /// Service prefix to subscribe under (default: the config's `ipc.service_prefix`; a replay
    /// publishes under `<prefix>-replay`).
    #[arg(long)]
    prefix: Option<String>,
    /// Quit after this many seconds (scripted captures; default: until q).
    #[arg(long, allow_negative_numbers = true)]
    seconds: Option<f64>,
}

/// What the subscription thread forwards.
enum Event {
    Motion(usize, f64, [f64; 6]),
    Forecast(Forecast),
    Health(Health),
}

fn wall_s() -> f64 {
    SystemTime::now()
        .duration_since(UNIX_EPOCH)
        .map_or(0.0, |d| d.as_secs_f64())
}

/// Silence after which the subscriptions are made anew (a daemon that crashed left its ports).
const RECONNECT_AFTER: Duration = Duration::from_secs(10);

fn subscribe(names: Names, n_vessels: usize, tx: mpsc::Sender<Event>, stop: Arc<AtomicBool>) {
    while !stop.load(Ordering::Relaxed) {
        let subs = ForecastSubscriber::new(&names).and_then(|f| Ok((f, MotionSubscriber::new(&names)?)));
        let (fs, ms) = match subs {
            Ok(s) => s,
            Err(_) => {
                std::thread::sleep(Duration::from_secs(1));
                continue;
            }
        };
        let mut last = Instant::now();
        let (mut got, mut motion) = (vec![], vec![]);
        while !stop.load(Ordering::Relaxed) && last.elapsed() < RECONNECT_AFTER {
            got.clear();
            motion.clear();
            if fs.wait(Duration::from_millis(100), &mut got).is_err() || ms.drain(&mut motion).is_err() {
                break;
            }
            let now = wall_s();
            for m in &motion {
                if m.schema_version == SCHEMA_VERSION && (m.vessel as usize) < n_vessels {
                    let _ = tx.send(Event::Motion(m.vessel as usize, m.time_s, m.x));
                }
            }
            for r in got.drain(..) {
                last = Instant::now();
                let ev = match r {
                    Received::Forecast(h, v) => {
                        let n = h.steps as usize + 1;
                        let nv = (h.n_vessels as usize).min(n_vessels);
                        if h.schema_version != shipcast::shell::ipc::wire::FORECAST_SCHEMA_VERSION
                            || v.len() < 2 * 6 * nv * n
                        {
                            continue;
                        }
                        Event::Forecast(Forecast {
                            issue_time_s: h.issue_time_s,
                            dt_s: h.dt_s,
                            horizon_s: h.horizon_s[..nv].to_vec(),
                            trusted_from_s: h.trusted_from_s[..nv].to_vec(),
                            series_span_s: (0..6 * nv).map(|i| [h.series_span(i).0, h.series_span(i).1]).collect(),
                            flags: flags::names(h.flags),
                            compute_ms: h.compute_ms,
                            x: v.chunks_exact(n).take(6 * nv).map(|s| s.to_vec()).collect(),
                            // the band after all the daemon's series (it may have more vessels)
                            sigma: v[h.n_series as usize * n..]
                                .chunks_exact(n)
                                .take(6 * nv)
                                .map(|s| s.to_vec())
                                .collect(),
                            received_wall_s: now,
                        })
                    }
                    Received::Status(s) => {
                        if s.schema_version != shipcast::shell::ipc::wire::STATUS_SCHEMA_VERSION {
                            continue;
                        }
                        let nv = n_vessels.min(s.motion_age_s.len());
                        Event::Health(Health {
                            flags: flags::names(s.flags),
                            wave_age_s: s.wave_age_s,
                            motion_age_s: s.motion_age_s[..nv].to_vec(),
                            motion_rate_hz: s.motion_rate_hz[..nv].to_vec(),
                            last_compute_ms: s.last_compute_ms,
                            latency_p50_ms: s.latency_p50_ms,
                            latency_p99_ms: s.latency_p99_ms,
                            overruns: s.overruns,
                            running: s.running != 0,
                            received_wall_s: now,
                            link: (s.link_state != shipcast::shell::ipc::wire::link_state::NONE).then_some(
                                shipcast::console::LinkHealth {
                                    up: s.link_state == shipcast::shell::ipc::wire::link_state::UP,
                                    latency_ms: s.link_latency_ms,
                                    loss: s.link_loss,
                                    age_s: s.link_age_s,
                                },
                            ),
                        })
                    }
                };
                if tx.send(ev).is_err() {
                    return;
                }
            }
        }
    }
}

pub fn run(a: &ConsoleArgs) -> Result<()> {
    let cfg = super::load_config(&a.config)?;
    let sys = super::load_system(&cfg)?;
    view(&cfg, &sys, a.prefix.clone(), a.seconds)
}

/// The console on a loaded config and system (also what `shipcast demo` opens in a terminal).
pub fn view(
    cfg: &shipcast::shell::config::ShipcastConfig,
    sys: &shipcast::hydro::VesselSystem,
    prefix: Option<String>,
    seconds: Option<f64>,
) -> Result<()> {
    use ratatui::crossterm::event::{self, KeyCode, KeyEventKind, KeyModifiers};
    let vessels: Vec<String> = sys.spec.bodies.iter().map(|b| b.name.clone()).collect();
    let ext = sys.spec.external.clone();
    let channels = cfg.operation_channels(&vessels, &ext, &cfg.path)?;
    let colours = cfg
        .console
        .colours
        .parse()
        .map_err(|(k, m)| anyhow::anyhow!("{}: {k}: {m}", cfg.path.display()))?;
    let settings = Settings {
        channels,
        duration_s: cfg.operation.duration_s,
        history_s: cfg.console.history_s,
        period_s: cfg.forecast.period_s,
        history_wanted_s: shipcast::engine::history_wanted_s(cfg, sys),
        confidence: cfg.operation.confidence,
        colours,
    };
    let mut console = Console::new(settings, vessels.clone(), ext);
    let (tx, rx) = mpsc::channel();
    let stop = Arc::new(AtomicBool::new(false));
    let names = Names {
        prefix: prefix.unwrap_or_else(|| cfg.ipc.service_prefix.clone()),
    };
    let thread = {
        let stop = stop.clone();
        let n = vessels.len().min(shipcast::shell::ipc::wire::MAX_VESSELS);
        std::thread::Builder::new()
            .name("console-subscriptions".into())
            .spawn(move || subscribe(names, n, tx, stop))
            .context("starting the subscription thread")?
    };
    let mut terminal = ratatui::try_init().context("opening the terminal")?;
    let started = Instant::now();
    // redraw often enough that a silent daemon is said within two periods (STALE_PERIODS + this)
    let redraw = Duration::from_secs_f64((cfg.forecast.period_s / 5.0).clamp(0.05, 0.25));
    let result = (|| -> Result<()> {
        loop {
            while let Ok(ev) = rx.try_recv() {
                match ev {
                    Event::Motion(v, t, x) => console.on_motion(v, t, &x),
                    Event::Forecast(f) => console.on_forecast(f),
                    Event::Health(h) => console.on_health(h),
                }
            }
            let now = wall_s();
            terminal.draw(|f| shipcast::console::draw(f, &console, now))?;
            if seconds.is_some_and(|s| started.elapsed().as_secs_f64() > s) {
                return Ok(());
            }
            if event::poll(redraw)? {
                let ev = event::read()?;
                let event::Event::Key(k) = ev else { continue };
                if k.kind != KeyEventKind::Press {
                    continue;
                }
                let key = match k.code {
                    KeyCode::Char('c') if k.modifiers.contains(KeyModifiers::CONTROL) => return Ok(()),
                    KeyCode::Char(c) => Key::Char(c),
                    KeyCode::Up => Key::Up,
                    KeyCode::Down => Key::Down,
                    KeyCode::Esc => Key::Esc,
                    _ => continue,
                };
                if console.key(key) == Action::Quit {
                    return Ok(());
                }
            }
        }
    })();
    ratatui::restore();
    stop.store(true, Ordering::Relaxed);
    let _ = thread.join();
    result
}
