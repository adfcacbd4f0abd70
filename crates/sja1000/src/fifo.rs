//! The 64-byte receive FIFO (data sheet §6.4.9 and Figure 9): a circular
//! RAM; RBSA points at the first byte of the current message, RMC counts
//! the messages, the host sees the current message through the receive
//! buffer window and releases it with CMR.RRB.

/// Size of the RX FIFO RAM in bytes.
pub const FIFO_LEN: usize = 64;
const MAX_MSGS: usize = 32;

/// The receive FIFO.
#[derive(Clone, Debug)]
pub struct RxFifo {
    ram: [u8; FIFO_LEN],
    rbsa: u8,
    used: u8,
    // Lengths of the stored messages, oldest at `head`.
    lens: [u8; MAX_MSGS],
    head: u8,
    count: u8,
    // Messages lost to an overrun since the FIFO was last emptied.
    lost: u8,
}

impl Default for RxFifo {
    fn default() -> Self {
        RxFifo {
            ram: [0; FIFO_LEN],
            rbsa: 0,
            used: 0,
            lens: [0; MAX_MSGS],
            head: 0,
            count: 0,
            lost: 0,
        }
    }
}

impl RxFifo {
    /// Stores one message; false (and nothing stored) if it does not fit:
    /// the data overrun condition (§6.4.9: a partly written message is deleted).
    pub fn push(&mut self, msg: &[u8]) -> bool {
        let n = msg.len();
        if n == 0 {
            return false;
        }
        if n > FIFO_LEN - self.used as usize || self.count as usize >= MAX_MSGS {
            self.lost = self.lost.saturating_add(1);
            return false;
        }
        let start = self.rbsa as usize + self.used as usize;
        for (i, &b) in msg.iter().enumerate() {
            self.ram[(start + i) % FIFO_LEN] = b;
        }
        self.lens[(self.head as usize + self.count as usize) % MAX_MSGS] = n as u8;
        self.used += n as u8;
        self.count += 1;
        true
    }

    /// CMR.RRB: releases the current message; RBSA moves to the next one.
    /// Returns false if the FIFO was already empty.
    pub fn release(&mut self) -> bool {
        if self.count == 0 {
            return false;
        }
        let n = self.lens[self.head as usize];
        self.rbsa = ((self.rbsa as usize + n as usize) % FIFO_LEN) as u8;
        self.used -= n;
        self.head = ((self.head as usize + 1) % MAX_MSGS) as u8;
        self.count -= 1;
        true
    }

    /// Empties the FIFO (entering reset mode); RBSA keeps its value.
    pub fn clear(&mut self) {
        self.used = 0;
        self.count = 0;
        self.head = 0;
        self.lost = 0;
    }

    /// Messages lost to an overrun (a [`RxFifo::push`] that did not fit)
    /// since the FIFO was last emptied (reset mode, hardware reset). Not a
    /// register: a core that keeps an entry per lost message until its
    /// FIFO is emptied (waivers' `after = "data-overrun"`) is judged by it.
    pub fn lost(&self) -> u8 {
        self.lost
    }

    /// RMC: messages stored.
    pub fn rmc(&self) -> u8 {
        self.count
    }

    /// Bytes stored.
    pub fn used(&self) -> usize {
        self.used as usize
    }

    /// RBSA: RAM address of the current message.
    pub fn rbsa(&self) -> u8 {
        self.rbsa
    }

    /// Writes RBSA (reset mode only): the FIFO restarts empty at `v` (mod 64).
    pub fn set_rbsa(&mut self, v: u8) {
        self.clear();
        self.rbsa = v % FIFO_LEN as u8;
    }

    /// Byte `i` of the receive buffer window (RAM at RBSA + i, wrapping).
    pub fn window(&self, i: usize) -> u8 {
        self.ram[(self.rbsa as usize + i) % FIFO_LEN]
    }

    /// RAM byte at `addr` (0..64).
    pub fn ram(&self, addr: usize) -> u8 {
        self.ram[addr % FIFO_LEN]
    }

    /// Writes a RAM byte (reset mode access to addresses 32..95).
    pub fn set_ram(&mut self, addr: usize, v: u8) {
        self.ram[addr % FIFO_LEN] = v;
    }

    /// Hardware reset: RAM contents are undefined; they read 0 here.
    pub fn hard_reset(&mut self) {
        *self = RxFifo::default();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Messages go in back to back from RBSA and wrap at 64; RRB moves RBSA
    /// by the released message's length.
    #[test]
    fn wraps_and_releases() {
        let mut f = RxFifo::default();
        f.set_rbsa(60);
        assert!(f.push(&[1, 2, 3, 4, 5]));
        assert!(f.push(&[6, 7, 8]));
        assert_eq!(f.rmc(), 2);
        assert_eq!(f.ram(63), 4);
        assert_eq!(f.ram(0), 5);
        assert_eq!(f.window(0), 1);
        assert!(f.release());
        assert_eq!(f.rbsa(), 1);
        assert_eq!(f.window(0), 6);
        assert!(f.release());
        assert!(!f.release());
        assert_eq!(f.used(), 0);
    }

    /// A message that does not fit is dropped whole (overrun).
    #[test]
    fn overrun_drops_whole_message() {
        let mut f = RxFifo::default();
        for _ in 0..4 {
            assert!(f.push(&[0xAA; 13]));
        }
        assert_eq!(f.used(), 52);
        assert!(!f.push(&[0xBB; 13]));
        assert!(f.push(&[0xCC; 12]));
        assert_eq!(f.used(), 64);
        assert!(!f.push(&[0xDD; 3]));
        assert_eq!(f.rmc(), 5);
    }
}
