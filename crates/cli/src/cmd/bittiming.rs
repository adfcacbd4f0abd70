//! `bittiming`: list valid BTR0/BTR1 settings for a clock and a bit rate,
//! or check a given setting (exit 1 when it has problems).

use can_proto::timing::BusTiming;

/// Arguments of `cancosim bittiming`.
#[derive(clap::Args)]
pub struct Args {
    /// CAN clock (the SJA1000's XTAL / our clk_i), e.g. 24MHz.
    #[arg(long, value_parser = super::parse_si)]
    clock: u32,
    /// Target bit rate, e.g. 500k.
    #[arg(long, value_parser = super::parse_si)]
    rate: u32,
    /// BTR0 to check (with --btr1).
    #[arg(long, value_parser = super::parse_byte, requires = "btr1")]
    btr0: Option<u8>,
    /// BTR1 to check (with --btr0).
    #[arg(long, value_parser = super::parse_byte, requires = "btr0")]
    btr1: Option<u8>,
    /// How many candidates to list.
    #[arg(long, default_value_t = 10)]
    top: usize,
}

/// Runs the subcommand; returns the exit code.
pub fn run(a: Args) -> anyhow::Result<i32> {
    if let (Some(b0), Some(b1)) = (a.btr0, a.btr1) {
        let t = BusTiming::from_btr(b0, b1);
        println!(
            "BTR0=0x{b0:02X} BTR1=0x{b1:02X}: BRP={} SJW={} TSEG1={} TSEG2={} SAM={} -> {} tq of {} clocks, {:.1} kbit/s, sample point {:.1}%",
            t.brp, t.sjw, t.tseg1, t.tseg2, t.sam as u8, t.tq_per_bit(), t.clocks_per_tq(),
            t.bit_rate(a.clock as f64) / 1e3, t.sample_point() * 100.0
        );
        let issues = t.validate(a.clock, a.rate);
        if issues.is_empty() {
            println!("ok: valid for {} kbit/s at {} MHz", a.rate as f64 / 1e3, a.clock as f64 / 1e6);
            return Ok(0);
        }
        for i in &issues {
            println!("problem: {i}");
        }
        return Ok(1);
    }
    let c = BusTiming::candidates(a.clock, a.rate);
    if c.is_empty() {
        println!("{}", BusTiming::for_bit_rate(a.clock, a.rate).unwrap_err());
        return Ok(1);
    }
    println!("{:>6} {:>6} {:>4} {:>5} {:>5} {:>4} {:>12} {:>9} {:>7}", "BTR0", "BTR1", "BRP", "TSEG1", "TSEG2", "SJW", "kbit/s", "err ppm", "sample");
    for cand in c.iter().take(a.top) {
        let t = cand.timing;
        let (b0, b1) = t.to_btr();
        println!(
            "  0x{b0:02X}   0x{b1:02X} {:>4} {:>5} {:>5} {:>4} {:>12.3} {:>9} {:>6.1}%",
            t.brp, t.tseg1, t.tseg2, t.sjw, cand.bit_rate / 1e3, cand.error_ppm, cand.sample_point * 100.0
        );
    }
    Ok(0)
}
