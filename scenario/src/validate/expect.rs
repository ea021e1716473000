//! `[expect]`: what a run must show (tail errors, detection delays, isolation, false alarms),
//! each naming an observer, a fault or a figure the scenario has.

use std::collections::BTreeSet;

use crate::check::{Bad, bad};
use crate::raw::RawExpect;
use crate::untrusted::quoted;

/// The checked `[expect]`.
pub(super) fn expect(
    raw: Option<RawExpect>,
    seen: &BTreeSet<String>,
    faults: &[plant::Fault],
    has_diagnosers: bool,
) -> Result<RawExpect, Bad> {
    let expect = raw.unwrap_or_default();
    check_expect(&expect, seen)?;
    for (name, &v) in &expect.detection_delay {
        let f = format!("expect.detection_delay.{name}");
        if !faults.iter().any(|x| &x.name == name) {
            return Err(bad(f, format!("no fault named {}", quoted(name))));
        }
        if !(v.is_finite() && v > 0.0) {
            return Err(bad(f, format!("{v} must be a finite number > 0")));
        }
    }
    let judged = !expect.detection_delay.is_empty()
        || expect.correct_isolation.is_some()
        || expect.first_isolation_correct.is_some()
        || expect.false_alarms.is_some();
    if judged && !has_diagnosers {
        return Err(bad(
            "expect",
            "detection, isolation and false alarms are judged by a [[diagnoser]]; the scenario has none",
        ));
    }
    Ok(expect)
}

pub(super) fn check_expect(e: &RawExpect, observers: &BTreeSet<String>) -> Result<(), Bad> {
    let known = |field: &str, name: &str| {
        if observers.contains(name) {
            Ok(())
        } else {
            Err(bad(field, format!("no observer named {}", quoted(name))))
        }
    };
    let positive = |field: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(bad(field, format!("{v} must be a finite number > 0")))
        }
    };
    for (table, map) in [
        ("tail_max_abs_error", &e.tail_max_abs_error),
        ("tail_max_abs_residual", &e.tail_max_abs_residual),
    ] {
        for (name, &v) in map {
            let f = format!("expect.{table}.{name}");
            known(&f, name)?;
            positive(&f, v)?;
        }
    }
    for (table, map) in [
        ("max_abs_difference", &e.max_abs_difference),
        ("tail_error_ratio", &e.tail_error_ratio),
    ] {
        for (pair, &v) in map {
            let f = format!("expect.{table}");
            let Some((a, b)) = pair.split_once('/') else {
                return Err(bad(
                    f,
                    format!("{} must name two observers as \"a/b\"", quoted(pair)),
                ));
            };
            known(&f, a)?;
            known(&f, b)?;
            positive(&f, v)?;
        }
    }
    Ok(())
}
