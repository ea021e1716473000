//! A scenario-wide `time_unit`: a bare number of a simulated time is in that unit. Over seeded
//! random scenarios and every unit, the file written with bare numbers under `time_unit = U` is
//! the file written with `"<v> U"` strings — the same checked scenario, field for field — and
//! `stall_timeout` stays wall-clock seconds, `frequency_hz` Hz.

use std::path::Path;

use scenario::Scenario;

/// A small LCG: the same cases on every run.
struct Cases(u64);

impl Cases {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0 >> 33
    }
    fn pick<T: Copy>(&mut self, from: &[T]) -> T {
        from[(self.next() % from.len() as u64) as usize]
    }
}

/// The scenario with every simulated time given by `t` (a number → its text in the file).
fn text(t: &dyn Fn(f64) -> String, dt: f64, steps: u64, stall: f64, unit_line: &str) -> String {
    let d = dt * steps as f64;
    format!(
        r#"name = "units"
{unit_line}dt = {dt}
duration = {duration}
tail = {tail}
stall_timeout = {stall}

[plant]
{plant}x0 = [1.0, -1.0, 2.0]

[[disturbance]]
kind = "piecewise"
times = [{p1}, {p2}]
values = [0.2, -0.1]

[[input]]
kind = "step"
time = {step}
after = 1.0

[[input]]
kind = "sine"
amplitude = 0.5
frequency_hz = 0.25

[[fault]]
name = "bias"
target = "sensor"
channel = 1
kind = "bias"
value = 0.3
start = {start}
end = {end}

[[fault]]
name = "blink"
target = "sensor"
channel = 2
kind = "bias"
value = 0.1
profile = "intermittent"
intervals = [[{i1}, {i2}]]

[[observer]]
name = "luenberger"
kind = "luenberger"
poles = [-1.0, -2.0, -3.0]
"#,
        dt = t(dt),
        duration = t(d),
        tail = t(dt * (steps / 4).max(1) as f64),
        plant = include_str!("../../fixtures/seed002_plant.toml"),
        p1 = t(dt * (steps / 5) as f64),
        p2 = t(dt * (steps / 2) as f64),
        step = t(dt * (steps / 3) as f64),
        start = t(dt * (steps / 4) as f64),
        end = t(dt * (steps / 2) as f64),
        i1 = t(dt * (steps / 3) as f64),
        i2 = t(dt * (2 * steps / 3) as f64),
    )
}

/// The checked scenario without what names the file and how it was written.
fn checked(text: &str) -> String {
    let mut s =
        Scenario::parse(Path::new("units.toml"), text).unwrap_or_else(|e| panic!("{e}\n{text}"));
    s.time_unit = None;
    s.source = String::new();
    format!("{s:?}")
}

#[test]
fn bare_times_under_a_time_unit_are_the_times_written_with_it() {
    let mut cases = Cases(36);
    for unit in ["ms", "s", "min", "h", "day", "days"] {
        for _ in 0..8 {
            // dt from the unit's own scale, a number of steps, and a stall limit of seconds.
            let dt = cases.pick(&[0.5, 1.0, 2.0, 5.0, 0.25, 10.0]);
            let steps = 40 + cases.next() % 400;
            let stall = cases.pick(&[10.0, 60.0, 600.0]);
            let bare = text(
                &|v| format!("{v:?}"),
                dt,
                steps,
                stall,
                &format!("time_unit = \"{unit}\"\n"),
            );
            let written = text(&|v| format!("\"{v:?} {unit}\""), dt, steps, stall, "");
            let (a, b) = (checked(&bare), checked(&written));
            assert_eq!(a, b, "{unit}, dt {dt}, {steps} steps");
            let s = Scenario::parse(Path::new("units.toml"), &bare).unwrap();
            assert_eq!(s.steps, steps);
            // dt in seconds, independently: the decimal "<dt>e-3" for ms; dt (a binary fraction
            // of few bits) times the unit's whole seconds is exact in binary for the others.
            let per = match unit {
                "ms" => None,
                "s" => Some(1.0),
                "min" => Some(60.0),
                "h" => Some(3600.0),
                _ => Some(86_400.0),
            };
            let want = per.map_or_else(|| format!("{dt}e-3").parse().unwrap(), |p| dt * p);
            assert_eq!(s.dt, want, "{unit} {dt}");
            assert_eq!(s.stall_timeout, stall, "stall_timeout stays seconds");
            assert_eq!(s.time_unit.as_deref(), Some(unit));
        }
    }
}
