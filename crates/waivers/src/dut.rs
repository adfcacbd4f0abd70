//! The DUT a run compares, as waivers and expected failures see it: its
//! name, revision and profile family, and the matching of `dut` globs and
//! `revisions` against it.
//!
//! An external core is named `"<profile> (<dir>)"`. A profile that
//! `extends` another belongs to its family: the DUT is then also matched
//! under each ancestor's name (`"<ancestor> (<dir>)"`), so a fork of a core
//! whose profile extends that core's inherits the core's waivers. The report
//! says which family member a waiver matched through.

use serde::{Deserialize, Serialize};

use crate::file::{DutGlob, RevRange, Revision};

/// The DUT a run compares: its name (as `RunRecord::dut`), revision and
/// the names it has through its profile's family.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct DutInfo {
    /// DUT name, matched against the waivers' `dut` globs.
    pub name: String,
    /// Revision (`r5`, `v1.2`), matched against `revisions`; a waiver with
    /// revision ranges never matches a DUT of unknown revision.
    pub revision: Option<String>,
    /// The profiles the DUT's profile extends, nearest first, each with
    /// the DUT's name under it; a glob that misses `name` may match one.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub family: Vec<FamilyMember>,
}

/// An ancestor of the DUT's profile, and the DUT's name under it.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct FamilyMember {
    /// The ancestor profile's name (`opencores-can`).
    pub profile: String,
    /// The DUT's name with that profile (`opencores-can (/path/to/fork)`).
    pub name: String,
}

/// How a DUT matched a list of globs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DutMatch<'a> {
    /// By its own name.
    Own,
    /// Through the family member of this profile name.
    Via(&'a str),
}

impl DutInfo {
    /// A DUT of unknown revision.
    pub fn new(name: &str) -> Self {
        DutInfo { name: name.into(), revision: None, family: Vec::new() }
    }

    /// Sets the revision.
    pub fn revision(mut self, rev: &str) -> Self {
        self.revision = Some(rev.into());
        self
    }

    /// Adds the family of the DUT's profile `profile`: `ancestors` are the
    /// profiles it extends, nearest first. A DUT named `"<profile> (<dir>)"`
    /// is `"<ancestor> (<dir>)"` under each; one named `profile` is the
    /// ancestor's name.
    pub fn in_family(mut self, profile: &str, ancestors: &[String]) -> Self {
        let rest = self.name.strip_prefix(profile).filter(|r| r.is_empty() || r.starts_with(" (")).map(str::to_string);
        self.family = ancestors
            .iter()
            .map(|a| FamilyMember { profile: a.clone(), name: format!("{a}{}", rest.clone().unwrap_or_default()) })
            .collect();
        self
    }

    /// Name and revision, for messages.
    pub(crate) fn label(&self) -> String {
        match &self.revision {
            Some(r) => format!("{} {r}", self.name),
            None => self.name.clone(),
        }
    }

    /// Whether the DUT is one the globs name (its own name first, then its
    /// family's) and its revision is in one of `revisions` (none: any).
    pub fn matched_by<'a>(&'a self, globs: &[DutGlob], revisions: &[RevRange]) -> Option<DutMatch<'a>> {
        let by = if globs.iter().any(|g| g.matches(&self.name)) {
            DutMatch::Own
        } else {
            let m = self.family.iter().find(|m| globs.iter().any(|g| g.matches(&m.name)))?;
            DutMatch::Via(&m.profile)
        };
        if revisions.is_empty() {
            return Some(by);
        }
        match self.revision.as_deref().map(str::parse::<Revision>) {
            Some(Ok(r)) if revisions.iter().any(|rr| rr.contains(&r)) => Some(by),
            _ => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn globs(g: &[&str]) -> Vec<DutGlob> {
        g.iter().map(|s| DutGlob::try_from(s.to_string()).unwrap()).collect()
    }

    #[test]
    fn a_fork_matches_its_parents_globs_through_the_family() {
        let fork = DutInfo::new("my-fork (/src/fork)").in_family("my-fork", &["opencores-can".into()]);
        assert_eq!(fork.family, vec![FamilyMember { profile: "opencores-can".into(), name: "opencores-can (/src/fork)".into() }]);
        assert_eq!(fork.matched_by(&globs(&["opencores-can (*)"]), &[]), Some(DutMatch::Via("opencores-can")));
        assert_eq!(fork.matched_by(&globs(&["my-fork (*)"]), &[]), Some(DutMatch::Own));
        assert_eq!(fork.matched_by(&globs(&["other-core (*)", "rtl"]), &[]), None, "another family's waiver");
        // Without the family the fork gets none of the parent's.
        assert_eq!(DutInfo::new("my-fork (/src/fork)").matched_by(&globs(&["opencores-can (*)"]), &[]), None);
    }

    #[test]
    fn the_family_keeps_the_revision_bound() {
        let ranges = vec![RevRange::try_from("r1..r3".to_string()).unwrap()];
        let fork = DutInfo::new("f (/d)").in_family("f", &["p".into()]);
        assert_eq!(fork.matched_by(&globs(&["p (*)"]), &ranges), None, "unknown revision");
        assert_eq!(fork.clone().revision("r2").matched_by(&globs(&["p (*)"]), &ranges), Some(DutMatch::Via("p")));
        assert_eq!(fork.revision("r5").matched_by(&globs(&["p (*)"]), &ranges), None);
    }

    #[test]
    fn a_dut_named_like_its_profile_takes_the_ancestor_name() {
        let d = DutInfo::new("child").in_family("child", &["parent".into(), "grand".into()]);
        let names: Vec<&str> = d.family.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["parent", "grand"]);
        assert_eq!(d.matched_by(&globs(&["gr*"]), &[]), Some(DutMatch::Via("grand")));
    }
}
