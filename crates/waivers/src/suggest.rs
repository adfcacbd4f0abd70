//! `diagnose --suggest-waivers`: candidate entries for the divergences of a
//! run, as waiver-file text. Never applied by itself: each explanation is a
//! `TODO` that [`crate::WaiverSet::parse`] rejects until an engineer writes
//! why the deviation is accepted.

use std::collections::BTreeMap;

use diagnose::{Divergence, DivergenceKind};

use crate::file::{FieldName, KindName, OutFile, OutWaiver, ResyncSpec, Revision};
use crate::report::describe;
use crate::dut::DutInfo;

/// Grouping key: divergences of the same kind at the same place.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
struct Key {
    kind: u8,
    field: Option<String>,
    register: Option<String>,
}

/// Candidate waiver entries (TOML) for `divergences` on `dut`, one per kind
/// and field (tx-bit, pins) or register (reads), bounded by the values seen.
pub fn suggest(divergences: &[Divergence], dut: &DutInfo) -> String {
    let mut groups: BTreeMap<Key, Vec<&Divergence>> = BTreeMap::new();
    for d in divergences {
        let key = Key {
            kind: d.kind as u8,
            field: if d.kind == DivergenceKind::RegisterRead { None } else { d.field.map(|f| format!("{f:?}")) },
            register: d.register.clone(),
        };
        groups.entry(key).or_default().push(d);
    }
    let mut out = Vec::new();
    for ds in groups.values() {
        let first = ds[0];
        let kind = KindName::of(first.kind);
        let mut id = kind.as_str().to_string();
        if let Some(f) = first.field.filter(|_| first.kind != DivergenceKind::RegisterRead) {
            id.push('-');
            id.push_str(&kebab(&format!("{f:?}")));
        }
        if let Some(r) = &first.register {
            id.push('-');
            id.push_str(&kebab(r));
        }
        let mut expected: Vec<u32> = ds.iter().map(|d| d.expected).collect();
        let mut seen: Vec<u32> = ds.iter().map(|d| d.seen).collect();
        expected.sort_unstable();
        expected.dedup();
        seen.sort_unstable();
        seen.dedup();
        let address = first
            .register
            .as_deref()
            .and_then(|r| r.strip_prefix("address "))
            .and_then(|a| a.trim().parse::<u8>().ok());
        let (bits, resync) = match first.kind {
            DivergenceKind::RegisterRead => {
                let diff = ds.iter().fold(0u32, |m, d| m | (d.expected ^ d.seen)) as u8;
                let bits: Vec<u8> = (0..8).filter(|b| diff & (1 << b) != 0).collect();
                let reg = first.register.as_deref().unwrap_or("").to_ascii_uppercase();
                let resync = match reg.as_str() {
                    "TXERR" => ResyncSpec::AdoptDutTec,
                    "RXERR" => ResyncSpec::AdoptDutRec,
                    _ if address.is_some() => ResyncSpec::AdoptDutRegister,
                    _ => ResyncSpec::None,
                };
                (Some(bits), vec![resync])
            }
            _ => {
                // Skip as many bits as the longest run of consecutive divergences.
                let mut bits: Vec<u64> = ds.iter().filter_map(|d| d.bit).collect();
                bits.sort_unstable();
                let (mut best, mut run) = (1u32, 1u32);
                for w in bits.windows(2) {
                    run = if w[1] == w[0] + 1 { run + 1 } else { 1 };
                    best = best.max(run);
                }
                (None, vec![ResyncSpec::SkipBits(best)])
            }
        };
        let base = id.clone();
        let mut n = 1;
        while out.iter().any(|w: &OutWaiver| w.id == id) {
            n += 1;
            id = format!("{base}-{n}");
        }
        out.push(OutWaiver {
            id,
            kind,
            explanation: format!("TODO: why is this deviation accepted? {} seen, first: {}", ds.len(), describe(first)),
            dut: vec![dut.name.clone()],
            // Only a revision the file format can read back (`r5`, `v1.2`).
            revisions: dut.revision.iter().filter(|r| r.parse::<Revision>().is_ok()).cloned().collect(),
            fields: (first.kind == DivergenceKind::TxBit).then(|| first.field.map(|f| vec![FieldName(f)])).flatten(),
            register: first.register.clone(),
            address,
            bits,
            expected: (first.kind != DivergenceKind::RegisterRead).then_some(expected),
            seen: Some(seen),
            resync,
        });
    }
    let body = toml::to_string(&OutFile { waiver: out }).expect("suggested waivers always serialise");
    format!(
        "# Candidate waivers for {} ({} divergence(s)); generated, NOT applied.\n\
         # Review each entry, narrow it, and replace the TODO explanation before use.\n\n{body}",
        match &dut.revision {
            Some(r) => format!("{} {r}", dut.name),
            None => dut.name.clone(),
        },
        divergences.len()
    )
}

/// `ActiveErrorFlag` -> `active-error-flag`, `address 14` -> `address-14`.
fn kebab(s: &str) -> String {
    let mut out = String::new();
    for (i, c) in s.chars().enumerate() {
        if c.is_ascii_uppercase()
            && i > 0
            && !out.ends_with('-')
            && s.chars().nth(i - 1).is_some_and(|p| p.is_ascii_lowercase())
        {
            out.push('-');
        }
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('-') {
            out.push('-');
        }
    }
    out.trim_matches('-').to_string()
}

#[cfg(test)]
mod tests {
    use super::kebab;

    #[test]
    fn ids_are_kebab_case() {
        assert_eq!(kebab("ActiveErrorFlag"), "active-error-flag");
        assert_eq!(kebab("address 14"), "address-14");
        assert_eq!(kebab("TXERR"), "txerr");
    }
}
