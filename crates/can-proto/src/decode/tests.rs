//! Decoder tests: known frames, each error, signalling, truncation, fuzz.

use super::*;
use crate::{Bits, FrameTrait};
use alloc::string::ToString;
use alloc::vec;
use alloc::vec::Vec;
use proptest::prelude::*;

/// `n` recessive bits.
fn idle(n: usize) -> Vec<bool> {
    vec![RECESSIVE; n]
}

/// The wire bits of `f` with the ACK slot driven dominant when `ack`.
fn wire(f: &CanFrame, ack: bool) -> Vec<bool> {
    let mut w: Vec<bool> = f.wire_bits().iter().by_vals().collect();
    let ack_slot = w.len() - 9;
    w[ack_slot] = !ack;
    w
}

/// Integration, the frame, intermission and one idle bit.
fn on_bus(f: &CanFrame) -> Vec<bool> {
    let mut v = idle(11);
    v.extend(wire(f, true));
    v.extend(idle(4));
    v
}

fn starts(ev: &[DecodeEvent]) -> Vec<(Field, u64)> {
    ev.iter()
        .filter_map(|e| match *e {
            DecodeEvent::FieldStart { field, bit } => Some((field, bit)),
            _ => None,
        })
        .collect()
}

fn frames(ev: &[DecodeEvent]) -> Vec<DecodedFrame> {
    ev.iter()
        .filter_map(|e| match *e {
            DecodeEvent::Frame(f) => Some(f),
            _ => None,
        })
        .collect()
}

fn errors(ev: &[DecodeEvent]) -> Vec<(BusError, Field, u64)> {
    ev.iter()
        .filter_map(|e| match *e {
            DecodeEvent::Error { error, field, bit } => Some((error, field, bit)),
            _ => None,
        })
        .collect()
}

fn stuff_bits(ev: &[DecodeEvent]) -> Vec<u64> {
    ev.iter()
        .filter_map(|e| match *e {
            DecodeEvent::StuffBit { bit } => Some(bit),
            _ => None,
        })
        .collect()
}

fn thesis_frame() -> CanFrame {
    CanFrame::new(CanFrame::std_id(0x529).unwrap(), &[0x51]).unwrap()
}

// ---------------------------------------------------------------- known frames

/// The DE2 thesis frame (seed 000): ID 0x529, DLC 1, data 0x51. Its CRC is
/// 0x7D2A = 111 1101 0010 1010 (reference division in `crc_reference`).
/// On the wire, from SOF = bit 0:
/// ```text
///  0     SOF            0
///  1-11  ID             10100101001
///  12    RTR            0
///  13    IDE            0
///  14    r0             0
///  15-16 DLC3 DLC2      00        (RTR..DLC2: five dominant bits)
///  17    stuff          1
///  18-19 DLC1 DLC0      01
///  20-27 data           01010001
///  28-31 CRC 14..11     1111      (with data bit 0: five recessive bits)
///  32    stuff          0
///  33-43 CRC 10..0      10100101010
///  44    CRC delimiter, 45 ACK slot, 46 ACK delimiter, 47-53 EOF,
///  54-56 intermission, 57 bus idle
/// ```
#[test]
fn thesis_frame_field_indices() {
    let f = thesis_frame();
    let ev = Decoder::decode(on_bus(&f));
    let sof = 11;
    let rel: Vec<(Field, u64)> = starts(&ev)
        .into_iter()
        .map(|(fl, b)| (fl, b.wrapping_sub(sof)))
        .collect();
    assert_eq!(
        rel,
        [
            (Field::BusIdle, 0u64.wrapping_sub(11)),
            (Field::Sof, 0),
            (Field::BaseId, 1),
            (Field::SrrRtr, 12),
            (Field::Ide, 13),
            (Field::R0, 14),
            (Field::Dlc, 15),
            (Field::Data, 20),
            (Field::Crc, 28),
            (Field::CrcDelim, 44),
            (Field::AckSlot, 45),
            (Field::AckDelim, 46),
            (Field::Eof, 47),
            (Field::Intermission, 54),
            (Field::BusIdle, 57),
        ]
    );
    assert_eq!(stuff_bits(&ev), [sof + 17, sof + 32]);
    assert_eq!(
        frames(&ev),
        [DecodedFrame {
            frame: f,
            start_bit: sof,
            end_bit: sof + 53,
            ack: true
        }]
    );
    assert_eq!(errors(&ev), []);
    assert_eq!(f.crc(), 0x7D2A);
    // Display, for reports and the diagnoser.
    let lines: Vec<alloc::string::String> = ev.iter().map(|e| e.to_string()).collect();
    assert!(lines.contains(&"bit 28: stuff bit".into()), "{lines:?}");
    assert!(lines.contains(&"bit 31: data field".into()));
    assert!(
        lines.contains(&"bits 11-64: frame id 0x529 dlc 1".into()),
        "{lines:?}"
    );
    let e = DecodeEvent::Error {
        error: BusError::Stuff,
        field: Field::Dlc,
        bit: 28,
    };
    assert_eq!(e.to_string(), "bit 28: stuff error in data length code");
    assert_eq!(BusError::Crc.kind(), embedded_can::ErrorKind::Crc);
}

#[test]
fn decode_str_reads_the_thesis_frame() {
    // 11 idle | SOF ID RTR IDE r0 DLC3 DLC2 stuff DLC1 DLC0 | data | CRC with
    // its stuff bit | CRC del, ACK (dominant), ACK del | EOF | intermission
    let s = "11111111111 | 0 10100101001 0 0 0 00 1 01 | 01010001 | 1111 0 10100101010 | 1 0 1 | 1111111 | 111";
    let ev = decode_str(s).unwrap();
    let fr = frames(&ev);
    assert_eq!(fr.len(), 1);
    assert_eq!(fr[0].frame, thesis_frame());
    assert!(fr[0].ack);
    assert_eq!(decode_str("0110x1"), Err(NotABit { pos: 4, ch: 'x' }));
    assert_eq!(
        NotABit { pos: 4, ch: 'x' }.to_string(),
        "character 'x' at position 4 is not a bit (expected 0, 1, or a separator: space, _ or |)"
    );
}

#[test]
fn decode_bits_matches_decode() {
    let f = CanFrame::new(CanFrame::ext_id(0x1ABC_DEF0).unwrap(), &[1, 2, 3]).unwrap();
    let mut b = Bits::new();
    b.extend(on_bus(&f));
    assert_eq!(decode_bits(&b), Decoder::decode(on_bus(&f)));
    assert_eq!(frames(&decode_bits(&b))[0].frame, f);
}

/// Extended frame layout: SRR and IDE recessive, 18 more ID bits, RTR, r1,
/// r0, DLC; no data for a remote frame.
#[test]
fn extended_remote_frame_fields() {
    let f = CanFrame::new_remote(CanFrame::ext_id(0x0155_5555).unwrap(), 3).unwrap();
    let ev = Decoder::decode(on_bus(&f));
    let order: Vec<Field> = starts(&ev).into_iter().map(|(fl, _)| fl).collect();
    assert_eq!(
        order,
        [
            Field::BusIdle,
            Field::Sof,
            Field::BaseId,
            Field::SrrRtr,
            Field::Ide,
            Field::ExtId,
            Field::Rtr,
            Field::R1,
            Field::R0,
            Field::Dlc,
            Field::Crc,
            Field::CrcDelim,
            Field::AckSlot,
            Field::AckDelim,
            Field::Eof,
            Field::Intermission,
            Field::BusIdle,
        ]
    );
    let fr = frames(&ev);
    assert_eq!(fr[0].frame, f);
    assert!(
        fr[0].frame.is_remote_frame() && fr[0].frame.dlc() == 3 && fr[0].frame.data().is_empty()
    );
}

#[test]
fn dlc_over_8_decodes_8_bytes() {
    for dlc in 9..=15u8 {
        let f =
            CanFrame::with_dlc(CanFrame::std_id(0x7FF).unwrap(), false, dlc, &[0xA5; 8]).unwrap();
        let fr = frames(&Decoder::decode(on_bus(&f)));
        assert_eq!(fr.len(), 1);
        assert_eq!(fr[0].frame.dlc_raw(), dlc);
        assert_eq!(fr[0].frame.data(), &[0xA5; 8]);
    }
}

#[test]
fn unacknowledged_frame_is_reported_as_such() {
    // In self-test mode nobody acknowledges and nobody flags it.
    let f = thesis_frame();
    let mut v = idle(11);
    v.extend(wire(&f, false));
    v.extend(idle(3));
    let fr = frames(&Decoder::decode(v));
    assert_eq!(fr.len(), 1);
    assert!(!fr[0].ack);
}

// ------------------------------------------------------------- integration

#[test]
fn no_frame_before_integration() {
    let f = thesis_frame();
    // Ten recessive bits are not enough: the SOF is not accepted, and the
    // frame's own bits never hold 11 recessive bits before its EOF.
    let mut v = idle(10);
    v.extend(wire(&f, true));
    let ev = Decoder::decode(v.clone());
    assert_eq!(frames(&ev), []);
    assert!(!starts(&ev).iter().any(|&(fl, _)| fl == Field::Sof));
    // ACK delimiter + EOF make 8 recessive bits; three more integrate, and
    // then a second frame is read.
    v.extend(idle(3));
    let second = v.len() as u64;
    v.extend(wire(&f, true));
    v.extend(idle(3));
    let ev = Decoder::decode(v);
    let fr = frames(&ev);
    assert_eq!(fr.len(), 1);
    assert_eq!(fr[0].start_bit, second);
    assert!(starts(&ev).contains(&(Field::BusIdle, second - 11)));
}

// ------------------------------------------------------------------ errors

/// Flipping any CRC bit (and restuffing, as a transmitter with a corrupted
/// CRC register would) gives a CRC error at the last CRC bit and no frame.
#[test]
fn flipped_crc_bit_is_a_crc_error() {
    let f = thesis_frame();
    let unstuffed = f.unstuffed_bits();
    let n = unstuffed.len();
    for k in n - 15..n {
        let mut bad = unstuffed.clone();
        let b = bad[k];
        bad.set(k, !b);
        let stuffed = crate::stuff::stuff(&bad);
        let mut v = idle(11);
        v.extend(stuffed.iter().by_vals());
        let crc_delim = v.len() as u64;
        v.extend([true, false, true]); // CRC delimiter, ACK (dominant), ACK delimiter
        v.extend([false; 6]); // receivers' error flags, from the first EOF bit
        v.extend(idle(8 + 3 + 1));
        let ev = Decoder::decode(v);
        let last_crc = crc_delim
            - 1
            - stuff_bits(&ev)
                .iter()
                .filter(|&&s| s == crc_delim - 1)
                .count() as u64;
        assert_eq!(
            errors(&ev),
            [(BusError::Crc, Field::Crc, last_crc)],
            "flip {k}"
        );
        assert_eq!(frames(&ev), []);
        let s = starts(&ev);
        let tail: Vec<Field> = s
            .iter()
            .skip_while(|&&(fl, _)| fl != Field::CrcDelim)
            .map(|&(fl, _)| fl)
            .collect();
        assert_eq!(
            tail,
            [
                Field::CrcDelim,
                Field::AckSlot,
                Field::AckDelim,
                Field::ActiveErrorFlag,
                Field::ErrorDelimiter,
                Field::Intermission,
                Field::BusIdle
            ]
        );
        assert!(s.contains(&(Field::ActiveErrorFlag, crc_delim + 3)));
        assert!(s.contains(&(Field::ErrorDelimiter, crc_delim + 9)));
    }
}

/// A sixth equal bit in place of the first stuff bit (bit 17 of the thesis
/// frame, after RTR IDE r0 DLC3 DLC2) is a stuff error at that bit, in the
/// DLC; the error flag follows at the next bit.
#[test]
fn sixth_equal_bit_is_a_stuff_error_at_that_bit() {
    let f = thesis_frame();
    let mut v = idle(11);
    let mut w = wire(&f, true);
    assert!(w[17], "bit 17 is the recessive stuff bit");
    w[17] = false;
    v.extend(&w[..18]);
    v.extend([false; 5]); // six dominant bits of flags in all
    v.extend(idle(11));
    let ev = Decoder::decode(v);
    assert_eq!(errors(&ev), [(BusError::Stuff, Field::Dlc, 11 + 17)]);
    assert!(starts(&ev).contains(&(Field::ActiveErrorFlag, 11 + 18)));
    assert!(starts(&ev).contains(&(Field::ErrorDelimiter, 11 + 23)));
    assert!(starts(&ev).contains(&(Field::Intermission, 11 + 31)));
    assert_eq!(frames(&ev), []);
}

/// Every stuff bit of random frames, replaced by a sixth equal bit.
#[test]
fn every_stuff_bit_position_is_checked() {
    let f = CanFrame::new(CanFrame::ext_id(0).unwrap(), &[0, 0xFF, 0, 0xFF]).unwrap();
    let clean = Decoder::decode(on_bus(&f));
    let stuffs = stuff_bits(&clean);
    assert!(stuffs.len() > 8, "{stuffs:?}");
    for &s in &stuffs {
        let mut v = on_bus(&f);
        v[s as usize] = !v[s as usize];
        let ev = Decoder::decode(v);
        assert_eq!(errors(&ev)[0].0, BusError::Stuff, "stuff bit {s}");
        assert_eq!(errors(&ev)[0].2, s);
        assert_eq!(frames(&ev), []);
    }
}

#[test]
fn dominant_crc_delimiter_is_a_form_error() {
    let f = thesis_frame();
    let mut v = on_bus(&f);
    let crc_delim = 11 + 44;
    v[crc_delim] = false;
    let ev = Decoder::decode(v);
    assert_eq!(
        errors(&ev),
        [(BusError::Form, Field::CrcDelim, crc_delim as u64)]
    );
    assert_eq!(frames(&ev), []);
    // The next bit (the dominant ACK slot) is read as the start of a flag.
    assert!(starts(&ev).contains(&(Field::ActiveErrorFlag, crc_delim as u64 + 1)));
}

#[test]
fn dominant_eof_bit_is_a_form_error_but_not_the_last() {
    let f = thesis_frame();
    for k in 0..6 {
        let mut v = on_bus(&f);
        let eof = 11 + 47 + k;
        v[eof] = false;
        let ev = Decoder::decode(v);
        assert_eq!(
            errors(&ev),
            [(BusError::Form, Field::Eof, eof as u64)],
            "EOF bit {k}"
        );
        assert_eq!(frames(&ev), []);
    }
    // Last EOF bit dominant: valid for receivers, then an overload flag.
    let mut v = on_bus(&f);
    let last = 11 + 53;
    v.truncate(last);
    v.extend([false; 7]); // transmitter's error flag, receivers' overload flags
    v.extend(idle(8 + 3 + 1));
    let ev = Decoder::decode(v);
    assert_eq!(errors(&ev), []);
    assert_eq!(frames(&ev).len(), 1);
    let s = starts(&ev);
    assert!(s.contains(&(Field::OverloadFlag, last as u64)));
    assert!(
        s.contains(&(Field::OverloadDelimiter, last as u64 + 7)),
        "{s:?}"
    );
}

#[test]
fn recessive_ack_then_flag_is_an_ack_error() {
    let f = thesis_frame();
    let mut v = idle(11);
    v.extend(wire(&f, false));
    let ack_slot = 11 + 45;
    v.truncate(ack_slot + 1);
    v.extend([false; 6]); // transmitter's flag from the ACK delimiter
    v.extend(idle(12));
    let ev = Decoder::decode(v);
    assert_eq!(
        errors(&ev),
        [(BusError::Acknowledge, Field::AckSlot, ack_slot as u64)]
    );
    assert!(starts(&ev).contains(&(Field::ActiveErrorFlag, ack_slot as u64 + 1)));
    assert!(starts(&ev).contains(&(Field::ErrorDelimiter, ack_slot as u64 + 7)));
    assert_eq!(frames(&ev), []);
}

#[test]
fn dominant_ack_delimiter_after_ack_is_a_form_error() {
    let f = thesis_frame();
    let mut v = on_bus(&f);
    v[11 + 46] = false;
    let ev = Decoder::decode(v);
    assert_eq!(errors(&ev), [(BusError::Form, Field::AckDelim, 11 + 46)]);
}

// ------------------------------------------------------- error and overload

#[test]
fn passive_error_flag_then_delimiter() {
    // A stuff error seen only by an error-passive node: six recessive bits of
    // passive flag, then the 8-bit delimiter, then intermission.
    let f = thesis_frame();
    let mut w = wire(&f, true);
    w[17] = false;
    let mut v = idle(11);
    v.extend(&w[..18]);
    v.extend(idle(6 + 8 + 3 + 1));
    let ev = Decoder::decode(v);
    let s = starts(&ev);
    let flag = 11 + 18;
    assert!(s.contains(&(Field::PassiveErrorFlag, flag)));
    assert!(s.contains(&(Field::ErrorDelimiter, flag + 6)), "{s:?}");
    assert!(s.contains(&(Field::Intermission, flag + 14)));
    assert!(s.contains(&(Field::BusIdle, flag + 17)));
}

#[test]
fn superposed_error_flags_lengthen_the_flag() {
    let f = thesis_frame();
    let mut w = wire(&f, true);
    w[17] = false;
    let mut v = idle(11);
    v.extend(&w[..18]);
    v.extend([false; 12]);
    v.extend(idle(12));
    let s = starts(&Decoder::decode(v));
    assert!(s.contains(&(Field::ActiveErrorFlag, 29)));
    assert!(s.contains(&(Field::ErrorDelimiter, 41)));
}

#[test]
fn dominant_bit_in_error_delimiter() {
    let f = thesis_frame();
    let mut w = wire(&f, true);
    w[17] = false;
    let mut base = idle(11);
    base.extend(&w[..18]);
    base.extend([false; 6]);
    let delim = base.len() as u64;
    // Bits 1..7 of the delimiter dominant: bit 1 only delays it (the node
    // waits for a recessive bus), bits 2..7 are form errors.
    for k in 1..7u64 {
        let mut v = base.clone();
        v.extend(idle(k as usize));
        v.push(false);
        v.extend(idle(20));
        let ev = Decoder::decode(v);
        assert_eq!(
            errors(&ev)[1],
            (BusError::Form, Field::ErrorDelimiter, delim + k),
            "bit {k}"
        );
    }
    // Bit 8 dominant: an overload flag (ISO 11898-1).
    let mut v = base.clone();
    v.extend(idle(7));
    v.extend([false; 6]);
    v.extend(idle(12));
    let ev = Decoder::decode(v);
    assert_eq!(errors(&ev).len(), 1);
    assert!(starts(&ev).contains(&(Field::OverloadFlag, delim + 7)));
    assert!(starts(&ev).contains(&(Field::OverloadDelimiter, delim + 13)));
}

#[test]
fn overload_in_intermission_and_sof_at_third_bit() {
    let f = thesis_frame();
    let mut v = on_bus(&f);
    let inter = 11 + 54;
    v.truncate(inter);
    v.push(true);
    v.extend([false; 6]); // overload flag from intermission bit 2
    v.extend(idle(8 + 2));
    let second = v.len() as u64; // third intermission bit: SOF
    v.extend(wire(&f, true));
    v.extend(idle(3));
    let ev = Decoder::decode(v);
    let s = starts(&ev);
    assert!(s.contains(&(Field::OverloadFlag, inter as u64 + 1)));
    assert!(s.contains(&(Field::OverloadDelimiter, inter as u64 + 7)));
    assert!(s.contains(&(Field::Intermission, inter as u64 + 15)));
    let fr = frames(&ev);
    assert_eq!(fr.len(), 2);
    assert_eq!(fr[1].start_bit, second);
    assert_eq!(errors(&ev), []);
}

#[test]
fn short_overload_flag_is_a_form_error() {
    let f = thesis_frame();
    let mut v = on_bus(&f);
    let inter = 11 + 54;
    v.truncate(inter);
    v.extend([false, false, true]);
    v.extend(idle(20));
    let ev = Decoder::decode(v);
    assert_eq!(
        errors(&ev),
        [(BusError::Form, Field::OverloadFlag, inter as u64 + 2)]
    );
}

#[test]
fn parse_frame_reports_errors_and_truncation() {
    let f = thesis_frame();
    let mut w = f.wire_bits();
    assert_eq!(
        parse_frame(&w[..50]),
        Err(FrameError::Truncated { bits: 50 })
    );
    w.set(17, false);
    let e = parse_frame(&w).unwrap_err();
    assert_eq!(
        e,
        FrameError::Bus {
            error: BusError::Stuff,
            field: Field::Dlc,
            bit: 17
        }
    );
    assert_eq!(
        e.to_string(),
        "stuff error in the data length code at bit 17"
    );
    // Leading idle bits are skipped; indices count from the slice start.
    let mut v = Bits::new();
    v.extend([true; 3]);
    v.extend(f.wire_bits());
    assert_eq!(parse_frame(&v).unwrap().start_bit, 3);
}

// --------------------------------------------------------------- truncation

#[test]
fn truncated_streams_give_no_frame() {
    for f in [
        thesis_frame(),
        CanFrame::with_dlc(
            CanFrame::ext_id(0x1FFF_FFFF).unwrap(),
            false,
            15,
            &[0xFF; 8],
        )
        .unwrap(),
    ] {
        let v = on_bus(&f);
        let last_eof = v.len() - 4 - 1;
        for cut in 0..v.len() {
            let ev = Decoder::decode(v[..cut].iter().copied());
            let want = usize::from(cut > last_eof);
            assert_eq!(frames(&ev).len(), want, "cut at {cut}");
            assert_eq!(errors(&ev), []);
        }
    }
}

// ------------------------------------------------------------ property tests

fn arb_frame() -> impl Strategy<Value = CanFrame> {
    (
        any::<bool>(),
        0u32..(1 << 29),
        any::<bool>(),
        0u8..=15,
        any::<[u8; 8]>(),
    )
        .prop_map(|(ext, id, rtr, dlc, data)| {
            let id = if ext {
                CanFrame::ext_id(id).unwrap()
            } else {
                CanFrame::std_id((id & 0x7FF) as u16).unwrap()
            };
            let n = if rtr { 0 } else { dlc.min(8) as usize };
            CanFrame::with_dlc(id, rtr, dlc, &data[..n]).unwrap()
        })
}

/// Checks what every event list must satisfy, whatever the input.
fn check_invariants(ev: &[DecodeEvent], len: usize) -> Result<(), TestCaseError> {
    let mut last = 0;
    for e in ev {
        prop_assert!(e.bit() >= last, "bit index went back: {} after {}", e, last);
        prop_assert!(e.bit() < len as u64, "{} beyond the stream", e);
        last = e.bit();
        if let DecodeEvent::Frame(f) = e {
            prop_assert!(f.start_bit < f.end_bit);
            // The shortest frame: 44 bits from SOF to the end of EOF.
            prop_assert!(f.end_bit - f.start_bit + 1 >= 44);
        }
    }
    Ok(())
}

proptest! {
    /// Encode then decode gives the frame back, at the right bits, and the
    /// field of every wire bit matches the encoder's own field labels.
    #[test]
    fn round_trip(f in arb_frame(), ack in any::<bool>(), gap in 0usize..5) {
        let mut v = idle(11 + gap);
        let sof = v.len() as u64;
        v.extend(wire(&f, ack));
        v.extend(idle(3));
        let ev = Decoder::decode(v.clone());
        check_invariants(&ev, v.len())?;
        prop_assert_eq!(errors(&ev), []);
        let fr = frames(&ev);
        prop_assert_eq!(fr.len(), 1);
        prop_assert_eq!(fr[0], DecodedFrame { frame: f, start_bit: sof, end_bit: sof + f.bit_len() as u64 - 1, ack });

        // Field of each bit from SOF to the last CRC bit, from the events.
        let s = starts(&ev);
        let stuffed: Vec<u64> = stuff_bits(&ev);
        let crc_delim = s.iter().find(|&&(fl, _)| fl == Field::CrcDelim).unwrap().1;
        let mut from_decoder = Vec::new();
        for b in sof..crc_delim {
            if stuffed.contains(&b) {
                continue;
            }
            let field = s.iter().rev().find(|&&(_, at)| at <= b).unwrap().0;
            from_decoder.push((field, v[b as usize]));
        }
        let mut from_encoder = Vec::new();
        f.for_each_unstuffed_bit(|field, level| from_encoder.push((field, level)));
        prop_assert_eq!(from_decoder, from_encoder);
        // The encoder's annotated layout agrees bit for bit.
        let layout = f.wire_layout();
        for (i, wb) in layout.iter().enumerate() {
            let b = sof + i as u64;
            prop_assert_eq!(wb.stuff, stuffed.contains(&b), "bit {}", i);
            let field = s.iter().rev().find(|&&(_, at)| at <= b).unwrap().0;
            if !wb.stuff {
                prop_assert_eq!(wb.field, field, "bit {}", i);
            }
        }
        // parse_frame reads the transmitter's own bits.
        prop_assert_eq!(
            parse_frame(&f.wire_bits()),
            Ok(DecodedFrame { frame: f, start_bit: 0, end_bit: f.bit_len() as u64 - 1, ack: false })
        );
        // Stuff bits are exactly where the stuffer put them.
        let unstuffed: Bits = crate::stuff::destuff(&f.wire_bits()[..(crc_delim - sof) as usize]).unwrap();
        prop_assert_eq!(unstuffed, f.unstuffed_bits());
    }

    /// Back-to-back frames, each starting at the first bit after
    /// intermission, all decode.
    #[test]
    fn back_to_back(fs in prop::collection::vec(arb_frame(), 1..5)) {
        let mut v = idle(11);
        for f in &fs {
            v.extend(wire(f, true));
            v.extend(idle(3));
        }
        let ev = Decoder::decode(v.clone());
        check_invariants(&ev, v.len())?;
        let got: Vec<CanFrame> = frames(&ev).into_iter().map(|d| d.frame).collect();
        prop_assert_eq!(got, fs);
        prop_assert!(!starts(&ev).iter().skip(1).any(|&(fl, _)| fl == Field::BusIdle));
    }

    /// Fuzz: arbitrary bit sequences never panic, indices never go back.
    #[test]
    fn fuzz_random_bits(v in prop::collection::vec(any::<bool>(), 0..2000)) {
        let ev = Decoder::decode(v.clone());
        check_invariants(&ev, v.len())?;
    }

    /// Fuzz closer to the bus: valid frames and signalling with random bit
    /// flips, so that every state is reached.
    #[test]
    fn fuzz_corrupted_traffic(input in corrupted_traffic()) {
        let ev = Decoder::decode(input.clone());
        check_invariants(&ev, input.len())?;
    }
}

/// Frames, idle gaps, error and overload flags, then `flips` random bits
/// inverted.
fn corrupted_traffic() -> impl Strategy<Value = Vec<bool>> {
    let chunk = prop_oneof![
        4 => (arb_frame(), any::<bool>()).prop_map(|(f, ack)| wire(&f, ack)),
        2 => (0usize..14).prop_map(idle),
        1 => (1usize..14).prop_map(|n| vec![false; n]),
    ];
    (
        prop::collection::vec(chunk, 1..12),
        prop::collection::vec(any::<prop::sample::Index>(), 0..6),
    )
        .prop_map(|(chunks, flips)| {
            let mut v = idle(11);
            for c in chunks {
                v.extend(c);
            }
            let len = v.len();
            for i in flips {
                let k = i.index(len);
                v[k] = !v[k];
            }
            v
        })
}

/// Long fuzz campaign; prints executions and what the decoder produced.
#[test]
#[ignore = "long fuzz; run with cargo test -p can-proto --release -- --ignored"]
fn fuzz_long() {
    use proptest::test_runner::{Config, TestRunner};
    use std::sync::atomic::{AtomicU64, Ordering::Relaxed};
    static CASES: AtomicU64 = AtomicU64::new(0);
    static BITS: AtomicU64 = AtomicU64::new(0);
    static FRAMES: AtomicU64 = AtomicU64::new(0);
    static ERRORS: AtomicU64 = AtomicU64::new(0);
    for (name, random) in [("random bits", true), ("corrupted traffic", false)] {
        let mut runner = TestRunner::new(Config {
            cases: 100_000,
            failure_persistence: None,
            ..Config::default()
        });
        let strat = if random {
            prop::collection::vec(any::<bool>(), 0..2000).boxed()
        } else {
            corrupted_traffic().boxed()
        };
        let (c0, b0, f0, e0) = (
            CASES.load(Relaxed),
            BITS.load(Relaxed),
            FRAMES.load(Relaxed),
            ERRORS.load(Relaxed),
        );
        runner
            .run(&strat, |v| {
                let ev = Decoder::decode(v.clone());
                check_invariants(&ev, v.len())?;
                CASES.fetch_add(1, Relaxed);
                BITS.fetch_add(v.len() as u64, Relaxed);
                FRAMES.fetch_add(frames(&ev).len() as u64, Relaxed);
                ERRORS.fetch_add(errors(&ev).len() as u64, Relaxed);
                Ok(())
            })
            .unwrap();
        std::println!(
            "fuzz {name}: {} cases, {} bits, {} frames, {} errors decoded, no failure",
            CASES.load(Relaxed) - c0,
            BITS.load(Relaxed) - b0,
            FRAMES.load(Relaxed) - f0,
            ERRORS.load(Relaxed) - e0
        );
    }
}

/// Decoder speed on back-to-back random frames (not a timed assertion).
#[test]
#[ignore = "measurement; run with cargo test -p can-proto --release decoder_throughput -- --ignored --nocapture"]
fn decoder_throughput() {
    use proptest::strategy::ValueTree;
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let mut v = idle(11);
    while v.len() < 1_000_000 {
        let f = arb_frame().new_tree(&mut runner).unwrap().current();
        v.extend(wire(&f, true));
        v.extend(idle(3));
    }
    let rounds = 20;
    let t = std::time::Instant::now();
    let mut frames_seen = 0usize;
    for _ in 0..rounds {
        let mut d = Decoder::new();
        for &b in &v {
            for e in d.push(b) {
                frames_seen += matches!(e, DecodeEvent::Frame(_)) as usize;
            }
        }
    }
    let secs = t.elapsed().as_secs_f64();
    let bits = (v.len() * rounds) as f64;
    assert!(frames_seen > rounds * 1000);
    std::println!(
        "decoder: {:.1} Mbit/s ({} bits, {} frames in {:.3} s)",
        bits / secs / 1e6,
        bits,
        frames_seen,
        secs
    );
}
