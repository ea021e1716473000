//! The design report as text: a section per observer, bank and controller, matrices as rows of
//! significant digits, every list of poles with its domain (s or z).

use lti::Mat;
use lti::eig::{format_list, sig};
use observer::design::Condition;

use super::sections::{ControllerSection, DesignReport, ObserverSection};

impl DesignReport {
    /// The human-readable text.
    pub fn text(&self) -> String {
        render(self)
    }
}

fn render(r: &DesignReport) -> String {
    let mut text = format!("{}: {}\n", r.scenario, r.description);
    for o in &r.observers {
        text += &observer(o, r.dt);
    }
    if let Some(banks) = &r.banks {
        text += &self::banks(banks);
    }
    text += &controller(&r.controller);
    if !r.warnings.is_empty() {
        text += "\nwarnings:\n";
        for w in &r.warnings {
            text += &format!("  - {w}\n");
        }
    }
    text
}

/// Matrices with more entries than this are shown in part (numpy's print summarisation, with
/// its 3 edge items; numpy's threshold is 1000 entries, ours keeps every matrix up to 100 × 100 —
/// all the shipped scenarios' — whole). A 1000-state design printed whole was 46 MB of text and
/// a tenth of its time; `--json` carries every entry.
pub const WHOLE_UP_TO: usize = 10_000;

/// The first and last rows and columns a summarised matrix shows.
const EDGE: usize = 3;

/// A matrix as text under its paper's name: every entry up to [`WHOLE_UP_TO`] entries, else
/// the first and last [`EDGE`] rows and columns with "…" between.
pub fn matrix(name: &str, m: &Mat) -> String {
    let (rows, cols) = m.shape();
    let whole = rows * cols <= WHOLE_UP_TO;
    let shown = |len: usize| -> Vec<Option<usize>> {
        if whole || len <= 2 * EDGE {
            (0..len).map(Some).collect()
        } else {
            (0..EDGE)
                .map(Some)
                .chain(std::iter::once(None))
                .chain((len - EDGE..len).map(Some))
                .collect()
        }
    };
    let (row_ix, col_ix) = (shown(rows), shown(cols));
    // One buffer for the whole matrix (a String per entry and per row was a third of a large
    // report's time).
    let mut s = String::with_capacity(64 + row_ix.len() * (10 + 14 * col_ix.len()));
    s.push_str("    ");
    s.push_str(name);
    if whole {
        s.push_str(" =\n");
    } else {
        s.push_str(&format!(
            " = ({rows}×{cols}: its first and last {EDGE} rows and columns; every entry in `uio-launcher design --json`)\n"
        ));
    }
    for i in &row_ix {
        let Some(i) = *i else {
            s.push_str("      …\n");
            continue;
        };
        s.push_str("      [");
        for j in &col_ix {
            let entry = match *j {
                Some(j) => sig(m[(i, j)]), // ASCII: its length is its width
                None => "…".to_string(),
            };
            s.extend(std::iter::repeat_n(
                ' ',
                14usize.saturating_sub(entry.chars().count()),
            ));
            s.push_str(&entry);
        }
        s.push_str(" ]\n");
    }
    s
}

fn conditions(c: &[Condition]) -> String {
    c.iter()
        .map(|c| {
            format!(
                "    {} {:<52} {}\n",
                if c.ok { "ok  " } else { "FAIL" },
                c.name,
                c.detail
            )
        })
        .collect()
}

fn observer(o: &ObserverSection, dt: f64) -> String {
    match o {
        ObserverSection::Process { name, command, .. } => format!(
            "\nobserver '{name}' (process)\n  external process: {}\n",
            scenario::untrusted::one_line(&command.join(" "))
        ),
        ObserverSection::Designed {
            name,
            kind,
            designed,
        } => {
            let r = &designed.report;
            let mut text = format!("\nobserver '{name}' ({kind})\n");
            text += "  conditions:\n";
            text += &conditions(&r.conditions);
            text += "  matrices:\n";
            for (n, m) in &r.matrices {
                text += &matrix(n, m);
            }
            // Every list says its domain: s for the continuous poles and fixed modes (ln(z)/dt
            // for a sampled-only design), z for the sampled ones.
            text += &format!("  poles (s):        {}\n", format_list(&r.poles));
            text += &time_constants(&r.poles);
            text += &format!(
                "  poles (z, dt = {dt}): {}\n",
                format_list(&r.discrete_poles)
            );
            if !r.fixed_modes.is_empty() {
                text += &format!("  fixed modes (s):  {}\n", format_list(&r.fixed_modes));
            }
            for n in &r.notes {
                text += &format!("  note: {n}\n");
            }
            text
        }
        ObserverSection::Refused {
            name,
            kind,
            error: e,
            carried,
        } => {
            let mut text = format!("\nobserver '{name}' ({kind})\n");
            text += "  conditions:\n";
            text += &conditions(&e.conditions);
            if !e.conditions.iter().any(|c| !c.ok) {
                text += &format!("    FAIL {:<52} {}\n", e.condition, e.detail);
            }
            text += &format!(
                "  no observer: {} does not hold: {}{carried}\n",
                e.condition, e.detail
            );
            text
        }
    }
}

fn controller(c: &ControllerSection) -> String {
    match c {
        ControllerSection::None => String::new(),
        ControllerSection::Error(e) => format!("\ncontroller: {e}\n"),
        ControllerSection::Process {
            observer, command, ..
        } => format!(
            "\ncontroller: external process on '{observer}': {}\n",
            scenario::untrusted::one_line(&command.join(" "))
        ),
        ControllerSection::Feedback {
            kind,
            observer,
            feedback: fb,
            measured,
            track,
            continuous,
        } => {
            let law = match (&fb.integral, track) {
                (Some(_), _) => "u = −G x̂ − G_ξ ξ, ξ⁺ = ξ + dt (r − z)",
                (None, true) => "u = N r − G x̂",
                (None, false) => "u = r − G x̂",
            };
            let ff = if fb.feedforward.is_some() {
                " − M ŵ"
            } else {
                ""
            };
            let mut text = format!(
                "\ncontroller: {kind}, {law}{ff}, on '{observer}'\n  G {}\n",
                fb.how
            );
            text += &matrix("G", &fb.g);
            if !measured.is_empty() {
                text += &format!(
                    "  measured disturbances {}: not commanded, u = r (their [[input]] signals); G, R and the tracked outputs cover the other inputs (designed on their columns Γ_c of Γ_B)\n",
                    measured.join(", ")
                );
            }
            if let Some((gi, ct, m)) = &fb.integral {
                text += &format!(
                    "  integral action on the tracked outputs z = C_t x, {} (designed on the augmented sampled plant):\n",
                    if m.is_some() {
                        "measured as z = M y"
                    } else {
                        "estimated as z = C_t x̂ (not a combination of the outputs)"
                    }
                );
                text += &matrix("G_ξ", gi);
                text += &matrix("C_t", ct);
                if let Some(m) = m {
                    text += &matrix("M", m);
                }
            } else if *track {
                text += "  prefilter N = (C_t(I − Φ + Γ_BG)⁻¹Γ_B)⁻¹ (unit DC gain from r to z):\n";
                text += &matrix("N", &fb.n);
            }
            if let Some([mw, ..]) = &fb.feedforward {
                text += "  feedforward: u −= M ŵ_{k−1}, M = Γ_B⁺Γ_E (w enters through the inputs: Γ_E = Γ_B M); ŵ from the observer's estimator, M W:\n";
                text += &matrix("MW", mw);
            }
            let closed = if *continuous {
                "eig(A − BG)"
            } else {
                "ln(z)/dt of the sampled loop"
            };
            text += &format!(
                "  closed loop, {closed}: {}\n",
                format_list(&fb.closed_loop)
            );
            text += &format!(
                "  sampled eig(Φ − Γ_BG):       {}\n",
                format_list(&fb.discrete_closed_loop)
            );
            text += &format!("  stable: {}\n", fb.stable());
            if !fb.stable() {
                text +=
                    "  the run refuses an unstable loop (pass --allow-unstable to run it anyway)\n";
            }
            text
        }
    }
}

/// The poles as time constants, τ = −1/Re(p), each in a readable unit ("τ: 1 s, 0.5 s, 16.7 min"):
/// how fast each mode of the error decays, which a pole of −0.001667 does not say at a glance.
fn time_constants(poles: &[lti::eig::C64]) -> String {
    let taus: Vec<String> = poles
        .iter()
        .filter(|p| p.re < 0.0 && p.im >= 0.0)
        .map(|p| {
            let tau = -1.0 / p.re;
            let (unit, per) = lti::units::scale(tau * 3.0);
            format!("{} {unit}", sig(tau / per))
        })
        .collect();
    if taus.is_empty() {
        String::new()
    } else {
        format!("  time constants τ = −1/Re p: {}\n", taus.join(", "))
    }
}

/// Each bank: its members (role, poles, threshold), and the structure matrix computed from the
/// designs beside the one asked for.
fn banks(banks: &Result<Vec<diagnosis::Bank>, String>) -> String {
    let banks = match banks {
        Ok(b) => b,
        Err(e) => return format!("\ndiagnoser: {e}\n"),
    };
    let mut text = String::new();
    for b in banks {
        let d = &b.spec;
        text += &format!(
            "\ndiagnoser '{}' ({} scheme, {} faults, {} members)\n",
            d.name,
            d.scheme.name(),
            d.channels.name(),
            b.members.len()
        );
        for (i, m) in b.members.iter().enumerate() {
            let role = diagnosis::bank::role(d, &b.channels, i);
            let threshold = match d.threshold {
                diagnosis::Threshold::Calibrated { runs, margin } => format!(
                    "{margin} × the largest J of {runs} fault-free realisation(s), set when run"
                ),
                _ => sig(m.threshold),
            };
            text += &format!(
                "  {} ({role}): {}, sampled poles {}, threshold {threshold}\n",
                m.name,
                m.designed.report.kind,
                format_list(&m.designed.report.discrete_poles)
            );
            if let Some(g) = &m.glr {
                let tested: Vec<&str> =
                    g.channels.iter().map(|&j| b.channels[j].as_str()).collect();
                text += &format!(
                    "    GLR over {} samples, onsets on {}: threshold {}\n",
                    g.window,
                    if tested.is_empty() {
                        "no channel".to_string()
                    } else {
                        tested.join(", ")
                    },
                    sig(g.threshold)
                );
            }
        }
        text += &format!(
            "  structure, transient (rows: residuals, columns: {}):\n",
            b.channels.join(", ")
        );
        for (i, r) in b.structure.iter().enumerate() {
            text += &format!("    r{} {:?}\n", i + 1, r);
        }
        if d.structure.is_some() {
            text += "  equals the structure asked for\n";
        }
        match &b.steady {
            Some(st) => {
                text += &format!(
                    "  steady-state structure under a constant fault (rows: residuals, columns: {}):\n",
                    b.channels.join(", ")
                );
                for (i, r) in st.iter().enumerate() {
                    text += &format!("    r{} {:?}\n", i + 1, r);
                }
            }
            None => {
                text += "  steady-state structure: not computed (a member's state is not a function of the plant's)\n"
            }
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_matrix_up_to_ten_thousand_entries_is_printed_whole_and_a_larger_one_by_its_corners() {
        let m = |r: usize, c: usize| Mat::from_fn(r, c, |i, j| (i * 1000 + j) as f64 + 0.25);
        let small = matrix("K", &m(2, 2));
        let padded = |v: f64| format!("{:>14}", sig(v));
        assert_eq!(
            small,
            format!(
                "    K =\n      [{}{} ]\n      [{}{} ]\n",
                padded(0.25),
                padded(1.25),
                padded(1000.25),
                padded(1001.25)
            )
        );
        let whole = matrix("F", &m(100, 100));
        assert_eq!(whole.lines().count(), 101);
        assert!(!whole.contains('…'));

        let big = matrix("F", &m(150, 120));
        let lines: Vec<&str> = big.lines().collect();
        assert_eq!(lines.len(), 1 + 3 + 1 + 3, "{big}");
        assert!(lines[0].contains("150×120") && lines[0].contains("--json"));
        assert_eq!(lines[4].trim(), "…");
        let first: Vec<&str> = lines[1]
            .trim_matches(|c| c == ' ' || c == '[' || c == ']')
            .split_whitespace()
            .collect();
        let want: Vec<String> = [0.25, 1.25, 2.25]
            .iter()
            .map(|v| sig(*v))
            .chain(std::iter::once("…".to_string()))
            .chain([117.25, 118.25, 119.25].iter().map(|v| sig(*v)))
            .collect();
        assert_eq!(first, want);
        let last: Vec<&str> = lines[7]
            .trim_matches(|c| c == ' ' || c == '[' || c == ']')
            .split_whitespace()
            .collect();
        assert_eq!(last.last().copied(), Some(sig(149_119.25).as_str()));
    }
}
