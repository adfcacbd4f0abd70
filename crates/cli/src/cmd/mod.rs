//! One module per subcommand.
pub mod bench;
pub mod bittiming;
pub mod campaign;
pub mod decode;
pub mod diagnose;
pub mod profile;
pub mod regress;
pub mod run;
pub mod formats;
pub mod generate;
pub mod gitcore;
pub mod mutate;
pub mod reference;

/// Parses "24MHz", "16e6", "500k", "125000", "1M" into a number.
pub fn parse_si(s: &str) -> Result<u32, String> {
    let t = s.trim().to_ascii_lowercase();
    let t = t.trim_end_matches("hz").trim_end_matches("bps").trim_end_matches("bit/s");
    let (num, mult) = match t.chars().last() {
        Some('k') => (&t[..t.len() - 1], 1e3),
        Some('m') => (&t[..t.len() - 1], 1e6),
        _ => (t, 1.0),
    };
    let v: f64 = num.trim().parse().map_err(|_| format!("'{s}' is not a number like 24MHz, 500k or 125000"))?;
    let v = v * mult;
    if !(1.0..=4.0e9).contains(&v) {
        return Err(format!("'{s}' is out of range"));
    }
    Ok(v.round() as u32)
}

/// Parses "0x41", "65" or "0b0100_0001" into a byte.
pub fn parse_byte(s: &str) -> Result<u8, String> {
    let t = s.trim().replace('_', "");
    let r = if let Some(h) = t.strip_prefix("0x").or_else(|| t.strip_prefix("0X")) {
        u8::from_str_radix(h, 16)
    } else if let Some(b) = t.strip_prefix("0b") {
        u8::from_str_radix(b, 2)
    } else {
        t.parse()
    };
    r.map_err(|_| format!("'{s}' is not a byte (0..255, 0x.. or 0b..)"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn si_units() {
        assert_eq!(parse_si("24MHz"), Ok(24_000_000));
        assert_eq!(parse_si("500k"), Ok(500_000));
        assert_eq!(parse_si("117.6k"), Ok(117_600));
        assert!(parse_si("fast").is_err());
        assert_eq!(parse_byte("0x41"), Ok(0x41));
        assert_eq!(parse_byte("0b0010_0101"), Ok(0x25));
        assert!(parse_byte("0x141").is_err());
    }
}
