//! Decoder from sampled bus levels to frames, fields and error events.
//! (Filled in by the can-proto work.)
