//! `regress --coverage`: a Verilated core built with coverage writes its
//! counters per run; they are merged into an lcov .info and an HTML report,
//! and the per-file summary is printed. A small probe core keeps the build
//! short: one line every host write executes, one no scenario reaches.

use std::process::Command;

const PROBE: &str = r#"// can_top port list; a line every write runs, a line none does.
module cov_probe (
    input            wb_clk_i,
    input            wb_rst_i,
    input      [7:0] wb_dat_i,
    output reg [7:0] wb_dat_o,
    input            wb_cyc_i,
    input            wb_stb_i,
    input            wb_we_i,
    input      [7:0] wb_adr_i,
    output reg       wb_ack_o,
    input            clk_i,
    input            rx_i,
    output           tx_o,
    output           bus_off_on,
    output           irq_on,
    output           clkout_o
);
    reg [7:0] mem [0:31];
    reg [7:0] never;
    always @(posedge wb_clk_i) begin
        if (wb_rst_i) begin
            wb_ack_o <= 1'b0;
            wb_dat_o <= 8'h00;
            never    <= 8'h00;
        end else begin
            wb_ack_o <= wb_cyc_i & wb_stb_i & ~wb_ack_o;
            if (wb_cyc_i & wb_stb_i & ~wb_ack_o & wb_we_i) begin
                mem[wb_adr_i[4:0]] <= wb_dat_i;
                if (wb_adr_i == 8'hEE) begin
                    never <= wb_dat_i;
                end
            end
            if (wb_cyc_i & wb_stb_i & ~wb_ack_o & ~wb_we_i) wb_dat_o <= mem[wb_adr_i[4:0]] ^ never;
        end
    end
    assign tx_o       = 1'b1;
    assign irq_on     = 1'b1;
    assign bus_off_on = 1'b1;
    assign clkout_o   = clk_i;
endmodule
"#;

/// Line number (1-based) of the line of `text` that contains `needle`.
fn line_of(text: &str, needle: &str) -> u32 {
    text.lines().position(|l| l.contains(needle)).unwrap_or_else(|| panic!("no line with {needle}")) as u32 + 1
}

/// lcov `DA` count of `line` in the record of the file ending in `file`.
fn da(info: &str, file: &str, line: u32) -> Option<u64> {
    let rec = info.split("end_of_record").find(|r| r.lines().any(|l| l.starts_with("SF:") && l.ends_with(file)))?;
    rec.lines().filter_map(|l| l.strip_prefix("DA:")).find_map(|d| {
        let (n, c) = d.split_once(',')?;
        (n.parse::<u32>().ok()? == line).then(|| c.parse().ok())?
    })
}

#[test]
fn a_coverage_run_writes_lcov_and_html_where_the_live_line_is_hit_and_the_dead_one_not() {
    let scratch = tempfile::tempdir().unwrap();
    let (core, cache, out) = (scratch.path().join("core"), scratch.path().join("cache"), scratch.path().join("cov"));
    std::fs::create_dir_all(&core).unwrap();
    std::fs::write(core.join("cov_probe.v"), PROBE).unwrap();
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let o = Command::new(env!("CARGO_BIN_EXE_cancosim"))
        .args(["regress", "tb/de2-pelican-selftest.toml", "--top", "cov_probe", "--profile", "tb/fixtures/at-ack.toml", "--external"])
        .arg(format!("probe={}", core.display()))
        .arg("--coverage")
        .arg(&out)
        .current_dir(&root)
        .env("COSIM_CACHE_DIR", &cache)
        .output()
        .expect("cancosim runs");
    let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    // The probe is no CAN controller: the run diverges (exit 1), not an error (2).
    assert_eq!(o.status.code(), Some(1), "{all}");
    let dut = out.join("probe");
    let info = std::fs::read_to_string(dut.join("coverage.info")).unwrap_or_else(|e| panic!("no coverage.info ({e}):\n{all}"));
    assert!(dut.join("html/index.html").is_file(), "genhtml's report:\n{all}");
    assert!(out.join("dat/probe/de2-pelican-selftest.dat").is_file(), "the run's own counters");
    let live = line_of(PROBE, "mem[wb_adr_i[4:0]] <= wb_dat_i;");
    let dead = line_of(PROBE, "never <= wb_dat_i;");
    assert!(da(&info, "cov_probe.v", live).is_some_and(|n| n > 0), "line {live} runs on every host write:\n{info}");
    assert_eq!(da(&info, "cov_probe.v", dead), Some(0), "line {dead} is never reached:\n{info}");
    // The summary: the file and the total, with the three kinds.
    let table = all.lines().skip_while(|l| !l.starts_with("code coverage on probe")).collect::<Vec<_>>().join("\n");
    assert!(table.contains("line") && table.contains("toggle") && table.contains("branch"), "{all}");
    let row = table.lines().find(|l| l.contains("cov_probe.v")).unwrap_or_else(|| panic!("a row for the probe:\n{all}"));
    assert!(!row.contains("100.0% (0/0)") && row.contains('%'), "{row}");
    assert!(table.lines().any(|l| l.starts_with("total")), "{all}");
}

#[test]
fn coverage_of_the_golden_model_is_said_to_be_none() {
    let scratch = tempfile::tempdir().unwrap();
    let root = std::path::PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let o = Command::new(env!("CARGO_BIN_EXE_cancosim"))
        .args(["regress", "tb/pelican-frame-kinds.toml", "--dut", "model", "--coverage"])
        .arg(scratch.path())
        .current_dir(&root)
        .output()
        .expect("cancosim runs");
    let all = format!("{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    assert_eq!(o.status.code(), Some(0), "{all}");
    assert!(all.contains("code coverage on model: none (the golden model is not Verilated)"), "{all}");
    // Functional coverage is printed with --coverage, holes first.
    assert!(all.contains("functional coverage on model"), "{all}");
    assert!(all.contains("holes in "), "{all}");
}
