//! Fuzz of the bit-stream decoder: whatever the bus
//! levels, [`Decoder::push`] never panics, never loses its place, and
//! always gets back onto the bus: after any input, enough recessive bits
//! and one valid frame, that frame is decoded. Inputs: arbitrary bits,
//! long dominant and recessive runs (past every `u8` counter), truncated
//! frames, active, passive and superposed error flags, overload flags, and
//! valid frames with bits flipped at the interesting places (stuff bits,
//! CRC delimiter, ACK slot and delimiter, EOF). [`parse_frame`] and
//! [`decode_str`] are fuzzed the same way.
//!
//! Every case has a time bound (`support/time_bound.rs`). The suite runs a
//! CI-sized number of cases; the `#[ignore]`d `fuzz_decoder_large` runs
//! `FUZZ_CASES` (default 200 000) per strategy and prints executions:
//! `cargo test -p can-proto --test suite fuzz_decode:: -- --ignored --nocapture`.

#[path = "../support/time_bound.rs"]
mod time_bound;

use can_proto::decode::Events;
use can_proto::{CanFrame, DecodeEvent, Decoder, Field, FrameTrait, decode_str, parse_frame};
use proptest::prelude::*;
use proptest::test_runner::{Config, TestCaseError, TestRunner};
use std::time::{Duration, Instant};

/// Bound of one case (inputs are at most ~60 000 bits; the decoder runs
/// at tens of Mbit/s, so this leaves room for a loaded machine).
const CASE_BOUND: Duration = Duration::from_secs(2);

fn arb_frame() -> impl Strategy<Value = CanFrame> {
    (any::<bool>(), 0u32..(1 << 29), any::<bool>(), 0u8..=15, any::<[u8; 8]>()).prop_map(
        |(ext, id, rtr, dlc, data)| {
            let id = if ext {
                CanFrame::ext_id(id).unwrap()
            } else {
                CanFrame::std_id((id & 0x7FF) as u16).unwrap()
            };
            let n = if rtr { 0 } else { dlc.min(8) as usize };
            CanFrame::with_dlc(id, rtr, dlc, &data[..n]).unwrap()
        },
    )
}

/// The transmitter's wire bits with the ACK slot driven by a receiver.
fn wire(f: &CanFrame, ack: bool) -> Vec<bool> {
    let mut w: Vec<bool> = f.wire_bits().iter().by_vals().collect();
    let slot = w.len() - 9;
    w[slot] = !ack;
    w
}

/// Offsets (from SOF) of the bits most worth corrupting: stuff bits, the
/// last CRC bit, CRC delimiter, ACK slot, ACK delimiter, every EOF bit.
fn hot_bits(f: &CanFrame) -> Vec<usize> {
    let layout = f.wire_layout();
    let mut v: Vec<usize> = layout.iter().enumerate().filter(|(_, b)| b.stuff).map(|(i, _)| i).collect();
    let n = layout.len();
    v.extend((n - 11)..n); // CRC delimiter, ACK slot, ACK delimiter, EOF 1..7
    v.push(n - 12); // last bit before the CRC delimiter
    v
}

/// One piece of bus traffic, as the levels every receiver samples.
fn chunk() -> impl Strategy<Value = Vec<bool>> {
    prop_oneof![
        // a valid frame and its intermission
        4 => (arb_frame(), any::<bool>()).prop_map(|(f, ack)| {
            let mut v = wire(&f, ack);
            v.extend([true; 3]);
            v
        }),
        // a frame corrupted at its hot bits (and anywhere)
        4 => (arb_frame(), any::<bool>(), prop::collection::vec(any::<prop::sample::Index>(), 1..4), any::<bool>())
            .prop_map(|(f, ack, picks, anywhere)| {
                let mut v = wire(&f, ack);
                let hot = hot_bits(&f);
                for p in picks {
                    let k = if anywhere { p.index(v.len()) } else { hot[p.index(hot.len())] };
                    v[k] = !v[k];
                }
                v
            }),
        // a truncated frame: the stream goes on with whatever follows
        2 => (arb_frame(), any::<prop::sample::Index>()).prop_map(|(f, cut)| {
            let w = wire(&f, true);
            let n = cut.index(w.len());
            w[..n].to_vec()
        }),
        // long dominant runs: past every 8-bit counter (stuck-dominant bus)
        1 => (1usize..3000).prop_map(|n| vec![false; n]),
        // long recessive runs
        1 => (1usize..600).prop_map(|n| vec![true; n]),
        // active error flag (possibly superposed), then the delimiter
        2 => (6usize..13, 0usize..9).prop_map(|(flag, delim)| {
            let mut v = vec![false; flag];
            v.extend(vec![true; delim]);
            v
        }),
        // passive error flag (6 recessive), possibly a dominant bit in it
        1 => (any::<prop::sample::Index>(), any::<bool>()).prop_map(|(i, spoil)| {
            let mut v = vec![true; 14];
            if spoil {
                let k = i.index(14);
                v[k] = false;
            }
            v
        }),
        // overload flag (maybe short: a form error) and delimiter
        1 => (1usize..9, 0usize..10).prop_map(|(flag, delim)| {
            let mut v = vec![true; 2];
            v.extend(vec![false; flag]);
            v.extend(vec![true; delim]);
            v
        }),
        // noise
        2 => prop::collection::vec(any::<bool>(), 0..80),
    ]
}

/// Integration (or not), then 1..40 chunks.
fn stream() -> impl Strategy<Value = Vec<bool>> {
    (any::<bool>(), prop::collection::vec(chunk(), 1..40)).prop_map(|(integrate, chunks)| {
        let mut v = if integrate { vec![true; 11] } else { Vec::new() };
        for c in chunks {
            v.extend(c);
        }
        v
    })
}

fn show(v: &[bool]) -> String {
    v.iter().map(|&b| if b { '1' } else { '0' }).collect()
}

/// Pushes `v` into `d`; checks what must hold for any input; returns the events.
fn push_all(d: &mut Decoder, v: &[bool]) -> Result<Vec<DecodeEvent>, TestCaseError> {
    let first = d.bit_index();
    let mut out = Vec::new();
    for &level in v {
        let ev: Vec<DecodeEvent> = d.push(level).collect();
        prop_assert!(ev.len() <= Events::CAPACITY);
        out.extend(ev);
    }
    prop_assert_eq!(d.bit_index(), first + v.len() as u64);
    // The bus idle field of integration is stamped at the first of its 11
    // recessive bits, which may have been pushed before this call.
    let mut last = first.saturating_sub(can_proto::decode::INTEGRATION_BITS as u64 - 1);
    for e in &out {
        prop_assert!(e.bit() >= last, "bit index went back: {} after {}", e, last);
        prop_assert!(e.bit() < first + v.len() as u64, "{} beyond the stream", e);
        last = e.bit();
        if let DecodeEvent::Frame(f) = e {
            prop_assert!(f.start_bit < f.end_bit);
            // 44 bits: the shortest frame, SOF to the last EOF bit.
            prop_assert!(f.end_bit - f.start_bit + 1 >= 44, "{}", e);
            prop_assert!(f.end_bit - f.start_bit + 1 <= 160, "{}", e);
            prop_assert!(f.frame.dlc_raw() <= 15 && f.frame.data().len() <= 8);
        }
        // Display never panics either.
        prop_assert!(!e.to_string().is_empty());
    }
    Ok(out)
}

/// The property of every decoder case: no panic, invariants hold, and
/// after the input, 30 recessive bits and one valid frame, the decoder
/// reports exactly that frame (it never gets stuck, whatever came before).
fn decoder_case(v: &[bool], frame: &CanFrame, integrated: bool) -> Result<(), TestCaseError> {
    time_bound::within(CASE_BOUND, || show(v), || {
        let mut d = if integrated { Decoder::integrated() } else { Decoder::new() };
        push_all(&mut d, v)?;
        // Longest way back to idle: a stuff error, a passive flag, its
        // delimiter and intermission (6 + 6 + 8 + 3) or integration (11).
        let mut tail = vec![true; 30];
        let sof = d.bit_index() + tail.len() as u64;
        tail.extend(wire(frame, true));
        tail.extend([true; 3]);
        let ev = push_all(&mut d, &tail)?;
        let got: Vec<_> = ev
            .iter()
            .filter_map(|e| match e {
                // A frame cut short by the end of the input may complete
                // during the recessive bits: it started before `sof`.
                DecodeEvent::Frame(f) if f.start_bit >= sof => Some(*f),
                _ => None,
            })
            .collect();
        prop_assert_eq!(got.len(), 1, "decoder did not recover: {:?}", ev);
        prop_assert_eq!(got[0].frame, *frame);
        prop_assert_eq!(got[0].start_bit, sof);
        prop_assert!(got[0].ack);
        let late_error = ev.iter().any(|e| matches!(e, DecodeEvent::Error { .. }) && e.bit() >= sof);
        prop_assert!(!late_error, "error in the valid frame: {:?}", ev);
        Ok(())
    })
}

/// `parse_frame` on arbitrary bits: never panics, and a strict prefix of a
/// frame's wire bits (ACK slot recessive, as the transmitter sends it) is
/// always `Truncated` with the prefix length.
fn parse_case(f: &CanFrame, cut: usize, noise: &[bool]) -> Result<(), TestCaseError> {
    time_bound::within(CASE_BOUND, || format!("{f:?} cut {cut} noise {}", show(noise)), || {
        let bits = f.wire_bits();
        let cut = cut % bits.len();
        prop_assert_eq!(
            parse_frame(&bits[..cut]),
            Err(can_proto::decode::FrameError::Truncated { bits: cut as u64 })
        );
        prop_assert_eq!(parse_frame(&bits).map(|d| d.frame), Ok(*f));
        let nb: can_proto::Bits = noise.iter().copied().collect();
        match parse_frame(&nb) {
            Ok(d) => prop_assert!(d.end_bit < noise.len() as u64),
            Err(e) => prop_assert!(!e.to_string().is_empty()),
        }
        Ok(())
    })
}

/// `decode_str` on any text: events, or the first character that is not a
/// bit, named with its position.
fn str_case(s: &str) -> Result<(), TestCaseError> {
    time_bound::within(CASE_BOUND, || format!("{s:?}"), || {
        match decode_str(s) {
            Ok(ev) => {
                let bits = s.chars().filter(|c| *c == '0' || *c == '1').count() as u64;
                prop_assert!(ev.iter().all(|e| e.bit() < bits));
            }
            Err(e) => {
                prop_assert_eq!(s.chars().nth(e.pos), Some(e.ch));
                prop_assert!(!"01_| ".contains(e.ch));
            }
        }
        Ok(())
    })
}

fn bits_text() -> impl Strategy<Value = String> {
    prop_oneof![
        "[01 _|]{0,400}",
        "[01 _|x2\\t\\n]{0,200}",
        "\\PC{0,100}",
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 512, ..ProptestConfig::default() })]

    #[test]
    fn decoder_survives_bus_traffic(v in stream(), f in arb_frame(), integrated in any::<bool>()) {
        decoder_case(&v, &f, integrated)?;
    }

    #[test]
    fn decoder_survives_random_bits(v in prop::collection::vec(any::<bool>(), 0..3000), f in arb_frame(), integrated in any::<bool>()) {
        decoder_case(&v, &f, integrated)?;
    }

    #[test]
    fn parse_frame_survives_truncation_and_noise(f in arb_frame(), cut in any::<usize>(), noise in prop::collection::vec(any::<bool>(), 0..300)) {
        parse_case(&f, cut, &noise)?;
    }

    #[test]
    fn decode_str_survives_any_text(s in bits_text()) {
        str_case(&s)?;
    }
}

/// A bus stuck dominant for a long time (past `u8` and `u16` counts), then
/// released: the decoder follows it as one long flag and recovers.
#[test]
fn stuck_dominant_bus_then_release() {
    let f = CanFrame::new(CanFrame::std_id(0x123).unwrap(), &[1, 2, 3]).unwrap();
    for n in [255usize, 256, 257, 65_537, 300_000] {
        let mut v = vec![true; 11];
        v.extend(vec![false; n]);
        decoder_case(&v, &f, false).unwrap();
    }
    // and a dominant run starting mid-frame
    let mut v = vec![true; 11];
    let w = wire(&f, true);
    v.extend(&w[..30]);
    v.extend(vec![false; 1000]);
    decoder_case(&v, &f, false).unwrap();
    // error flag: the decoder saw the stuck bus as a stuff error, then a flag
    let ev: Vec<DecodeEvent> = Decoder::decode(v);
    assert!(ev.iter().any(|e| matches!(e, DecodeEvent::Error { .. })));
    assert!(ev.iter().any(|e| matches!(e, DecodeEvent::FieldStart { field: Field::ActiveErrorFlag, .. })));
}

/// The large runs, one per strategy: executions, wall time, findings.
#[test]
#[ignore = "large fuzz run (minutes); run with FUZZ_CASES=N cargo test -p can-proto --test suite fuzz_decode::fuzz_decoder_large -- --ignored --nocapture"]
fn fuzz_decoder_large() {
    let cases = time_bound::large_cases(200_000);
    let run = |name: &str, f: &dyn Fn(&mut TestRunner) -> Result<(), String>| {
        let mut runner = TestRunner::new(Config { cases, failure_persistence: None, ..Config::default() });
        let t = Instant::now();
        let r = f(&mut runner);
        println!("fuzz decoder / {name}: {cases} cases in {:.1} s: {}", t.elapsed().as_secs_f64(), match &r {
            Ok(()) => "no failure".to_string(),
            Err(e) => format!("FAILED: {e}"),
        });
        r
    };
    let results = [
        run("bus traffic", &|r| {
            r.run(&(stream(), arb_frame(), any::<bool>()), |(v, f, i)| decoder_case(&v, &f, i))
                .map_err(|e| e.to_string())
        }),
        run("random bits", &|r| {
            r.run(&(prop::collection::vec(any::<bool>(), 0..3000), arb_frame(), any::<bool>()), |(v, f, i)| {
                decoder_case(&v, &f, i)
            })
            .map_err(|e| e.to_string())
        }),
        run("parse_frame", &|r| {
            r.run(&(arb_frame(), any::<usize>(), prop::collection::vec(any::<bool>(), 0..300)), |(f, c, n)| {
                parse_case(&f, c, &n)
            })
            .map_err(|e| e.to_string())
        }),
        run("decode_str", &|r| r.run(&bits_text(), |s| str_case(&s)).map_err(|e| e.to_string())),
    ];
    for r in results {
        r.unwrap();
    }
}

/// The per-case bound has teeth: a case slower than its bound fails and
/// names its input.
#[test]
#[should_panic(expected = "over its bound of 0.010 s; input: the slow case")]
fn a_case_over_its_time_bound_fails() {
    time_bound::within(Duration::from_millis(10), || "the slow case".to_string(), || {
        std::thread::sleep(Duration::from_millis(50))
    });
}
