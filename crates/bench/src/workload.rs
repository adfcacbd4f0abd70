//! The self-test loopback workload, one definition for every simulator.
//!
//! A lone PeliCAN node in self test mode (MOD.STM) sends frames to itself
//! with the self reception request (CMR.SRR), so no second node is needed
//! and the bus is the node's own `tx_o` fed back to `rx_i`. The same
//! sequence is written three more times, kept in step with this file:
//! `tb/bench/harness.cpp` (raw C++ Verilator), `tb/bench/bench_tb.v`
//! (Icarus), and here for the golden model and the co-simulation.
//!
//! Sequence: hardware reset; CR.RR; CDR = 0x80 (PeliCAN); MOD.RM; BTR0/BTR1
//! = 0x41/0x25 (40 clocks per bit at 24 MHz); ACR = 0, AMR = 0xFF (accept
//! all); IER = RIE|TIE; MOD = STM (operating); 12 bit times of idle. Per
//! frame: the 11 TX bytes (standard frame, DLC 8), CMR = SRR, then wait for
//! `irq_on` low, let [`SETTLE_BITS`] pass and read IR until both RI and TI were seen (one bit time
//! between tries), read SR (TCS and RBS must be set), read back the 11 RX
//! bytes and compare, CMR = RRB.

use regmap::peli;

/// CAN clocks per bit with BTR0/BTR1 = 0x41/0x25.
pub const CLOCKS_PER_BIT: u64 = 40;
/// Bit times between `irq_on` going low and the IR read. RI and TI of a
/// self-received frame come within a bit of each other, in an order that
/// is the implementation's business (our RTL sets RI a few clocks after
/// TI, the golden model before it); reading IR in between would make the
/// lockstep comparison of the co-simulation stop on that difference.
pub const SETTLE_BITS: u64 = 2;
/// Bit times to wait for an interrupt before giving up.
pub const IRQ_TIMEOUT_BITS: u64 = 200;

/// The shared frame generator: xorshift32 (13, 17, 5), seeded with the
/// low 32 bits of the seed (0 becomes 1). Simple enough to write the same
/// way in C++ and Verilog.
#[derive(Clone, Debug)]
pub struct XorShift32(u32);

impl XorShift32 {
    /// A generator for `seed`.
    pub fn new(seed: u64) -> Self {
        let s = seed as u32;
        XorShift32(if s == 0 { 1 } else { s })
    }

    /// Next value.
    pub fn next_u32(&mut self) -> u32 {
        let mut x = self.0;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.0 = x;
        x
    }

    /// The next frame's 11 TX buffer bytes (frame info, ID1, ID2, 8 data
    /// bytes): standard frame, random 11-bit ID, DLC 8, random data.
    pub fn next_frame(&mut self) -> [u8; 11] {
        let id = self.next_u32() & 0x7FF;
        let mut b = [0u8; 11];
        b[0] = 0x08;
        b[1] = (id >> 3) as u8;
        b[2] = ((id & 7) << 5) as u8;
        for d in &mut b[3..] {
            *d = self.next_u32() as u8;
        }
        b
    }
}

/// A host that can play the workload: register access plus waiting.
pub trait SelfTestHost {
    /// Why an access or a wait failed.
    type Error;
    /// Register write.
    fn write(&mut self, addr: u8, data: u8) -> Result<(), Self::Error>;
    /// Register read.
    fn read(&mut self, addr: u8) -> Result<u8, Self::Error>;
    /// Lets `bits` bit times pass.
    fn idle_bits(&mut self, bits: u64) -> Result<(), Self::Error>;
    /// Waits until `irq_on` is low (an interrupt is pending), at most
    /// [`IRQ_TIMEOUT_BITS`].
    fn wait_irq(&mut self) -> Result<(), Self::Error>;
}

/// What one run of the workload did.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SelfTestOutcome {
    /// Frames sent and received back.
    pub frames: u64,
    /// Read-back mismatches (SR without TCS/RBS, RX byte differing from
    /// the TX byte); 0 when the DUT works.
    pub errors: u64,
}

/// The configuration part of the sequence (after the hardware reset).
pub fn configure<H: SelfTestHost>(h: &mut H) -> Result<(), H::Error> {
    h.write(peli::MOD, 0x01)?; // BasicCAN CR.RR (same bit as MOD.RM)
    h.write(peli::CDR, 0x80)?;
    h.write(peli::MOD, peli::r#mod::RM)?;
    h.write(peli::BTR0, 0x41)?;
    h.write(peli::BTR1, 0x25)?;
    for a in 16..20 {
        h.write(a, 0x00)?;
    }
    for a in 20..24 {
        h.write(a, 0xFF)?;
    }
    h.write(peli::IER, peli::ier::RIE | peli::ier::TIE)?;
    h.write(peli::MOD, peli::r#mod::STM)?;
    h.idle_bits(12)
}

/// Configures, then sends `frames` frames from the generator seeded with `seed`.
pub fn run<H: SelfTestHost>(
    h: &mut H,
    frames: u64,
    seed: u64,
) -> Result<SelfTestOutcome, H::Error> {
    configure(h)?;
    let mut rng = XorShift32::new(seed);
    let mut out = SelfTestOutcome::default();
    for _ in 0..frames {
        let tx = rng.next_frame();
        for (i, &b) in tx.iter().enumerate() {
            h.write(16 + i as u8, b)?;
        }
        h.write(peli::CMR, peli::cmr::SRR)?;
        let mut ir = 0u8;
        loop {
            h.wait_irq()?;
            h.idle_bits(SETTLE_BITS)?;
            ir |= h.read(peli::IR)?;
            if ir & (peli::ir::RI | peli::ir::TI) == peli::ir::RI | peli::ir::TI {
                break;
            }
            h.idle_bits(1)?;
        }
        let sr = h.read(peli::SR)?;
        if sr & (peli::sr::TCS | peli::sr::RBS) != peli::sr::TCS | peli::sr::RBS {
            out.errors += 1;
        }
        for (i, &b) in tx.iter().enumerate() {
            // ID2 of a standard frame: ID.20..18 and RTR; the low nibble is not defined.
            let mask = if i == 2 { 0xF0 } else { 0xFF };
            if h.read(16 + i as u8)? & mask != b & mask {
                out.errors += 1;
            }
        }
        h.write(peli::CMR, peli::cmr::RRB)?;
        out.frames += 1;
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn xorshift_matches_the_published_sequence_and_never_sticks_at_zero() {
        // Marsaglia's xorshift32 (13, 17, 5) from state 1.
        let mut r = XorShift32::new(1);
        assert_eq!(r.next_u32(), 270_369);
        assert_eq!(r.next_u32(), 67_634_689);
        let mut z = XorShift32::new(0);
        assert_ne!(z.next_u32(), 0);
        // Only the low 32 bits of the seed count (the C++ and Verilog sides use 32 bits).
        assert_eq!(
            XorShift32::new(1 << 32).next_u32(),
            XorShift32::new(1).next_u32()
        );
    }

    #[test]
    fn frames_are_standard_dlc8_with_the_id_split_over_id1_id2() {
        let mut r = XorShift32::new(7);
        for _ in 0..100 {
            let f = r.next_frame();
            assert_eq!(f[0], 0x08);
            assert_eq!(f[2] & 0x1F, 0);
        }
    }
}
