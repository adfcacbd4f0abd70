//! The waiver audit end to end on our rtl/: a mutant of OCR bit 1 (the flop
//! stuck at 0) is killed by a scenario that reads OCR back, and survives it
//! once a crafted waiver covers exactly that read. The audit must then name
//! it hidden by that waiver, with the values, and count it as not killed.

use mutate::waiver_audit::HitDifference;
use mutate::{CampaignOptions, CoreSources, MutateConfig, MutationSource, Verdict};
use std::path::{Path, PathBuf};

const RTL_FILES: [&str; 8] = ["can_top.v", "can_wb_cdc.v", "can_regs.v", "can_btl.v", "can_bsp.v", "can_fce.v", "can_acf.v", "can_rxfifo.v"];

fn rtl() -> CoreSources {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../rtl").canonicalize().unwrap();
    CoreSources { dir, top: "can_top".into(), files: RTL_FILES.iter().map(PathBuf::from).collect(), ..Default::default() }
}

/// One mutation, chosen by yosys's own filter: OCR's flop output bit 1 held at 0.
fn ocr_mutation(dir: &Path) -> PathBuf {
    let src = rtl();
    let files: Vec<String> = src.files.iter().map(|f| src.dir.join(f).display().to_string()).collect();
    let script = format!(
        "read_verilog -I{} {}\nhierarchy -top can_top\nprep -top can_top\nflatten\nopt_clean\nmutate -list 1 -mode const0 -wire u_regs.ocr -wirebit 1 -o list.txt\n",
        src.dir.display(),
        files.join(" ")
    );
    std::fs::write(dir.join("list.ys"), script).unwrap();
    let out = std::process::Command::new("yosys").args(["-q", "-s", "list.ys"]).current_dir(dir).output().expect("yosys runs");
    assert!(out.status.success(), "yosys: {}", String::from_utf8_lossy(&out.stderr));
    let list = dir.join("list.txt");
    let text = std::fs::read_to_string(&list).unwrap();
    assert_eq!(text.lines().count(), 1, "one mutation of u_regs.ocr bit 1: {text}");
    list
}

const SCENARIO: &str = r#"
name = "OCR read back"
purpose = "OCR written and read back in reset mode"
verifies = ["OCR reads back 0xFF"]
sequence = ["reset mode, PeliCAN, OCR = 0xFF, read OCR"]
step = [
    { write = "CR", value = 1 },
    { write = "CDR", value = 0x80 },
    { write = "OCR", value = 0xFF },
    { read = "OCR", expect = 0xFF },
]
[clocks]
host_mhz = 50.0
can_mhz = 24.0
[host]
bfm = "wishbone"
[dut]
kind = "rtl"
[run]
max_bits = 40
[expect]
category = "Pass"
"#;

/// Covers exactly the mutant's read: OCR bit 1, model 1, DUT 0.
const WAIVER: &str = r#"
[[waiver]]
id = "crafted-ocr-bit1"
kind = "register-read"
register = "OCR"
bits = [1]
expected-bits = "xxxx_xx1x"
seen-bits = "xxxx_xx0x"
dut = ["*"]
explanation = "Crafted for the waiver audit's test: masks OCR bit 1 read as 0."
max-hits = 1
resync = ["none"]
"#;

fn config(work: &Path, list: &Path, waivers: Vec<PathBuf>, out: &str) -> MutateConfig {
    let sc = work.join("ocr.toml");
    std::fs::write(&sc, SCENARIO).unwrap();
    MutateConfig {
        sources: rtl(),
        from: MutationSource::Saved(list.to_path_buf()),
        scenarios: vec![scenario::Scenario::load(&sc).unwrap()],
        profile: cosim::Profile::rtl(),
        run: scenario::RunOptions { waivers, ..Default::default() },
        campaign: CampaignOptions { jobs: 1, ..Default::default() },
        formal: None,
        out: work.join(out),
        cache: cosim::cache_dir(),
        campaign_frames: 0,
        campaign_seed: 1,
    }
}

#[test]
fn a_survivor_a_waiver_masks_is_hidden_and_not_killed() {
    let work = tempfile::tempdir().unwrap();
    let list = ocr_mutation(work.path());
    let mut log = |l: &str| eprintln!("{l}");

    // Without the waiver the scenario kills the mutant: it is observable.
    let plain = mutate::mutate(&config(work.path(), &list, Vec::new(), "plain"), &mut log).unwrap();
    assert!(matches!(&plain.mutants[0].verdict, Verdict::Killed { why, .. } if why.contains("OCR")), "{:?}", plain.mutants[0].verdict);
    assert!(plain.hidden.is_empty());
    assert_eq!(plain.audit, None, "no waivers: nothing to audit");

    // With it the mutant passes; the audit finds the waiver hit the
    // original's run does not have.
    let w = work.path().join("waiver.toml");
    std::fs::write(&w, WAIVER).unwrap();
    let r = mutate::mutate(&config(work.path(), &list, vec![w], "waived"), &mut log).unwrap();
    assert_eq!(r.mutants[0].verdict, Verdict::Survived, "the crafted waiver masks the mutant");
    assert_eq!(r.hidden.len(), 1, "{:?}", r.hidden);
    let h = &r.hidden[0];
    assert_eq!((h.id, h.test.as_str()), (1, "OCR read back"));
    let hits: Vec<_> = h
        .differences
        .iter()
        .map(|d| match d {
            HitDifference::OtherWaiver { hit, .. } => (hit.waiver_id.as_str(), hit.model, hit.dut),
            other => panic!("the original hits no waiver: {other:?}"),
        })
        .collect();
    assert_eq!(hits, vec![("crafted-ocr-bit1", 0xFF, 0xFD)]);
    let c = r.counts();
    assert_eq!((c.killed, c.survived, c.hidden_by_waiver), (0, 0, 1));
    assert_eq!(r.score(), Some(0.0), "hidden by a waiver is not killed");
    assert!(r.summary().contains("1 hidden by a waiver"), "{}", r.summary());
    let a = r.audit.as_ref().expect("audited");
    assert_eq!((a.survivors, a.scenarios_with_waivers, a.scenarios_with_hits, a.baseline_hits, a.hidden), (1, 1, 0, 0, 1));
    let md = std::fs::read_to_string(work.path().join("waived/report.md")).unwrap();
    assert!(md.contains("## Hidden by a waiver") && md.contains("crafted-ocr-bit1") && md.contains("model 0xFF, DUT 0xFD"), "{md}");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(work.path().join("waived/report.json")).unwrap()).unwrap();
    assert_eq!(json["counts"]["hidden_by_waiver"], 1);
    assert_eq!(json["hidden"][0]["differences"][0]["hit"]["waiver_id"], "crafted-ocr-bit1");
}
