//! An observer that breaks the protocol on purpose, for the launcher's supervision tests
//! (`tests/tests/features/supervision/external.rs`). It speaks the protocol by hand — bus, ports, handshake — so that
//! it can get it wrong; the kit would not let it.
//!
//! `params.fault`, from step `params.at` (default 100) on: `nan` (a value is NaN), `wrong_step`
//! (the sample carries step k + 1), `wrong_len` (one value too many), `protocol` (the header says
//! version 2), `hang` (stops publishing and sleeps), `exit` (exits with status 7), `exit0` (exits
//! with status 0, before the run's end), `orphan` (starts a child process, then exits with status
//! 7: the child must not outlive the run), `kill` (dies by SIGKILL), `no_read` (publishes every
//! step at once, without reading the plant's samples), `never_ready` (never writes `ready`),
//! `refuse_version` (refuses the run's protocol version at start, as a component of another
//! version must), `taken_max` (stamps `taken_ns` = u64::MAX, "never", which hides that it did
//! not wait for its input), `nan_time` (its sample's `sim_time` is NaN), `close_stdout` (closes
//! its stdout before `ready` and lives on, as a component that failed to start without dying
//! would). Until then it publishes
//! y's first n values padded with zeros — a poor estimate, but a well-formed one.

use std::process::ExitCode;

use lockstep::component::read_config;
use lockstep::{Bus, PROTOCOL_VERSION, WireHeader, parse_launch, ready_then_wait_for_go};
use serde::Deserialize;

#[derive(Deserialize)]
struct Params {
    fault: String,
    #[serde(default = "default_at")]
    at: u64,
}

fn default_at() -> u64 {
    100
}

fn fail(msg: String) -> ExitCode {
    eprintln!("faulty_observer: {msg}");
    ExitCode::from(3)
}

fn main() -> ExitCode {
    lockstep::die_with_parent();
    let launch = match parse_launch("faulty_observer", std::env::args().skip(1)) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("{e}");
            return ExitCode::from(2);
        }
    };
    let cfg = match read_config() {
        Ok(c) => c,
        Err(e) => return fail(e),
    };
    let p: Params = match cfg.params() {
        Ok(p) => p,
        Err(e) => return fail(e),
    };
    if p.fault == "refuse_version" {
        eprintln!(
            "faulty_observer: the run speaks protocol version {PROTOCOL_VERSION}, this component 2"
        );
        return ExitCode::from(2);
    }
    if p.fault == "close_stdout" {
        // SAFETY: close(2) on this process's own stdout, which nothing here writes to again.
        unsafe { libc::close(1) };
        loop {
            std::thread::sleep(std::time::Duration::from_secs(60));
        }
    }
    if p.fault == "never_ready" {
        loop {
            std::thread::sleep(std::time::Duration::from_secs(60));
        }
    }
    let (n, plant_len) = (cfg.publishes.len, cfg.reads[0].len);
    let bus = match Bus::join(&launch.run, &cfg.name, lockstep::Wait::Yield) {
        Ok(b) => b,
        Err(e) => return fail(e.to_string()),
    };
    let out_len = if p.fault == "wrong_len" { n + 1 } else { n };
    let (outlet, inlet) = match (
        bus.outlet(&cfg.publishes.service, out_len),
        bus.inlet(&cfg.reads[0].service),
    ) {
        (Ok(o), Ok(i)) => (o, i),
        (Err(e), _) | (_, Err(e)) => return fail(e.to_string()),
    };
    if let Err(e) = ready_then_wait_for_go() {
        return fail(e.to_string());
    }
    if p.fault == "orphan" {
        // A child in the component's process group, which the launcher must kill with it.
        let _ = std::process::Command::new("sleep").arg("600").spawn();
    }
    if p.fault == "no_read" {
        let out = vec![0.0; out_len];
        for k in 0..cfg.steps {
            let header = WireHeader {
                step: k,
                sim_time: k as f64 * cfg.dt,
                sent_ns: 0,
                taken_ns: lockstep::now_ns(),
                protocol: PROTOCOL_VERSION,
                reserved: 0,
            };
            if let Err(e) = outlet.send_header(header, &out) {
                return fail(e.to_string());
            }
        }
        return ExitCode::SUCCESS;
    }
    let (mut sample, mut out) = (vec![0.0; plant_len], vec![0.0; out_len]);
    let y0 = cfg.reads[0].fields.get("y").map_or(0, |r| r[0]);
    for k in 0..cfg.steps {
        let h = match inlet.wait_step(k, &mut sample) {
            Ok(h) => h,
            Err(e) => return fail(e.to_string()),
        };
        for (i, o) in out.iter_mut().enumerate() {
            *o = if i < n {
                sample.get(y0 + i).copied().unwrap_or(0.0)
            } else {
                0.0
            };
        }
        let mut header = WireHeader {
            step: k,
            sim_time: h.sim_time,
            sent_ns: 0,
            taken_ns: h.received_ns,
            protocol: PROTOCOL_VERSION,
            reserved: 0,
        };
        if k >= p.at {
            match p.fault.as_str() {
                "nan" => out[0] = f64::NAN,
                "wrong_step" => header.step = k + 1,
                "protocol" => header.protocol = 2,
                "taken_max" => header.taken_ns = u64::MAX,
                "nan_time" => header.sim_time = f64::NAN,
                "hang" => loop {
                    std::thread::sleep(std::time::Duration::from_secs(60));
                },
                "exit" | "orphan" => return ExitCode::from(7),
                "exit0" => return ExitCode::SUCCESS,
                // SAFETY: raise(3) with a valid signal number.
                "kill" => unsafe {
                    libc::raise(libc::SIGKILL);
                },
                _ => {}
            }
        }
        if let Err(e) = outlet.send_header(header, &out) {
            return fail(e.to_string());
        }
    }
    ExitCode::SUCCESS
}
