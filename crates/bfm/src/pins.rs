//! Pin records: what one side drives during one host clock cycle.
//!
//! Names follow the opencores `can_top` Wishbone port list (`wb_*_i` seen
//! from the slave) and the Avalon-MM interface specification, seen from the
//! slave as a master drives it. All buses are 8 bits wide: the SJA1000 has
//! an 8-bit data bus and 8-bit register addresses.

/// Wishbone classic signals driven by the master (the DUT's `wb_*_i`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct WbMasterOut {
    /// `wb_cyc_i`: a bus cycle is in progress.
    pub cyc: bool,
    /// `wb_stb_i`: this cycle carries a valid transfer.
    pub stb: bool,
    /// `wb_we_i`: the transfer is a write.
    pub we: bool,
    /// `wb_adr_i[7:0]`: register address.
    pub adr: u8,
    /// `wb_dat_i[7:0]`: write data.
    pub dat: u8,
}

/// Wishbone classic signals driven by the slave (the DUT's `wb_*_o`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct WbSlaveOut {
    /// `wb_ack_o`: the transfer ends normally this cycle.
    pub ack: bool,
    /// `wb_dat_o[7:0]`: read data, valid with `ack` on a read.
    pub dat: u8,
    /// `err_o`: the transfer ends with an error (not on `can_top`; kept false).
    pub err: bool,
    /// `rty_o`: the slave asks the master to retry (not on `can_top`).
    pub rty: bool,
}

/// Avalon-MM slave-side signals as a master (or the interconnect) drives them.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct AvMasterOut {
    /// `address`: word address (the SJA1000 register number).
    pub address: u8,
    /// `chipselect`: the slave is selected.
    pub chipselect: bool,
    /// `read`: read request.
    pub read: bool,
    /// `write`: write request.
    pub write: bool,
    /// `writedata[7:0]`.
    pub writedata: u8,
    /// `begintransfer`: high in the first cycle of each transfer (optional).
    pub begintransfer: bool,
    /// `byteenable`: one lane on an 8-bit bus, so bit 0 only.
    pub byteenable: u8,
}

/// Avalon-MM slave outputs.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Hash)]
pub struct AvSlaveOut {
    /// `readdata[7:0]`.
    pub readdata: u8,
    /// `waitrequest`: the slave cannot accept the request this cycle.
    pub waitrequest: bool,
    /// `readdatavalid`: `readdata` carries the data of an earlier read
    /// (pipelined reads with variable latency).
    pub readdatavalid: bool,
}

impl WbMasterOut {
    /// True when a transfer is requested (`cyc & stb`).
    pub fn request(&self) -> bool {
        self.cyc && self.stb
    }
}

impl AvMasterOut {
    /// True when a transfer is requested (`chipselect & (read | write)`).
    pub fn request(&self) -> bool {
        self.chipselect && (self.read || self.write)
    }
}
