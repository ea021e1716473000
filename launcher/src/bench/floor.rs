//! The floor of `uio-launcher bench`: a bare ring of three processes over the same transport
//! (`lockstep` ports on iceoryx2, the same wait strategy and payload lengths as the seed-002
//! closed loop's plant → observer → controller → plant), doing no work and recording nothing.
//! Node 0 stands for the plant: it sends step k and waits for node 2's step k; the step time is
//! the same "send y_k → have u_k" as the run's. With pinning the nodes are placed as the run's
//! ring is (the plant on a CPU of its own). Its steps/s counts the whole process life, spawn to
//! reap, as a run's does, and its loop alone as well.

use std::io::{BufRead, BufReader, Write};
use std::os::unix::process::CommandExt;
use std::process::{Command, Stdio};
use std::time::Instant;

use lockstep::{Bus, RunSpace, Wait, die_with_parent, ready_then_wait_for_go};
use recording::write::{Latency, Percentiles, histogram};
use serde::{Deserialize, Serialize};

use crate::error::LaunchError;

/// What node 0 measured.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct FloorLoop {
    /// Steps per second of the loop alone (go → last step).
    pub loop_steps_per_s: f64,
    /// Step time, ns.
    pub step_ns: Percentiles,
}

const TOPICS: [&str; 3] = ["floor/plant", "floor/observer", "floor/controller"];

/// One node of the ring (the hidden `launcher floor-node` command).
pub fn node(
    run: &str,
    index: usize,
    steps: u64,
    lens: [usize; 3],
    wait: Wait,
) -> Result<(), String> {
    die_with_parent();
    let e = |x: lockstep::LockstepError| x.to_string();
    let space = RunSpace::open(run).map_err(e)?;
    let bus = Bus::join(&space, &format!("floor{index}"), wait).map_err(e)?;
    let outlet = bus.outlet(TOPICS[index], lens[index]).map_err(e)?;
    let from = (index + 2) % 3;
    let inlet = bus.inlet(TOPICS[from]).map_err(e)?;
    let payload = vec![0.0; lens[index]];
    let mut input = vec![0.0; lens[from]];
    ready_then_wait_for_go().map_err(e)?;
    if index != 0 {
        for k in 0..steps {
            inlet.wait_step(k, &mut input).map_err(e)?;
            outlet.send(k, 0.0, 0, &payload).map_err(e)?;
        }
        return Ok(());
    }
    let mut hist = histogram();
    let start = Instant::now();
    for k in 0..steps {
        let sent = outlet.send(k, 0.0, 0, &payload).map_err(e)?;
        let h = inlet.wait_step(k, &mut input).map_err(e)?;
        let _ = hist.record(h.received_ns.saturating_sub(sent).max(1));
    }
    let wall = start.elapsed().as_secs_f64();
    let out = FloorLoop {
        loop_steps_per_s: steps as f64 / wall.max(1e-9),
        step_ns: Latency::percentiles(&hist),
    };
    println!("{}", serde_json::to_string(&out).expect("serialises"));
    Ok(())
}

/// The floor's figures.
#[derive(Debug, Clone, Serialize)]
pub struct Floor {
    /// Steps per second, spawn to reap (as a run's steps/s).
    pub steps_per_s: f64,
    /// What the loop measured.
    pub inner: FloorLoop,
}

/// Runs the bare ring for `steps` steps with payloads `lens` (plant, observer, controller).
pub fn floor(steps: u64, lens: [usize; 3], wait: Wait, pin: bool) -> Result<Floor, LaunchError> {
    let fail = |m: String| LaunchError::Component(format!("bench floor: {m}"));
    let space = RunSpace::create().map_err(|x| fail(x.to_string()))?;
    let exe = std::env::current_exe().map_err(|x| fail(x.to_string()))?;
    let cpus = crate::run::ring_cpus(3, pin);
    let start = Instant::now();
    let mut children = Vec::new();
    let result = (|| {
        for (i, &cpu) in cpus.iter().enumerate() {
            let mut c = Command::new(&exe);
            c.arg("floor-node")
                .arg(space.id())
                .args([i.to_string(), steps.to_string()])
                .args(lens.map(|l| l.to_string()))
                .arg(wait.to_string());
            c.stdin(Stdio::piped())
                .stdout(Stdio::piped())
                .stderr(Stdio::inherit());
            // Placed as the run's ring is (the plant on a CPU of its own).
            if let Some(cpu) = cpu {
                // SAFETY: the closure only calls sched_setaffinity (async-signal-safe).
                unsafe {
                    c.pre_exec(move || {
                        crate::run::pin_self(cpu);
                        Ok(())
                    })
                };
            }
            children.push(
                c.spawn()
                    .map_err(|x| fail(format!("{}: {x}", exe.display())))?,
            );
        }
        let mut outs: Vec<BufReader<_>> = children
            .iter_mut()
            .map(|c| BufReader::new(c.stdout.take().expect("piped")))
            .collect();
        for (i, o) in outs.iter_mut().enumerate() {
            let mut line = String::new();
            o.read_line(&mut line).map_err(|x| fail(x.to_string()))?;
            if line.trim() != "ready" {
                return Err(fail(format!("node {i} did not report ready")));
            }
        }
        for c in &mut children {
            let stdin = c.stdin.as_mut().expect("piped");
            stdin
                .write_all(b"go\n")
                .and_then(|_| stdin.flush())
                .map_err(|x| fail(x.to_string()))?;
        }
        let mut line = String::new();
        outs[0]
            .read_line(&mut line)
            .map_err(|x| fail(x.to_string()))?;
        let inner: FloorLoop = serde_json::from_str(line.trim())
            .map_err(|x| fail(format!("node 0 said {line:?}: {x}")))?;
        for (i, c) in children.iter_mut().enumerate() {
            let status = c.wait().map_err(|x| fail(x.to_string()))?;
            if !status.success() {
                return Err(fail(format!("node {i} {status}")));
            }
        }
        Ok(inner)
    })();
    for c in &mut children {
        let _ = c.kill();
        let _ = c.wait();
    }
    let wall = start.elapsed().as_secs_f64();
    space.remove();
    let inner = result?;
    Ok(Floor {
        steps_per_s: steps as f64 / wall.max(1e-9),
        inner,
    })
}
