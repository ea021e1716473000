//! The entity groups every export format writes: series grouped by their parent path, each
//! member labelled as the CSV header labels it, and their values aligned on a list of steps,
//! with no value where a member was not recorded at a step (latency can lag one step).

use std::collections::BTreeMap;

use crate::read::{Recording, Series};
use crate::signals;
use crate::tools::recorded_scenario;

/// Groups series by their parent path: "/plant/x/1" → ("/plant/x", "1").
pub fn groups(r: &Recording) -> BTreeMap<String, Vec<(String, &Series)>> {
    let mut out: BTreeMap<String, Vec<(String, &Series)>> = BTreeMap::new();
    for (path, s) in &r.series {
        let (group, member) = match path.rsplit_once('/') {
            Some((g, m)) if !g.is_empty() && (m.parse::<usize>().is_ok() || g == "/latency") => {
                (g.to_string(), m.to_string())
            }
            _ => (path.clone(), "value".to_string()),
        };
        out.entry(group).or_default().push((member, s));
    }
    for members in out.values_mut() {
        members.sort_by_key(|(m, _)| {
            m.parse::<usize>()
                .map_or((1, m.clone()), |i| (0, format!("{i:09}")))
        });
    }
    out
}

/// One member of a group, named for the reader.
pub struct Member<'a> {
    /// The last path segment ("1", "plant_to_observer_uio"), or "value" for a group of one.
    pub member: String,
    /// The entity path ("/observer/uio/xhat/1").
    pub entity: String,
    /// The signal's name without unit ("eta", "e3", "plant->observer/uio", "step_latency").
    pub name: String,
    /// Name and unit, as the CSV header reads before quoting ("eta [rad]").
    pub label: String,
    /// The recorded values.
    pub series: &'a Series,
}

/// A group: its path and members.
pub struct Group<'a> {
    /// The entity path of the group ("/observer/uio/xhat").
    pub path: String,
    /// Members in column order.
    pub members: Vec<Member<'a>>,
}

impl Group<'_> {
    /// The steps at which any member has a value, ascending.
    pub fn steps(&self) -> Vec<i64> {
        union_steps(self.members.iter().map(|m| m.series))
    }
}

/// Every group of `r` with its members named (from the recorded scenario, where it parses).
pub fn labelled(r: &Recording) -> Vec<Group<'_>> {
    let scenario = recorded_scenario(r);
    groups(r)
        .into_iter()
        .map(|(path, members)| {
            let members = members
                .into_iter()
                .map(|(member, series)| {
                    let (name, label) = name_and_label(scenario.as_ref(), r, &path, &member);
                    let entity = Some(format!("{path}/{member}"))
                        .filter(|e| r.series.contains_key(e))
                        .unwrap_or_else(|| path.clone());
                    Member {
                        member,
                        entity,
                        name,
                        label,
                        series,
                    }
                })
                .collect();
            Group { path, members }
        })
        .collect()
}

/// The name and labelled name of `member` of `group`: the signal's name and unit where the
/// scenario is known (`eta`, `eta [rad]`), a latency's hop name in ns (the `step` member becomes
/// `step_latency`, not a second `step` column), else the member itself.
pub fn name_and_label(
    s: Option<&scenario::Scenario>,
    r: &Recording,
    group: &str,
    member: &str,
) -> (String, String) {
    let path = format!("{group}/{member}");
    if group == "/latency" {
        let name = if member == "step" {
            "step_latency".to_string()
        } else {
            r.names
                .get(&path)
                .cloned()
                .unwrap_or_else(|| member.to_string())
        };
        let label = format!("{name} [{}]", r.latency_label_unit());
        return (name, label);
    }
    match signals::named(s, &path) {
        Some(n) => (n.name.clone(), n.with_unit()),
        None => (member.to_string(), member.to_string()),
    }
}

/// The ascending union of the series' steps.
pub fn union_steps<'a>(series: impl IntoIterator<Item = &'a Series>) -> Vec<i64> {
    let mut steps: Vec<i64> = series
        .into_iter()
        .flat_map(|s| s.steps.iter().copied())
        .collect();
    steps.sort_unstable();
    steps.dedup();
    steps
}

/// `s`'s value at each of `steps` (ascending, a superset of `s`'s steps), `None` where `s` has
/// none.
pub fn aligned<'a>(steps: &'a [i64], s: &'a Series) -> impl Iterator<Item = Option<f64>> + 'a {
    let mut at = 0;
    steps.iter().map(move |&k| {
        if at < s.steps.len() && s.steps[at] == k {
            at += 1;
            Some(s.values[at - 1])
        } else {
            None
        }
    })
}

/// The sim_time of step `k`, as the CSV export writes it: k·dt.
pub fn sim_time(k: i64, dt: Option<f64>) -> Option<f64> {
    dt.map(|dt| k as f64 * dt)
}

/// The name of a group's array in the npz and MAT exports, and the stem of its CSV file:
/// "/observer/uio/xhat" → "observer_uio_xhat".
pub fn array_name(group: &str) -> String {
    group.trim_start_matches('/').replace('/', "_")
}

/// The steps of the whole recording, the rows of the npz and MAT arrays: the union over every
/// group's members.
pub fn all_steps(groups: &[Group<'_>]) -> Vec<i64> {
    union_steps(
        groups
            .iter()
            .flat_map(|g| g.members.iter().map(|m| m.series)),
    )
}

/// Each group's array name (through `name`), refused when two groups, or a group and one of
/// the `reserved` arrays (`t`, `step`), would share one.
pub fn unique_names(
    groups: &[Group<'_>],
    reserved: &[&str],
    name: impl Fn(&str) -> String,
) -> Result<Vec<String>, String> {
    let mut seen: BTreeMap<String, &str> = reserved
        .iter()
        .map(|r| (r.to_string(), "the export itself"))
        .collect();
    let mut out = Vec::with_capacity(groups.len());
    for g in groups {
        let n = name(&g.path);
        if let Some(other) = seen.insert(n.clone(), &g.path) {
            return Err(format!(
                "the groups {} and {other} would both be named {n}",
                g.path
            ));
        }
        out.push(n);
    }
    Ok(out)
}
