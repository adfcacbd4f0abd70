//! The tables. One macro invocation per view builds, from one list, both the
//! `Register` statics and the typed constants (`peli::SR`, `peli::sr::TBS`,
//! `peli::sr::lsb::TBS`, `peli::len::RXFIFO`), so they cannot disagree.

use crate::{AddrRow, Register, RegisterView, Target};

/// Mask of a field of `width` bits at `lsb`.
pub(crate) const fn mask(lsb: u8, width: u8) -> u8 {
    (((1u16 << width) - 1) << lsb) as u8
}

macro_rules! or_default {
    ($d:expr;) => {
        $d
    };
    ($d:expr; $v:expr) => {
        $v
    };
}

/// Emits the field module of one register: a mask constant per field, an
/// `lsb` sub-module, and `FIELDS` for the table. `use a::b` re-exports the
/// field module of a register with the same layout instead.
macro_rules! field_mod {
    ($reg:ident, $lname:ident, use $($p:ident)::+) => {
        #[doc = concat!("Fields of `", stringify!($reg), "` (same layout as `", stringify!($($p)::+), "`).")]
        pub use $($p)::+ as $lname;
    };
    ($reg:ident, $lname:ident, $( $fname:ident @ $flsb:literal $(+ $fw:literal)? : $fdoc:literal ),* $(,)?) => {
        #[doc = concat!("Fields of `", stringify!($reg), "`: in-register masks; bit positions in `lsb`.")]
        pub mod $lname {
            $(
                #[doc = concat!("`", stringify!($fname), "` mask: ", $fdoc)]
                pub const $fname: u8 = crate::map::mask($flsb, or_default!(1; $($fw)?));
            )*
            /// Least significant bit of each field.
            pub mod lsb {
                $(
                    #[doc = concat!("`", stringify!($fname), "` lsb")]
                    pub const $fname: u8 = $flsb;
                )*
            }
            /// The fields as table entries.
            pub const FIELDS: &[crate::FieldDef] = &[
                $( crate::FieldDef {
                    name: stringify!($fname),
                    lsb: $flsb,
                    width: or_default!(1; $($fw)?),
                    meaning: $fdoc,
                } ),*
            ];
        }
    };
}

macro_rules! view_map {
    (
        $(#[$meta:meta])*
        pub mod $modname:ident = $mode:expr;
        $(
            $name:ident / $lname:ident @ $addr:literal $(x $len:literal)? : $title:literal,
            hw $hw:literal, rm $rm:literal $(, note $note:literal)?
            { $($fields:tt)* }
        )*
    ) => {
        $(#[$meta])*
        pub mod $modname {
            $(
                #[doc = concat!("`", stringify!($name), "` ", $title, ": address ", stringify!($addr))]
                pub const $name: u8 = $addr;
            )*

            /// Number of consecutive addresses each register spans.
            pub mod len {
                $(
                    #[doc = concat!("`", stringify!($name), "` length")]
                    pub const $name: u8 = or_default!(1; $($len)?);
                )*
            }

            $( field_mod!($name, $lname, $($fields)*); )*

            /// The register definitions, one static each.
            pub mod def {
                $(
                    #[doc = concat!("`", stringify!($name), "` ", $title)]
                    pub static $name: crate::Register = crate::Register {
                        name: stringify!($name),
                        title: $title,
                        mode: $mode,
                        addr: $addr,
                        len: or_default!(1; $($len)?),
                        reset_hw: crate::ResetValue::parse($hw),
                        reset_rm: crate::ResetValue::parse($rm),
                        fields: super::$lname::FIELDS,
                        note: or_default!(""; $($note)?),
                    };
                )*
            }

            /// Every register of this view, in address order.
            pub(crate) static REGISTERS: &[&crate::Register] = &[ $( &def::$name ),* ];
        }
    };
}

view_map! {
    /// PeliCAN view (`CDR.7 = 1`): addresses, field masks, lengths and
    /// definitions. Data sheet section 6.4, Tables 5 (addresses) and 6
    /// (reset values; `hw` = hardware reset, `rm` = reset mode entered by
    /// setting MOD.RM or by bus-off).
    pub mod peli = crate::Mode::PeliCan;

    MOD / r#mod @ 0 : "mode register",
        hw "0000_0001", rm "0000_xxx1",
        note "LOM, STM and AFM are writable in reset mode only; SM cannot be set in reset mode. \
              The thesis table (seed 000 annexe 1) shows only the reset-mode-entry column."
    {
        RM @ 0 : "reset mode: 1 = reset mode, 0 = operating mode",
        LOM @ 1 : "listen only mode",
        STM @ 2 : "self test mode: a transmission succeeds without acknowledge",
        AFM @ 3 : "acceptance filter mode: 1 = single 32-bit filter, 0 = dual filter",
        SM @ 4 : "sleep mode",
    }

    CMR / cmr @ 1 : "command register",
        hw "0000_0000", rm "0000_0000",
        note "write only; reads 00H in PeliCAN (the thesis table's FFH is the BasicCAN value)"
    {
        TR @ 0 : "transmission request",
        AT @ 1 : "abort transmission",
        RRB @ 2 : "release receive buffer",
        CDO @ 3 : "clear data overrun",
        SRR @ 4 : "self reception request",
    }

    SR / sr @ 2 : "status register",
        hw "0011_1100", rm "xx11_x100",
        note "read only. PeliCAN reset sets TS and RS (waiting for bus-free); the thesis table \
              gives TS = RS = 0, which is the BasicCAN table (data sheet Table 2)."
    {
        RBS @ 0 : "receive buffer status: 1 = message(s) in the RXFIFO",
        DOS @ 1 : "data overrun status: a message was lost, RXFIFO full",
        TBS @ 2 : "transmit buffer status: 1 = released, the CPU may write the TX buffer",
        TCS @ 3 : "transmission complete status",
        RS @ 4 : "receive status: receiving a message",
        TS @ 5 : "transmit status: transmitting a message",
        ES @ 6 : "error status: an error counter reached EWLR",
        BS @ 7 : "bus status: 1 = bus-off",
    }

    IR / ir @ 3 : "interrupt register",
        hw "0000_0000", rm "xxx0_0x00",
        note "read only; a read clears every bit except RI (RI follows RBS and is cleared by RRB)"
    {
        RI @ 0 : "receive interrupt",
        TI @ 1 : "transmit interrupt",
        EI @ 2 : "error warning interrupt: ES or BS changed",
        DOI @ 3 : "data overrun interrupt",
        WUI @ 4 : "wake-up interrupt",
        EPI @ 5 : "error passive interrupt",
        ALI @ 6 : "arbitration lost interrupt",
        BEI @ 7 : "bus error interrupt",
    }

    IER / ier @ 4 : "interrupt enable register",
        hw "xxxx_xxxx", rm "xxxx_xxxx"
    {
        RIE @ 0 : "receive interrupt enable",
        TIE @ 1 : "transmit interrupt enable",
        EIE @ 2 : "error warning interrupt enable",
        DOIE @ 3 : "data overrun interrupt enable",
        WUIE @ 4 : "wake-up interrupt enable",
        EPIE @ 5 : "error passive interrupt enable",
        ALIE @ 6 : "arbitration lost interrupt enable",
        BEIE @ 7 : "bus error interrupt enable",
    }

    BTR0 / btr0 @ 6 : "bus timing register 0",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "writable in reset mode only"
    {
        BRP @ 0 + 6 : "baud rate prescaler: tscl = 2 * tclk * (BRP + 1)",
        SJW @ 6 + 2 : "synchronisation jump width: tSJW = tscl * (SJW + 1)",
    }

    BTR1 / btr1 @ 7 : "bus timing register 1",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "writable in reset mode only"
    {
        TSEG1 @ 0 + 4 : "time segment 1: tTSEG1 = tscl * (TSEG1 + 1)",
        TSEG2 @ 4 + 3 : "time segment 2: tTSEG2 = tscl * (TSEG2 + 1)",
        SAM @ 7 : "sampling: 1 = three samples (low/medium speed buses), 0 = one sample",
    }

    OCR / ocr @ 8 : "output control register",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "writable in reset mode only"
    {
        OCMODE @ 0 + 2 : "output mode: 0 bi-phase, 1 test, 2 normal, 3 clock",
        OCPOL0 @ 2 : "TX0 output polarity",
        OCTN0 @ 3 : "TX0 pull-down transistor enable",
        OCTP0 @ 4 : "TX0 pull-up transistor enable",
        OCPOL1 @ 5 : "TX1 output polarity",
        OCTN1 @ 6 : "TX1 pull-down transistor enable",
        OCTP1 @ 7 : "TX1 pull-up transistor enable",
    }

    TEST / test @ 9 : "test register",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "production test only: the data sheet warns that using it in normal operation \
              may cause undesired behaviour (missing from the thesis table)"
    {}

    ALC / alc @ 11 : "arbitration lost capture register",
        hw "0000_0000", rm "xxxx_xxxx",
        note "read only; captured on arbitration loss and frozen until read"
    {
        BITNO @ 0 + 5 : "bit number at which arbitration was lost (0 = ID.28)",
    }

    ECC / ecc @ 12 : "error code capture register",
        hw "0000_0000", rm "xxxx_xxxx",
        note "read only; captured on a bus error and frozen until read"
    {
        SEG @ 0 + 5 : "segment code: frame position of the error",
        DIR @ 5 : "direction: 1 = error during reception, 0 = during transmission",
        ERRC @ 6 + 2 : "error code: 0 bit, 1 form, 2 stuff, 3 other",
    }

    EWLR / ewlr @ 13 : "error warning limit register",
        hw "0110_0000", rm "xxxx_xxxx",
        note "writable in reset mode only; 96 after hardware reset"
    {}

    RXERR / rxerr @ 14 : "RX error counter register",
        hw "0000_0000", rm "xxxx_xxxx",
        note "writable in reset mode only; bus-off clears it"
    {}

    TXERR / txerr @ 15 : "TX error counter register",
        hw "0000_0000", rm "xxxx_xxxx",
        note "writable in reset mode only; writing 255 forces a bus-off that happens when reset \
              mode is left (until then it reads 255, status and interrupts unchanged), as one by \
              errors; bus-off sets it to 127, it then counts bus-free occurrences down during \
              recovery"
    {}

    // Addresses 16..28 have three meanings: RX buffer (operating read), TX
    // buffer (operating write), acceptance filter (reset mode, 16..23 only).
    // The thesis table lists the TX frame info at 16 as unreadable and
    // misses that a read of 16 returns the RX frame info.
    RXFI / rxfi @ 16 : "RX frame information",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "operating mode read; first byte of the receive buffer window"
    {
        DLC @ 0 + 4 : "data length code (may exceed 8; at most 8 bytes follow)",
        RTR @ 6 : "remote transmission request",
        FF @ 7 : "frame format: 1 = extended (EFF), 0 = standard (SFF)",
    }

    ACR0 / acr0 @ 16 : "acceptance code register 0",
        hw "xxxx_xxxx", rm "xxxx_xxxx", note "reset mode only" {}
    TXFI / txfi @ 16 : "TX frame information",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "operating mode write; reads back at TXBUF (96)"
    { use crate::map::peli::rxfi }

    RXB / rxb @ 17 x 12 : "receive buffer: SFF ID1 ID2 data1..8 or EFF ID1..ID4 data1..8",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "operating mode read; the window onto the current RXFIFO message"
    {}
    ACR1 / acr1 @ 17 : "acceptance code register 1",
        hw "xxxx_xxxx", rm "xxxx_xxxx", note "reset mode only" {}
    TXB / txb @ 17 x 12 : "transmit buffer: SFF ID1 ID2 data1..8 or EFF ID1..ID4 data1..8",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "operating mode write, only while SR.TBS = 1"
    {}
    ACR2 / acr2 @ 18 : "acceptance code register 2",
        hw "xxxx_xxxx", rm "xxxx_xxxx", note "reset mode only" {}
    ACR3 / acr3 @ 19 : "acceptance code register 3",
        hw "xxxx_xxxx", rm "xxxx_xxxx", note "reset mode only" {}
    AMR0 / amr0 @ 20 : "acceptance mask register 0",
        hw "xxxx_xxxx", rm "xxxx_xxxx", note "reset mode only; 1 = don't care" {}
    AMR1 / amr1 @ 21 : "acceptance mask register 1",
        hw "xxxx_xxxx", rm "xxxx_xxxx", note "reset mode only; 1 = don't care" {}
    AMR2 / amr2 @ 22 : "acceptance mask register 2",
        hw "xxxx_xxxx", rm "xxxx_xxxx", note "reset mode only; 1 = don't care" {}
    AMR3 / amr3 @ 23 : "acceptance mask register 3",
        hw "xxxx_xxxx", rm "xxxx_xxxx", note "reset mode only; 1 = don't care" {}

    RMC / rmc @ 29 : "RX message counter",
        hw "0000_0000", rm "0000_0000",
        note "read only; messages in the RXFIFO"
    {
        RMC @ 0 + 5 : "number of messages in the RXFIFO",
    }

    RBSA / rbsa @ 30 : "RX buffer start address register",
        hw "0000_0000", rm "xxxx_xxxx",
        note "writable in reset mode only; internal RAM address of the current message"
    {
        RBSA @ 0 + 6 : "RXFIFO address of the first byte of the current message",
    }

    CDR / cdr @ 31 : "clock divider register",
        hw "0000_0000", rm "xxxx_xxxx",
        note "CAN mode, CBP, RXINTEN and clock off are writable in reset mode only; CDR.4 reads 0. \
              Hardware reset value 00H in Intel mode, 05H in Motorola mode."
    {
        CD @ 0 + 3 : "CLKOUT divider: fosc/2, /4, /6, /8, /10, /12, /14; 7 = fosc",
        CLKOFF @ 3 : "clock off: 1 = CLKOUT disabled",
        RXINTEN @ 5 : "TX1 output used as receive interrupt output",
        CBP @ 6 : "comparator bypass of the RX input comparator",
        CANMODE @ 7 : "CAN mode: 1 = PeliCAN, 0 = BasicCAN",
    }

    RXFIFO / rxfifo @ 32 x 64 : "internal RAM: 64-byte RX FIFO (RAM 0..63)",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "read in both modes, written in reset mode only"
    {}

    TXBUF / txbuf @ 96 x 13 : "internal RAM: TX buffer read-back (RAM 64..76)",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "read in both modes, written in reset mode only"
    {}

    RAMFREE / ramfree @ 109 x 3 : "internal RAM: free bytes (RAM 77..79)",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "read in both modes, written in reset mode only"
    {}
}

view_map! {
    /// BasicCAN view (`CDR.7 = 0`, PCA82C200 compatible): addresses, field
    /// masks, lengths and definitions. Data sheet section 6.3, Tables 1
    /// (addresses) and 2 (reset values; `hw` = hardware reset, `rm` = reset
    /// request CR.RR set by software or bus-off).
    pub mod basic = crate::Mode::BasicCan;

    CR / cr @ 0 : "control register",
        hw "0x1x_xxx1", rm "0x1x_xxx1",
        note "CR.7 must be written 0; CR.6 (the PCA82C200 sync bit) keeps the value written \
              and does nothing; CR.5 reads 1"
    {
        RR @ 0 : "reset request: 1 = reset mode, 0 = operating mode",
        RIE @ 1 : "receive interrupt enable",
        TIE @ 2 : "transmit interrupt enable",
        EIE @ 3 : "error interrupt enable",
        OIE @ 4 : "overrun interrupt enable",
    }

    CMR / cmr @ 1 : "command register",
        hw "1111_1111", rm "1111_1111",
        note "write only; reads FFH"
    {
        TR @ 0 : "transmission request",
        AT @ 1 : "abort transmission",
        RRB @ 2 : "release receive buffer",
        CDO @ 3 : "clear data overrun",
        GTS @ 4 : "go to sleep",
    }

    SR / sr @ 2 : "status register",
        hw "0000_1100", rm "xx00_x100",
        note "read only"
    { use crate::map::peli::sr }

    IR / ir @ 3 : "interrupt register",
        hw "1110_0000", rm "1110_0x00",
        note "read only; IR.7..5 read 1; a read clears the interrupt flags"
    {
        RI @ 0 : "receive interrupt",
        TI @ 1 : "transmit interrupt",
        EI @ 2 : "error interrupt: ES or BS changed",
        DOI @ 3 : "data overrun interrupt",
        WUI @ 4 : "wake-up interrupt",
    }

    ACR / acr @ 4 : "acceptance code register",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "reset mode only; reads FFH in operating mode (the thesis table has it right here)"
    {}
    AMR / amr @ 5 : "acceptance mask register",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "reset mode only; reads FFH in operating mode; 1 = don't care"
    {}

    BTR0 / btr0 @ 6 : "bus timing register 0",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "reset mode only; reads FFH in operating mode (the thesis table says readable: \
              that is PeliCAN)"
    { use crate::map::peli::btr0 }
    BTR1 / btr1 @ 7 : "bus timing register 1",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "reset mode only; reads FFH in operating mode"
    { use crate::map::peli::btr1 }
    OCR / ocr @ 8 : "output control register",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "reset mode only; reads FFH in operating mode"
    { use crate::map::peli::ocr }
    TEST / test @ 9 : "test register",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "production test only"
    {}

    TXID1 / txid1 @ 10 : "TX identifier 1",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "operating mode only; reads FFH in reset mode"
    {
        ID @ 0 + 8 : "identifier bits ID.10..ID.3",
    }
    TXID2 / txid2 @ 11 : "TX identifier 2, RTR and DLC",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "operating mode only; reads FFH in reset mode"
    {
        DLC @ 0 + 4 : "data length code",
        RTR @ 4 : "remote transmission request",
        ID @ 5 + 3 : "identifier bits ID.2..ID.0",
    }
    TXDATA / txdata @ 12 x 8 : "TX data bytes 1..8",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "operating mode only; reads FFH in reset mode"
    {}

    RXID1 / rxid1 @ 20 : "RX identifier 1",
        hw "xxxx_xxxx", rm "xxxx_xxxx",
        note "the window onto the current RXFIFO message"
    { use crate::map::basic::txid1 }
    RXID2 / rxid2 @ 21 : "RX identifier 2, RTR and DLC",
        hw "xxxx_xxxx", rm "xxxx_xxxx"
    { use crate::map::basic::txid2 }
    RXDATA / rxdata @ 22 x 8 : "RX data bytes 1..8",
        hw "xxxx_xxxx", rm "xxxx_xxxx"
    {}

    CDR / cdr @ 31 : "clock divider register",
        hw "0000_0000", rm "xxxx_xxxx",
        note "CAN mode, CBP, RXINTEN and clock off are writable in reset mode only"
    { use crate::map::peli::cdr }
}

// ---------------------------------------------------------------------------
// Address allocation tables (data sheet Table 5 for PeliCAN, Table 1 for
// BasicCAN): for each address range, what an operating/reset read/write does.

const fn rd(r: &'static Register) -> RegisterView {
    RegisterView { target: Target::Register(r), write_mask: 0xFF, note: "" }
}
const fn wr(r: &'static Register, write_mask: u8) -> RegisterView {
    RegisterView { target: Target::Register(r), write_mask, note: "" }
}
const fn k(c: u8) -> RegisterView {
    RegisterView { target: Target::Constant(c), write_mask: 0, note: "" }
}
const NOP: RegisterView = RegisterView { target: Target::Nothing, write_mask: 0, note: "" };
const fn n(mut v: RegisterView, note: &'static str) -> RegisterView {
    v.note = note;
    v
}
const fn row(
    first: u8,
    last: u8,
    op_read: RegisterView,
    op_write: RegisterView,
    rst_read: RegisterView,
    rst_write: RegisterView,
) -> AddrRow {
    AddrRow { first, last, op_read, op_write, rst_read, rst_write }
}
/// Readable in both modes, writable in reset mode only.
const fn cfg(first: u8, last: u8, r: &'static Register) -> AddrRow {
    row(first, last, rd(r), n(NOP, "writable in reset mode only"), rd(r), wr(r, 0xFF))
}
/// Read only in both modes.
const fn ro(first: u8, last: u8, r: &'static Register) -> AddrRow {
    row(first, last, rd(r), NOP, rd(r), NOP)
}
/// Reserved: reads `c`, writes ignored.
const fn rsv(first: u8, last: u8, c: u8) -> AddrRow {
    row(first, last, k(c), NOP, k(c), NOP)
}

const IR_READ_PELI: &str = "read clears every bit except RI";
const IR_READ_BASIC: &str = "read clears the interrupt flags";

pub(crate) static PELI_TABLE: &[AddrRow] = {
    use peli::def::*;
    &[
        row(0, 0, rd(&MOD), n(wr(&MOD, 0x11), "LOM/STM/AFM unchanged in operating mode"), rd(&MOD),
            n(wr(&MOD, 0x0F), "SM cannot be set in reset mode")),
        row(1, 1, k(0x00), wr(&CMR, 0x1F), k(0x00), wr(&CMR, 0x1F)),
        ro(2, 2, &SR),
        row(3, 3, n(rd(&IR), IR_READ_PELI), NOP, n(rd(&IR), IR_READ_PELI), NOP),
        row(4, 4, rd(&IER), wr(&IER, 0xFF), rd(&IER), wr(&IER, 0xFF)),
        rsv(5, 5, 0x00),
        cfg(6, 6, &BTR0),
        cfg(7, 7, &BTR1),
        cfg(8, 8, &OCR),
        row(9, 9, rd(&TEST), wr(&TEST, 0xFF), rd(&TEST), wr(&TEST, 0xFF)),
        rsv(10, 10, 0x00),
        row(11, 11, n(rd(&ALC), "read re-arms the capture"), NOP, n(rd(&ALC), "read re-arms the capture"), NOP),
        row(12, 12, n(rd(&ECC), "read re-arms the capture"), NOP, n(rd(&ECC), "read re-arms the capture"), NOP),
        cfg(13, 13, &EWLR),
        cfg(14, 14, &RXERR),
        cfg(15, 15, &TXERR),
        row(16, 16, rd(&RXFI), wr(&TXFI, 0xFF), rd(&ACR0), wr(&ACR0, 0xFF)),
        row(17, 17, rd(&RXB), wr(&TXB, 0xFF), rd(&ACR1), wr(&ACR1, 0xFF)),
        row(18, 18, rd(&RXB), wr(&TXB, 0xFF), rd(&ACR2), wr(&ACR2, 0xFF)),
        row(19, 19, rd(&RXB), wr(&TXB, 0xFF), rd(&ACR3), wr(&ACR3, 0xFF)),
        row(20, 20, rd(&RXB), wr(&TXB, 0xFF), rd(&AMR0), wr(&AMR0, 0xFF)),
        row(21, 21, rd(&RXB), wr(&TXB, 0xFF), rd(&AMR1), wr(&AMR1, 0xFF)),
        row(22, 22, rd(&RXB), wr(&TXB, 0xFF), rd(&AMR2), wr(&AMR2, 0xFF)),
        row(23, 23, rd(&RXB), wr(&TXB, 0xFF), rd(&AMR3), wr(&AMR3, 0xFF)),
        // Table 5 lists 24..28 as reserved in reset mode (reads 00H).
        row(24, 28, rd(&RXB), wr(&TXB, 0xFF), k(0x00), NOP),
        ro(29, 29, &RMC),
        cfg(30, 30, &RBSA),
        row(31, 31, rd(&CDR), n(wr(&CDR, 0x07), "CAN mode, CBP, RXINTEN, clock off unchanged in operating mode"),
            rd(&CDR), wr(&CDR, 0xEF)),
        cfg(32, 95, &RXFIFO),
        cfg(96, 108, &TXBUF),
        cfg(109, 111, &RAMFREE),
        rsv(112, 127, 0x00),
    ]
};

pub(crate) static BASIC_TABLE: &[AddrRow] = {
    use basic::def::*;
    &[
        row(0, 0, rd(&CR), wr(&CR, 0x5F), rd(&CR), wr(&CR, 0x5F)),
        row(1, 1, k(0xFF), wr(&CMR, 0x1F), k(0xFF), wr(&CMR, 0x1F)),
        ro(2, 2, &SR),
        row(3, 3, n(rd(&IR), IR_READ_BASIC), NOP, n(rd(&IR), IR_READ_BASIC), NOP),
        // Configuration registers read FFH in operating mode (Table 1).
        row(4, 4, k(0xFF), NOP, rd(&ACR), wr(&ACR, 0xFF)),
        row(5, 5, k(0xFF), NOP, rd(&AMR), wr(&AMR, 0xFF)),
        row(6, 6, k(0xFF), NOP, rd(&BTR0), wr(&BTR0, 0xFF)),
        row(7, 7, k(0xFF), NOP, rd(&BTR1), wr(&BTR1, 0xFF)),
        row(8, 8, k(0xFF), NOP, rd(&OCR), wr(&OCR, 0xFF)),
        row(9, 9, rd(&TEST), wr(&TEST, 0xFF), rd(&TEST), wr(&TEST, 0xFF)),
        // TX buffer: operating mode only; reads FFH in reset mode.
        row(10, 10, rd(&TXID1), wr(&TXID1, 0xFF), k(0xFF), NOP),
        row(11, 11, rd(&TXID2), wr(&TXID2, 0xFF), k(0xFF), NOP),
        row(12, 19, rd(&TXDATA), wr(&TXDATA, 0xFF), k(0xFF), NOP),
        ro(20, 20, &RXID1),
        ro(21, 21, &RXID2),
        ro(22, 29, &RXDATA),
        // Address 30 is unused in Table 1; this map defines it as reading 00H.
        rsv(30, 30, 0x00),
        row(31, 31, rd(&CDR), n(wr(&CDR, 0x07), "CAN mode, CBP, RXINTEN, clock off unchanged in operating mode"),
            rd(&CDR), wr(&CDR, 0xEF)),
    ]
};
