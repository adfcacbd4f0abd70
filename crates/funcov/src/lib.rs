//! Functional coverage of the CAN protocol and of the SJA1000 register set,
//! observed on the golden model's side of a run, so the figures mean the
//! same for every DUT: which frame kinds went over the bus, which error
//! kinds the reference detected in which field, its fault-confinement
//! transitions, where it lost arbitration, which register bits the host
//! wrote and read in which view and mode, which interrupts it saw raised and
//! cleared, and which acceptance-filter modes accepted and rejected frames.
//!
//! The bins are fixed in advance ([`Coverage::new`]): a bin nobody hit is a
//! hole, listed first. An observation outside the bins (e.g. an error kind
//! in a field CAN 2.0B does not allow for it) is kept as an `unlisted` bin,
//! so the model of the bins cannot silently hide anything. A bin the
//! protocol or the SJA1000 cannot reach is marked unreachable with the
//! reason ([`Bin::unreachable`]): not a hole, not in the totals, printed
//! with its reason.
//!
//! It reads only what the test bench already records ([`diagnose::RunRecord`]:
//! the reference's engine events, the host accesses) and the frames its bus
//! decoder logged; it changes nothing in a run.

mod bins;
mod observe;
mod table;
mod unreachable;

use serde::{Deserialize, Serialize};
use std::collections::HashMap;

pub use observe::BusFrame;

/// One coverage bin.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Bin {
    /// Group, e.g. "frame kinds", "registers PeliCAN reset write".
    pub group: String,
    /// The bin in the group, e.g. "EFF remote DLC 3".
    pub name: String,
    /// Times it was hit.
    pub hits: u64,
    /// Not part of the bin model: seen, but outside what the bins list.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub unlisted: bool,
    /// Why no run can hit it (the protocol or the SJA1000 rules it out):
    /// then it is no hole and not counted in the totals.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub unreachable: Option<String>,
}

impl Bin {
    /// Counted in hit/total: listed and reachable.
    fn counted(&self) -> bool {
        !self.unlisted && self.unreachable.is_none()
    }
}

/// A set of bins with their hits: one run's, or merged over a suite.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Coverage {
    /// Every bin, in the model's order (unlisted ones appended).
    pub bins: Vec<Bin>,
    #[serde(skip)]
    index: HashMap<(String, String), usize>,
}

impl Default for Coverage {
    fn default() -> Self {
        Coverage::new()
    }
}

impl PartialEq for Coverage {
    fn eq(&self, other: &Self) -> bool {
        self.bins == other.bins
    }
}

/// Hit and total bins of one group.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct GroupSummary {
    /// Group name.
    pub group: String,
    /// Bins hit at least once.
    pub hit: usize,
    /// Bins in the group.
    pub total: usize,
}

impl GroupSummary {
    /// Hit bins in percent (100 for an empty group).
    pub fn percent(&self) -> f64 {
        if self.total == 0 { 100.0 } else { 100.0 * self.hit as f64 / self.total as f64 }
    }
}

impl Coverage {
    /// Every bin of the model, none hit.
    pub fn new() -> Coverage {
        let mut c = Coverage { bins: Vec::new(), index: HashMap::new() };
        for (group, name) in bins::all() {
            c.push(group, name, false);
        }
        let unmatched = unreachable::mark(&mut c.bins);
        debug_assert!(unmatched.is_empty(), "unreachable entries that name no bin: {unmatched:?}");
        c
    }

    /// Unreachable-list entries that name no bin (kept empty by a test).
    pub fn unmatched_unreachable_entries() -> Vec<String> {
        let mut c = Coverage { bins: Vec::new(), index: HashMap::new() };
        for (group, name) in bins::all() {
            c.push(group, name, false);
        }
        unreachable::mark(&mut c.bins)
    }

    fn push(&mut self, group: String, name: String, unlisted: bool) -> usize {
        let k = self.bins.len();
        self.index.insert((group.clone(), name.clone()), k);
        self.bins.push(Bin { group, name, hits: 0, unlisted, unreachable: None });
        k
    }

    fn reindex(&mut self) {
        self.index = self.bins.iter().enumerate().map(|(k, b)| ((b.group.clone(), b.name.clone()), k)).collect();
    }

    /// Counts one hit of `group`/`name`; a bin the model does not list is
    /// added as unlisted.
    pub fn hit(&mut self, group: &str, name: &str) {
        let key = (group.to_string(), name.to_string());
        let k = match self.index.get(&key) {
            Some(&k) => k,
            None => self.push(key.0, key.1, true),
        };
        self.bins[k].hits += 1;
    }

    /// Hits of `group`/`name` (None: no such bin).
    pub fn hits(&self, group: &str, name: &str) -> Option<u64> {
        self.index.get(&(group.to_string(), name.to_string())).map(|&k| self.bins[k].hits)
    }

    /// Adds another run's hits (bins matched by group and name).
    pub fn merge(&mut self, other: &Coverage) {
        if self.index.len() != self.bins.len() {
            self.reindex();
        }
        for b in &other.bins {
            let key = (b.group.clone(), b.name.clone());
            let k = match self.index.get(&key) {
                Some(&k) => k,
                None => self.push(key.0, key.1, b.unlisted),
            };
            self.bins[k].hits += b.hits;
            if self.bins[k].unreachable.is_none() {
                self.bins[k].unreachable = b.unreachable.clone();
            }
        }
    }

    /// The listed, reachable bins nobody hit.
    pub fn holes(&self) -> impl Iterator<Item = &Bin> {
        self.bins.iter().filter(|b| b.hits == 0 && b.counted())
    }

    /// The bins marked unreachable (each with its reason).
    pub fn unreachable(&self) -> impl Iterator<Item = &Bin> {
        self.bins.iter().filter(|b| b.unreachable.is_some())
    }

    /// Observations outside the bin model.
    pub fn unlisted(&self) -> impl Iterator<Item = &Bin> {
        self.bins.iter().filter(|b| b.unlisted)
    }

    /// Per group, in the model's order: hit and total listed, reachable bins.
    pub fn summary(&self) -> Vec<GroupSummary> {
        let mut out: Vec<GroupSummary> = Vec::new();
        for b in self.bins.iter().filter(|b| b.counted()) {
            if out.last().is_none_or(|g| g.group != b.group) {
                out.push(GroupSummary { group: b.group.clone(), hit: 0, total: 0 });
            }
            let g = out.last_mut().expect("pushed above");
            g.total += 1;
            g.hit += (b.hits > 0) as usize;
        }
        out
    }

    /// All listed, reachable bins: hit and total.
    pub fn totals(&self) -> GroupSummary {
        let listed = self.bins.iter().filter(|b| b.counted());
        GroupSummary { group: "all".into(), hit: listed.clone().filter(|b| b.hits > 0).count(), total: listed.count() }
    }

    /// Records what one run exercised: `record` (the reference's events
    /// and the host accesses) and the frames the bench's bus decoder saw.
    pub fn observe(&mut self, record: &diagnose::RunRecord, frames: &[BusFrame]) {
        observe::run(self, record, frames);
    }

    /// The holes of `group` in words, register bits folded per register
    /// and value (`ACR0 =1 bits 7-0`).
    pub fn holes_in(&self, group: &str) -> Vec<String> {
        table::compact_holes(self, group)
    }

    /// The table: groups with the fewest hit bins first, then every hole
    /// by group, then anything unlisted.
    pub fn to_table(&self) -> String {
        table::render(self)
    }
}
