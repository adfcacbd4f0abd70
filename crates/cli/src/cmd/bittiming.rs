//! `bittiming`: list valid BTR0/BTR1 settings for a clock and a bit rate
//! (`--rate`), or analyse given registers (`--btr0 --btr1`): the bit rate
//! they give, and with `--rate` their deviation from it (exit 1 when the
//! setting has problems).

use can_proto::timing::{BIT_RATE_TOLERANCE_PPM, BusTiming, TimingIssue};

/// The usual CAN bit rates, for naming the one a setting is closest to.
const STANDARD_RATES: [u32; 10] = [10_000, 20_000, 50_000, 83_333, 100_000, 125_000, 250_000, 500_000, 800_000, 1_000_000];

/// Arguments of `cancosim bittiming`.
#[derive(clap::Args)]
pub struct Args {
    /// CAN clock (the SJA1000's XTAL / our clk_i), e.g. 24MHz.
    #[arg(long, value_parser = super::parse_si)]
    clock: u32,
    /// Target bit rate, e.g. 500k: list settings for it, or with --btr0/--btr1 check them against it.
    #[arg(long, value_parser = super::parse_si, required_unless_present = "btr0")]
    rate: Option<u32>,
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
        let actual = t.bit_rate(a.clock as f64);
        let mut issues = t.validate(a.clock, a.rate.unwrap_or(actual.round() as u32));
        let mut standard = true;
        match a.rate {
            Some(rate) => println!(
                "deviation from {} kbit/s: {:+} ppm ({:+.2}%; at most ±{} ppm is accepted here)",
                rate as f64 / 1e3,
                t.error_ppm(a.clock, rate),
                t.error_ppm(a.clock, rate) as f64 / 1e4,
                BIT_RATE_TOLERANCE_PPM
            ),
            None => {
                // No target: the rate is what it is; name the nearest usual one.
                issues.retain(|i| !matches!(i, TimingIssue::BitRateOffTarget { .. }));
                let near = STANDARD_RATES
                    .into_iter()
                    .min_by_key(|&r| t.error_ppm(a.clock, r).unsigned_abs())
                    .expect("a non-empty list");
                let ppm = t.error_ppm(a.clock, near);
                standard = ppm.unsigned_abs() <= BIT_RATE_TOLERANCE_PPM;
                if standard {
                    println!("that is the standard {} kbit/s ({ppm:+} ppm)", near as f64 / 1e3);
                } else {
                    println!(
                        "not a standard rate: the nearest, {} kbit/s, is {:+.2}% away; nodes at {} kbit/s will not understand this one (check with --rate {})",
                        near as f64 / 1e3,
                        ppm as f64 / 1e4,
                        near as f64 / 1e3,
                        near
                    );
                }
            }
        }
        if issues.is_empty() {
            match a.rate {
                Some(rate) => println!("ok: valid for {} kbit/s at {} MHz", rate as f64 / 1e3, a.clock as f64 / 1e6),
                None if standard => println!("ok: a sound setting for {:.1} kbit/s at {} MHz", actual / 1e3, a.clock as f64 / 1e6),
                None => println!("otherwise sound: segments, SJW and sample point are valid for {:.1} kbit/s at {} MHz", actual / 1e3, a.clock as f64 / 1e6),
            }
            return Ok(0);
        }
        for i in &issues {
            println!("problem: {i}");
        }
        return Ok(1);
    }
    let rate = a.rate.expect("clap requires --rate without --btr0");
    let c = BusTiming::candidates(a.clock, rate);
    if c.is_empty() {
        println!("{}", BusTiming::for_bit_rate(a.clock, rate).unwrap_err());
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
