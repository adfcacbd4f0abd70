//! Bad input through the frame API: identifiers out of range, DLC
//! above 15, data not matching the DLC, and what DLC 9..15 means (the CAN
//! rule: 8 data bytes, the DLC kept as sent). Each is `None`, never a
//! panic or a silently truncated frame.

use can_proto::{CanFrame, FrameTrait, parse_frame};

#[test]
fn identifiers_out_of_range_are_refused() {
    assert!(CanFrame::std_id(0x7FF).is_some());
    assert!(CanFrame::std_id(0x800).is_none());
    assert!(CanFrame::std_id(u16::MAX).is_none());
    assert!(CanFrame::ext_id(0x1FFF_FFFF).is_some());
    assert!(CanFrame::ext_id(0x2000_0000).is_none());
    assert!(CanFrame::ext_id(u32::MAX).is_none());
}

#[test]
fn dlc_and_data_that_do_not_agree_are_refused() {
    let id = CanFrame::std_id(0x123).unwrap();
    assert!(CanFrame::with_dlc(id, false, 16, &[0; 8]).is_none(), "DLC is 4 bits");
    assert!(CanFrame::with_dlc(id, false, 255, &[0; 8]).is_none());
    assert!(CanFrame::with_dlc(id, false, 9, &[0; 7]).is_none(), "DLC 9 carries 8 bytes");
    assert!(CanFrame::with_dlc(id, false, 2, &[0; 3]).is_none());
    assert!(CanFrame::with_dlc(id, true, 4, &[1]).is_none(), "a remote frame carries no data");
    assert!(CanFrame::new(id, &[0; 9]).is_none(), "nine data bytes");
    assert!(CanFrame::new_remote(id, 16).is_none());
}

/// DLC 9..15: 8 data bytes on the wire, the DLC as sent, and the decoder
/// reads the same frame back.
#[test]
fn dlc_9_to_15_means_8_bytes() {
    let id = CanFrame::ext_id(0x1ABC_DEF0).unwrap();
    for dlc in 9..=15u8 {
        let f = CanFrame::with_dlc(id, false, dlc, &[0xA5; 8]).unwrap();
        assert_eq!((f.dlc_raw(), f.data_len(), f.data().len()), (dlc, 8, 8));
        let back = parse_frame(&f.wire_bits()).unwrap().frame;
        assert_eq!(back, f);
        assert_eq!(back.dlc_raw(), dlc);
        let r = CanFrame::with_dlc(id, true, dlc, &[]).unwrap();
        assert_eq!((r.dlc_raw(), r.data_len()), (dlc, 0));
        assert_eq!(parse_frame(&r.wire_bits()).unwrap().frame, r);
    }
}
