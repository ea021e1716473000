//! Which observers share a process when a run goes across processes.
//!
//! Every `[[observer]]` runs in a process of its own. A diagnosis bank's members all read the
//! same plant samples, so one process steps them all (`observer::shell`): a bank costs one
//! subscriber of the plant's service and one process, whatever its size. A bank with a member
//! placed on another host (`[remote]`) keeps one process per member.

use std::collections::BTreeMap;

use crate::{ObserverEntry, Remote};

/// One observer process.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct ObserverProcess {
    /// The observers it steps: indices into the scenario's `observers`.
    pub observers: Vec<usize>,
    /// The diagnoser (its index) whose bank it hosts, whole.
    pub bank: Option<usize>,
}

/// The observer processes, in order: the scenario's own observers one by one, then each bank's
/// members together.
pub fn observer_processes(
    observers: &[ObserverEntry],
    remote: &BTreeMap<String, Remote>,
) -> Vec<ObserverProcess> {
    let mut out: Vec<ObserverProcess> = Vec::new();
    let mut bank_of: BTreeMap<usize, usize> = BTreeMap::new();
    let split: Vec<usize> = observers
        .iter()
        .filter(|o| remote.contains_key(&o.name))
        .filter_map(|o| o.member.map(|(d, _)| d))
        .collect();
    for (i, o) in observers.iter().enumerate() {
        match o.member {
            Some((d, _)) if !split.contains(&d) => match bank_of.get(&d) {
                Some(&p) => out[p].observers.push(i),
                None => {
                    bank_of.insert(d, out.len());
                    out.push(ObserverProcess {
                        observers: vec![i],
                        bank: Some(d),
                    });
                }
            },
            _ => out.push(ObserverProcess {
                observers: vec![i],
                bank: None,
            }),
        }
    }
    out
}
