//! Known deviations of a DUT from the golden model (issue 9).
//!
//! A waiver file ([`file`]) lists the deviations an engineer accepts for a
//! DUT or a range of its revisions, each with an explanation, optional
//! bounds and the re-synchronisation it allows. The lockstep comparator
//! hands every divergence to a [`Session`]: a waived one comes back as
//! [`Resync`] steps to apply before comparing on; an unwaived one stops the
//! run or is collected ([`CollectMode`]). The [`WaiverReport`] keeps waived
//! divergences apart from failures and warns about waivers that never
//! matched, so nothing is silently hidden. [`suggest`] writes candidate
//! entries for a run's divergences, which are never applied by themselves.
#![warn(missing_docs)]

pub mod file;
pub mod report;
pub mod run;
pub mod set;
pub mod suggest;

pub use file::{KindName, ResyncSpec, RevRange, Revision, WaiverError};
pub use report::{Counts, Stale, Waived, WaiverReport, describe};
pub use run::{Action, CollectMode, Session};
pub use set::{DutInfo, Observed, Resync, Verdict, Waiver, WaiverSet};
pub use suggest::suggest;
