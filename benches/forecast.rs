//! One 300 s forecast of the one-ship demo (6 DOF) and the two-ship demo (12 DOF, full 12x12 coupling,
//! every DOF active), both radiation methods, 240 wave components in a short-crested JONSWAP sea
//! (config/scenarios/two-ship.toml's sea), after a 600 s simulated history; and one integrator step.
//! The two-ship state-space forecast also underway: 3 m/s and turning at 0.2 deg/s from t0 (the wave
//! force in pieces of 2 deg of heading). The band of the two-ship forecast (`band`: every
//! component's response variance and the leads it is known over, as the daemon adds it to each
//! forecast), against the forecast it goes with. Setup (loading, fitting, the spin-up, the response
//! table) is outside the timing.

use criterion::{Criterion, criterion_group, criterion_main};
use shipcast::band::{ModelErrorCurve, ResponseTable, SpreadOptions, spread};
use shipcast::rom::stepper::Stepper;
use shipcast::rom::{ForecastRequest, Forecaster, RadiationMethod, RomOptions, TimeModel, Track};
use shipcast::shell::files::load_system;
use shipcast::shell::scenario::{Prepared, Scenario, past_options, prepare};
use std::hint::black_box;
use std::path::Path;

fn benches(c: &mut Criterion) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let sc = Scenario::load(&root.join("config/scenarios/two-ship.toml")).expect("scenario");
    let mut g = c.benchmark_group("forecast_300s_240_components");
    g.sample_size(20);
    for (name, system) in [
        ("one_ship_6dof", "config/vessels/ship/system.toml"),
        ("two_ship_12dof", "config/vessels/pair/system.toml"),
    ] {
        let sys = load_system(&root.join(system)).expect("demo database").system;
        for (mname, method) in [
            ("convolution", RadiationMethod::Convolution),
            ("state_space", RadiationMethod::StateSpace),
        ] {
            let model = TimeModel::new(
                &sys,
                RomOptions {
                    radiation: method,
                    ..sc.opts
                },
            )
            .expect("model");
            let past = TimeModel::new(&sys, past_options(model.opts)).expect("past model");
            let prep = prepare(&past, &model, &sc.waves, sc.history_s).expect("spin-up");
            let mut fc = Forecaster::new();
            let req = prep.request(300.0);
            g.bench_function(format!("{name}_{mname}"), |b| {
                b.iter(|| fc.forecast(&model, black_box(&req)).map(|f| f.steps).unwrap())
            });
            if name == "two_ship_12dof" && method == RadiationMethod::StateSpace {
                // the band: known for the first 60 s of each component (a radar's horizon)
                let table = ResponseTable::of(&model).expect("response table");
                let known = vec![vec![[0.0, 60.0]; req.waves.len()]; 2];
                let opts = SpreadOptions {
                    model_error: ModelErrorCurve {
                        checked_to_s: f64::INFINITY,
                        ..ModelErrorCurve::prior(0.15, 12)
                    },
                    trusted_nrmse: 0.6,
                    start_var: vec![],
                    start_offset: vec![],
                    coupled_var: vec![],
                };
                let steps = (300.0 / model.opts.dt_s).round() as usize;
                g.bench_function(format!("{name}_band"), |b| {
                    b.iter(|| {
                        spread(
                            &table,
                            black_box(req.waves),
                            &known,
                            2,
                            0.0,
                            model.g_m_s2,
                            model.water_depth_m,
                            steps,
                            model.opts.dt_s,
                            &opts,
                        )
                        .to_s[0]
                    })
                });
                let turning = ForecastRequest {
                    track: Some(Track {
                        turn_rate_rad_s: 0.2f64.to_radians(),
                        ..Track::straight(3.0)
                    }),
                    ..req
                };
                g.bench_function(format!("{name}_{mname}_turning_3m_s"), |b| {
                    b.iter(|| fc.forecast(&model, black_box(&turning)).map(|f| f.steps).unwrap())
                });
            }
            if name == "two_ship_12dof" {
                // one step of the integrator (state space), from the prepared state
                let mut st = Stepper::new();
                let n = model.n();
                let zeros = vec![0.0; n];
                let f = vec![0.0; n];
                st.start(&model, &prep.x0, &prep.v0, &prep.memory, 1_000_000, &zeros)
                    .unwrap();
                if method == RadiationMethod::StateSpace {
                    c_step(&mut g, &model, &mut st, &prep, &f, &zeros);
                }
            }
        }
    }
    g.finish();
}

fn c_step(
    g: &mut criterion::BenchmarkGroup<criterion::measurement::WallTime>,
    model: &TimeModel,
    st: &mut Stepper,
    prep: &Prepared,
    f: &[f64],
    zeros: &[f64],
) {
    g.bench_function("two_ship_12dof_one_step_state_space", |b| {
        b.iter(|| {
            // back to the prepared state now and then: the modes without restoring drift, and a long
            // enough run (4e4 s: 4e5 steps) leaves the bound on displacements
            if st.k + 1 >= 100_000 {
                st.start(model, &prep.x0, &prep.v0, &prep.memory, 1_000_000, zeros)
                    .unwrap();
            }
            st.step(model, black_box(f), zeros).unwrap()
        })
    });
}

criterion_group!(forecast, benches);
criterion_main!(forecast);
