//! Runs a campaign from the command line until the CLI has its
//! `campaign` subcommand: `cargo run --release -p campaign --example campaign -- SEED FRAMES [model|rtl] [FIRST_FRAME] [FAULT_RATE]` (CAMPAIGN_FRAMES=1 lists every frame, CAMPAIGN_VCD=path writes the waveform, CAMPAIGN_MAX=n stops after n disagreements, CAMPAIGN_PLAN=1 lists the plan only, CAMPAIGN_STRICT=1 compares with no tolerance, CAMPAIGN_TOL=tx,status,pin,sof sets them in CAN clocks, CAMPAIGN_NODES=n model nodes)`.
use campaign::{CampaignConfig, DutChoice, run_campaign};

fn main() {
    let a: Vec<String> = std::env::args().collect();
    let seed = a.get(1).and_then(|s| s.parse().ok()).unwrap_or(1);
    let frames = a.get(2).and_then(|s| s.parse().ok()).unwrap_or(100);
    let dut = match a.get(3).map(String::as_str) {
        Some("model") => DutChoice::Model,
        _ => DutChoice::Rtl,
    };
    let first_frame = a.get(4).and_then(|s| s.parse().ok()).unwrap_or(0);
    let fault_rate = a.get(5).and_then(|s| s.parse().ok()).unwrap_or(CampaignConfig::default().fault_rate);
    if std::env::var_os("CAMPAIGN_PLAN").is_some() {
        let cfg = CampaignConfig { seed, fault_rate, ..CampaignConfig::default() };
        for i in first_frame..first_frame + frames {
            println!("frame {i}: {}", campaign::describe_frame(&cfg, i));
        }
        return;
    }
    let vcd = std::env::var_os("CAMPAIGN_VCD").map(std::path::PathBuf::from);
    let max_disagreements = std::env::var("CAMPAIGN_MAX").ok().and_then(|s| s.parse().ok()).unwrap_or(10);
    let mut compare = if std::env::var_os("CAMPAIGN_STRICT").is_some() { CampaignConfig::strict_compare() } else { CampaignConfig::compare_for(&dut) };
    if let Ok(t) = std::env::var("CAMPAIGN_TOL") {
        // tx,status,pin,sof in CAN clocks
        let v: Vec<u32> = t.split(',').filter_map(|x| x.parse().ok()).collect();
        if let [tx, status, pin, sof] = v[..] {
            compare = cosim::CompareConfig { tx_edge_tolerance: tx, status_tolerance: status, pin_tolerance: pin, sof_tolerance: sof, ..compare };
        }
    }
    let nodes = std::env::var("CAMPAIGN_NODES").ok().and_then(|s| s.parse().ok()).unwrap_or(CampaignConfig::default().nodes);
    let r = run_campaign(&CampaignConfig { seed, frames, dut, first_frame, fault_rate, vcd, max_disagreements, nodes, compare: Some(compare), ..CampaignConfig::default() });
    print!("{}", r.to_text());
    if std::env::var_os("CAMPAIGN_FRAMES").is_some() {
        for f in &r.frames {
            println!("{f:?}");
        }
    }
    std::process::exit(if r.passed() { 0 } else { 1 });
}
