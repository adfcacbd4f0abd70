//! A frame whose CRC sequence ends on a stuff condition. CAN 2.0B §5: the
//! stuffing rule covers SOF..CRC sequence, so when the last five bits of the
//! CRC sequence, counted by that rule, are equal, a stuff bit follows the
//! last CRC bit, before the CRC delimiter; it belongs to the CRC sequence
//! field. A stuff error there is captured in ECC with segment 01000 "CRC
//! sequence" (SJA1000 §6.4.9). The frame found here, by the kit's own CRC
//! and stuffing code, is the one tb/mutation-holes/ecc-stuff-after-crc-rx.toml
//! and -tx.toml send (rtl/ mutant 20 of an earlier rtl/'s seed-1 sample: that segment
//! read as 11000, CRC delimiter).

use can_proto::{BusError, CanFrame, DecodeEvent, Decoder, Field, FrameTrait, RECESSIVE};

/// Wire index (SOF = 0, stuff bits counted) of the stuff bit that follows
/// the last CRC bit, if the frame has one.
fn stuff_after_crc(f: &CanFrame) -> Option<usize> {
    let layout = f.wire_layout();
    let delim = layout.iter().position(|b| b.field == Field::CrcDelim)?;
    let before = layout[delim - 1];
    (before.stuff && before.field == Field::Crc).then_some(delim - 1)
}

/// ID 0x529 (the DE2 thesis' ID), DLC 1, data 0x15.
fn the_frame() -> CanFrame {
    CanFrame::new(CanFrame::std_id(0x529).unwrap(), &[0x15]).unwrap()
}

/// What the kit's decoder reports for the frame with wire bit `flip`
/// inverted, after 11 idle bits; bit indices from the frame's SOF.
fn errors_with_flip(flip: usize) -> Vec<(BusError, Field, u64)> {
    let mut bits: Vec<bool> = the_frame().wire_bits().iter().by_vals().collect();
    bits[flip] = !bits[flip];
    let idle = [RECESSIVE; 11];
    let mut d = Decoder::new();
    let mut out = Vec::new();
    for l in idle.into_iter().chain(bits) {
        for e in d.push(l) {
            if let DecodeEvent::Error { error, field, bit } = e {
                out.push((error, field, bit - 11));
            }
        }
    }
    out
}

#[test]
fn id_0x529_with_data_0x15_is_the_first_such_frame_from_id_0x529() {
    // The search: standard data frames with one byte, by ID from 0x529,
    // then by data byte; the first whose CRC ends with a stuff bit.
    let found = (0x529u16..=0x7FF)
        .flat_map(|id| (0..=255u8).map(move |d| (id, d)))
        .find(|&(id, d)| stuff_after_crc(&CanFrame::new(CanFrame::std_id(id).unwrap(), &[d]).unwrap()).is_some());
    assert_eq!(found, Some((0x529, 0x15)));
}

#[test]
fn its_crc_ends_with_five_dominant_bits_then_a_recessive_stuff_bit_at_wire_bit_43() {
    let f = the_frame();
    assert_eq!(f.crc(), 0x5620, "CRC 101 0110 0010 0000: the last five bits dominant");
    assert_eq!(f.crc() & 0x1F, 0);
    assert_ne!(f.crc() & 0x20, 0, "CRC bit 5 recessive: the run is exactly the last five");
    assert_eq!(stuff_after_crc(&f), Some(43));
    let layout = f.wire_layout();
    assert_eq!(layout.len(), 54, "SOF..EOF, 2 stuff bits");
    for b in &layout[38..43] {
        assert_eq!((b.field, b.level, b.stuff), (Field::Crc, false, false));
    }
    assert_eq!((layout[43].field, layout[43].level, layout[43].stuff), (Field::Crc, RECESSIVE, true));
    assert_eq!((layout[44].field, layout[44].level), (Field::CrcDelim, RECESSIVE));
    let stuff_bits: Vec<usize> = layout.iter().enumerate().filter(|(_, b)| b.stuff).map(|(i, _)| i).collect();
    assert_eq!(stuff_bits, [17, 43]);
}

#[test]
fn flipping_that_stuff_bit_is_a_stuff_error_in_the_crc_sequence_and_its_neighbours_are_not() {
    assert_eq!(errors_with_flip(43), [(BusError::Stuff, Field::Crc, 43)]);
    // One bit earlier (the last CRC bit): the stuff bit is then taken for
    // the CRC delimiter, and the CRC is wrong (this decoder reports it at
    // the last CRC bit; a controller signals it after the ACK delimiter).
    assert_eq!(errors_with_flip(42), [(BusError::Crc, Field::Crc, 42)]);
    // One bit later: a dominant CRC delimiter, a form error.
    assert_eq!(errors_with_flip(44)[0], (BusError::Form, Field::CrcDelim, 44));
}
