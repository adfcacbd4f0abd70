//! Known deviations of a DUT from the golden model.
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
//! An [`expected`] failure (`[[expected-failure]]`) declares a scenario that
//! must fail on a DUT with exactly the recorded signature (strict xfail).
//!
//! ```
//! use diagnose::{Divergence, DivergenceKind};
//! use waivers::{Action, CollectMode, DutInfo, Session, WaiverSet};
//!
//! let set = WaiverSet::parse(r#"
//! [[waiver]]
//! id = "es-late"
//! kind = "register-read"
//! register = "SR"
//! bits = [6]
//! dut = ["*opencores*"]
//! explanation = "SR.ES is set one bit after TEC reaches 96"
//! resync = ["none"]
//! "#, "example.toml")?;
//! let mut run = Session::new(set, DutInfo::new("cores/opencores-can"), CollectMode::StopAtFirst);
//! // In the comparator, for each divergence:
//! let sr = |model: u32, dut: u32| Divergence {
//!     kind: DivergenceKind::RegisterRead, register: Some("SR".into()), expected: model, seen: dut, ..Default::default()
//! };
//! assert_eq!(run.divergence(sr(0x4C, 0x0C)), Action::Resync(vec![])); // waived: go on
//! assert_eq!(run.divergence(sr(0x0C, 0x8C)), Action::Stop); // BS differs: a failure
//! let (report, _) = run.finish();
//! assert_eq!((report.waived.len(), report.failures.len()), (1, 1));
//! assert!(!report.passed());
//! # Ok::<(), waivers::WaiverError>(())
//! ```
#![warn(missing_docs)]

pub mod avoid;
pub mod dut;
pub mod expected;
pub mod file;
pub mod report;
pub mod run;
pub mod set;
pub mod suggest;

pub use expected::{ExpectedFailure, Place, SignatureDiff, StepAt, signature_line, signature_line_in_step};
pub use file::{BitPattern, Consequence, ConsequenceOf, KindName, Lateness, ResyncSpec, RevRange, Revision, WaiverError};
pub use report::{Counts, Stale, WaivedExpectation, Waived, WaiverReport, describe};
pub use run::{Action, CollectMode, Session};
pub use avoid::{Avoid, CAMPAIGN_TRIGGERS};
pub use dut::{DutInfo, DutMatch, FamilyMember};
pub use set::{EXAMPLE, file_schema};
pub use set::{Observed, Resync, Verdict, Waiver, WaiverSet, summary_of};
pub use suggest::suggest;
