//! A hostile Zenoh peer for the security tests (scripts/two-hosts.sh): it connects to an agent
//! with whatever credentials it is given (none, another CA's, or the user's own) and tries what
//! an attacker on the network would. Each action prints one line of what it achieved; the
//! script judges.
//!
//!   intruder [--ca F --cert F --key F] ENDPOINT open
//!   … listen KEY SECONDS             samples received, how many read as plain samples, a key seen
//!   … put KEY COUNT VALUES           forged plain samples (protocol 1, steps 1…)
//!   … start HOST RUN CONFIG_FILE     a start request; the agent's answer
//!   … queryable KEY SECONDS          how many queries it intercepted
//!   … big HOST MEGABYTES             one query that large

use std::time::{Duration, Instant};

use zenoh::{Config, Wait};

fn main() {
    let mut args: Vec<String> = std::env::args().skip(1).collect();
    let mut tls = Vec::new();
    while args.first().is_some_and(|a| a.starts_with("--")) {
        let flag = args.remove(0);
        tls.push((flag, args.remove(0)));
    }
    let endpoint = args.remove(0);
    let mut c = Config::default();
    let set = |c: &mut Config, k: &str, v: serde_json::Value| {
        c.insert_json5(k, &v.to_string()).expect("a valid setting")
    };
    set(&mut c, "mode", "client".into());
    set(&mut c, "connect/endpoints", serde_json::json!([endpoint]));
    set(&mut c, "scouting/multicast/enabled", false.into());
    set(
        &mut c,
        "transport/link/tls/verify_name_on_connect",
        false.into(),
    );
    set(
        &mut c,
        "transport/link/rx/max_message_size",
        serde_json::json!(2u64 << 30),
    );
    for (flag, path) in &tls {
        let key = match flag.as_str() {
            "--ca" => "root_ca_certificate",
            "--cert" => "connect_certificate",
            "--key" => "connect_private_key",
            f => panic!("unknown flag {f}"),
        };
        set(
            &mut c,
            &format!("transport/link/tls/{key}"),
            path.as_str().into(),
        );
        if key == "connect_certificate" {
            set(&mut c, "transport/link/tls/enable_mtls", true.into());
        }
    }
    let z = match zenoh::open(c).wait() {
        Ok(z) => z,
        Err(e) => {
            let e = e.to_string();
            println!(
                "refused: {}",
                e.split("  at ")
                    .next()
                    .unwrap_or(&e)
                    .trim_end_matches(['!', ' '])
            );
            return;
        }
    };
    let action = args.remove(0);
    match action.as_str() {
        "open" => println!("connected"),
        "listen" => {
            let sub = z
                .declare_subscriber(args[0].as_str())
                .wait()
                .expect("declares");
            let until = Instant::now() + Duration::from_secs_f64(args[1].parse().expect("seconds"));
            let (mut n, mut plain, mut key) = (0u64, 0u64, String::from("-"));
            while Instant::now() < until {
                if let Ok(Some(s)) = sub.recv_timeout(Duration::from_millis(50)) {
                    n += 1;
                    let b = s.payload().to_bytes();
                    // A plain sample: a 40-byte header whose protocol field is 1, then f64s.
                    if b.len() >= 40
                        && (b.len() - 40) % 8 == 0
                        && u32::from_le_bytes(b[32..36].try_into().unwrap()) == 1
                    {
                        plain += 1;
                    }
                    key = s.key_expr().to_string();
                }
            }
            println!("received {n} plain {plain} key {key}");
        }
        "put" => {
            let count: u64 = args[1].parse().expect("count");
            let values: usize = args[2].parse().expect("values");
            for step in 1..=count {
                let mut b = Vec::new();
                b.extend(step.to_le_bytes());
                b.extend((step as f64 * 0.001).to_le_bytes());
                b.extend([0u8; 16]);
                b.extend(1u32.to_le_bytes());
                b.extend(0u32.to_le_bytes());
                b.extend(std::iter::repeat_n(0u8, 8 * values));
                z.put(args[0].as_str(), b).wait().expect("puts");
            }
            std::thread::sleep(Duration::from_millis(200));
            println!("sent {count}");
        }
        "start" => {
            let config = std::fs::read_to_string(&args[2]).expect("a configuration file");
            let request = serde_json::json!({ "run": args[1], "builtin": "plant", "config": config, "secret": "00".repeat(32) });
            answer(&z, &args[0], request.to_string().into_bytes());
        }
        "big" => {
            let mb: usize = args[1].parse().expect("megabytes");
            answer(&z, &args[0], vec![b'x'; mb << 20]);
        }
        "queryable" => {
            let q = z
                .declare_queryable(args[0].as_str())
                .wait()
                .expect("declares");
            let until = Instant::now() + Duration::from_secs_f64(args[1].parse().expect("seconds"));
            let mut n = 0;
            while Instant::now() < until {
                if let Ok(Some(_)) = q.recv_timeout(Duration::from_millis(50)) {
                    n += 1;
                }
            }
            println!("intercepted {n}");
        }
        a => panic!("unknown action {a}"),
    }
}

/// Asks the agent of `host` to start something; prints its answer.
fn answer(z: &zenoh::Session, host: &str, payload: Vec<u8>) {
    let replies = z
        .get(format!("uio/agent/{host}/start"))
        .payload(payload)
        .timeout(Duration::from_secs(10))
        .wait()
        .expect("queries");
    match replies.recv() {
        Ok(r) => match r.result() {
            Ok(s) => println!(
                "reply ok: {}",
                s.payload().try_to_string().unwrap_or_default()
            ),
            Err(e) => println!(
                "reply err: {}",
                e.payload().try_to_string().unwrap_or_default()
            ),
        },
        Err(_) => println!("no reply"),
    }
}
