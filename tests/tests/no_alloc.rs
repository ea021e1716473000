//! After start-up, neither the step functions nor the process loops allocate.
//! A counting global allocator counts the allocations made by this thread while enabled.

use std::alloc::{GlobalAlloc, Layout, System};
use std::cell::Cell;
use std::sync::atomic::{AtomicU64, Ordering};

use controller::Controller;
use controller::shell::ControllerComponent;
use launcher::plan::plan;
use launcher::run::configs;
use lockstep::component::{Component, Runner};
use lockstep::{Bus, RunSpace, Wait};
use observer::shell::ObserverComponent;
use plant::Plant;
use plant::shell::PlantComponent;
use scenario::Scenario;
use tests::*;

struct Counting;

static ALLOCATIONS: AtomicU64 = AtomicU64::new(0);
thread_local! {
    static TRACKING: Cell<bool> = const { Cell::new(false) };
}

// SAFETY: defers to the system allocator; counting touches only an atomic and a const TLS cell.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        if TRACKING.with(|t| t.get()) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        if TRACKING.with(|t| t.get()) {
            ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        }
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// Allocations made by `f` on this thread.
fn allocations(f: impl FnOnce()) -> u64 {
    let before = ALLOCATIONS.load(Ordering::Relaxed);
    TRACKING.with(|t| t.set(true));
    f();
    TRACKING.with(|t| t.set(false));
    ALLOCATIONS.load(Ordering::Relaxed) - before
}

#[test]
fn counting_allocator_counts() {
    assert_eq!(allocations(|| drop(vec![1u8; 16])), 1);
}

fn shipped() -> Vec<Scenario> {
    let mut v: Vec<_> = std::fs::read_dir(repo().join("scenarios"))
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    v.sort();
    // Our own step functions: scenarios whose components are all built in.
    v.iter()
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| Scenario::load(p).unwrap())
        .filter(|s| {
            s.plant_process.is_none()
                && s.observers.iter().all(|o| o.process.is_none())
                && s.controller.as_ref().is_none_or(|c| c.process.is_none())
        })
        .collect()
}

/// The benchmark's random plant with 120 states, 120 outputs, a UIO and a Luenberger observer.
fn large() -> Scenario {
    Scenario::parse(
        std::path::Path::new("states-120.toml"),
        &launcher::bench::states::scenario_text(120, 400),
    )
    .unwrap()
}

#[test]
fn step_functions_do_not_allocate() {
    let mut scenarios = shipped();
    // A disturbance switching between samples makes the plant take its split-step path.
    let mut split = Scenario::load(&scenario("seed002-piecewise")).unwrap();
    split.disturbances[0] = lti::signal::Signal::Piecewise {
        times: vec![0.0, 0.00105, 0.0023],
        values: vec![1.0, -1.0, 2.0],
    };
    scenarios.push(split);
    // A large model: samples of hundreds of values, the double-precision exponential.
    scenarios.push(large());
    for s in scenarios {
        let Ok(p) = plan(&s) else {
            panic!("{} does not design", s.name)
        };
        let cfg = configs(&s, &p);
        let mut plant = Plant::new(&cfg.plant).unwrap();
        let mut observers: Vec<_> = cfg
            .observers
            .iter()
            .map(|(_, o)| o.as_ref().unwrap().instantiate())
            .collect();
        let mut controller = cfg.controller.as_ref().map(|c| Controller::new(c).unwrap());
        let c_obs = cfg
            .controller
            .as_ref()
            .and_then(|c| cfg.observers.iter().position(|(n, _)| *n == c.observer))
            .unwrap_or(0);
        let lay = cfg.layout;
        let (mut row, mut xhat, mut u) = (
            vec![0.0; lay.len()],
            vec![vec![0.0; lay.n]; observers.len()],
            vec![0.0; lay.l],
        );
        let steps = s.steps.min(5000);
        // A diverging run (the printed gain) stops at its first error, whose message allocates.
        let mut stopped = false;
        let mut step = |k: u64| {
            if stopped {
                return;
            }
            row.copy_from_slice(plant.sample(k));
            for (i, o) in observers.iter_mut().enumerate() {
                xhat[i].copy_from_slice(o.step(&row[lay.y()], &row[lay.u_prev()]));
            }
            match &mut controller {
                Some(c) => u.copy_from_slice(c.step(k, &xhat[c_obs], &row)),
                None => u.copy_from_slice(plant.reference()),
            }
            stopped = plant.advance(k, &u).is_err();
        };
        for k in 0..10 {
            step(k);
        }
        let n = allocations(|| (10..steps).for_each(&mut step));
        assert_eq!(n, 0, "{}: {n} allocations in {} steps", s.name, steps - 10);
    }
}

#[test]
fn process_loops_do_not_allocate() {
    let scratch = Scratch::new("no-alloc");
    // SAFETY: set before any run space is created; this test binary's other tests make none.
    unsafe { std::env::set_var(lockstep::RUNS_DIR_ENV, scratch.runs()) };
    for s in [Scenario::load(&scenario("seed002-sine")).unwrap(), large()] {
        process_loop(&s);
    }
}

fn process_loop(s: &Scenario) {
    let cfg = configs(s, &plan(s).unwrap());
    /// Removes the run's files even when an assertion fails.
    struct Cleanup(RunSpace);
    impl Drop for Cleanup {
        fn drop(&mut self) {
            self.0.remove();
        }
    }
    let space = Cleanup(RunSpace::create().unwrap());
    let space = &space.0;
    {
        let components = launcher::run::envelopes(s, &cfg, space, Wait::Yield);
        let bus =
            |c: &launcher::run::Launchable| Bus::join(space, &c.config.name, Wait::Yield).unwrap();
        let (plant_bus, ctrl_bus) = (bus(&components[0]), bus(components.last().unwrap()));
        let obs_buses: Vec<Bus> = components[1..components.len() - 1]
            .iter()
            .map(bus)
            .collect();
        let mut plant = Runner::new(
            &components[0].config,
            &plant_bus,
            PlantComponent::new(&components[0].config).unwrap(),
        )
        .unwrap();
        let mut observers: Vec<Runner<ObserverComponent>> = components[1..components.len() - 1]
            .iter()
            .zip(&obs_buses)
            .map(|(c, b)| {
                Runner::new(&c.config, b, ObserverComponent::new(&c.config).unwrap()).unwrap()
            })
            .collect();
        let c = components.last().unwrap();
        let mut controller = Runner::new(
            &c.config,
            &ctrl_bus,
            ControllerComponent::new(&c.config).unwrap(),
        )
        .unwrap();
        // Every component steps in lockstep order; each wait finds its sample already there.
        let mut step = |k: u64| {
            plant.step(k).unwrap();
            for o in observers.iter_mut() {
                o.step(k).unwrap();
            }
            controller.step(k).unwrap();
        };
        for k in 0..100 {
            step(k);
        }
        let end = s.steps.min(5000);
        let n = allocations(|| (100..end).for_each(&mut step));
        assert_eq!(
            n,
            0,
            "{}: {n} allocations in {} steps of the process loops",
            s.name,
            end - 100
        );
    }
}

/// The recording writer allocates nothing per step. Between two sends of a group, a
/// row and its values go into buffers sized for a whole batch (`FLUSH_STEPS` rows).
#[test]
fn the_recording_writer_allocates_nothing_between_sends() {
    use recording::write::{FLUSH_STEPS, RrdSink, blueprint};
    let s = Scenario::load(&scenario("seed002-sine")).unwrap();
    let dir = Scratch::new("noalloc-writer");
    let shown = s.clone();
    let mut sink = RrdSink::create(
        &dir.join("r.rrd"),
        "r",
        move |l| blueprint(&shown, l),
        &s.source,
        Default::default(),
    )
    .unwrap();
    let (g, late) = (sink.group("signals"), sink.group("late"));
    let ids: Vec<_> = [
        "/plant/x/1",
        "/plant/y/1",
        "/observer/a/xhat/1",
        "/observer/a/error/1",
        "/controller/u/1",
    ]
    .iter()
    .map(|p| sink.series(g, p, p, [0, 0, 0], 1.0))
    .collect();
    let step = sink.series(late, "/latency/step", "step", [0, 0, 0], 1.0);
    let mut k = 0u64;
    let mut one = |sink: &mut RrdSink| {
        sink.row(g, k, k as f64 * 1e-3);
        for (i, id) in ids.iter().enumerate() {
            sink.push(*id, (k + i as u64) as f64);
        }
        sink.row(late, k, k as f64 * 1e-3);
        sink.push(step, 1.0);
        sink.flush_full().unwrap();
        k += 1;
    };
    // Two batches sent: every buffer has been made for a whole batch.
    for _ in 0..2 * FLUSH_STEPS {
        one(&mut sink);
    }
    let n = allocations(|| (0..FLUSH_STEPS - 1).for_each(|_| one(&mut sink)));
    sink.finish(k).unwrap();
    assert_eq!(n, 0, "{n} allocations in {} rows", FLUSH_STEPS - 1);
}
