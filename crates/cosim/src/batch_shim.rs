//! The C++ inner loop of a CAN controller top (see [`crate::verilated`]'s
//! `Batch` for the layout): several instants in one foreign call while
//! nothing but the two clocks and `rx` drive the inputs. Only `std` is used
//! here, because `build.rs` includes this file with `#[path]`.

/// The body of the shim's inner loop (`vbridge::shimgen::gen_shim`'s
/// `inner_loop`): `m` is the model, `arg` a `Batch`.
pub fn batch_loop_cpp() -> &'static str {
    "  struct Batch {\n    uint8_t* host_clk; uint8_t* can_clk; uint8_t* rx; const uint8_t* tx; const uint8_t* irq;\n    \
     const uint8_t* bus_off; const uint8_t* clkout; const uint8_t* ack; const uint8_t* dat;\n    \
     const uint8_t* levels; uint8_t* out; uint32_t n; uint8_t rx_mode; uint8_t stop_irq;\n  };\n  \
     const auto* b = (const Batch*)arg;\n  \
     /* Locals: the eval writes memory the compiler cannot tell from *b. */\n  \
     uint8_t* const host_clk = b->host_clk; uint8_t* const can_clk = b->can_clk; uint8_t* const rx = b->rx;\n  \
     const uint8_t* const tx = b->tx; const uint8_t* const irq_p = b->irq; const uint8_t* const bus_off = b->bus_off;\n  \
     const uint8_t* const clkout = b->clkout; const uint8_t* const ack = b->ack; const uint8_t* const dat = b->dat;\n  \
     const uint8_t* const levels = b->levels; uint8_t* const out = b->out;\n  \
     const uint32_t n = b->n; const uint8_t rx_mode = b->rx_mode, stop_irq = b->stop_irq;\n  \
     const uint8_t ack0 = *ack, dat0 = *dat;\n  \
     for (uint32_t k = 0; k < n; ++k) {\n    \
     const uint8_t l = levels[k];\n    \
     if (l & 4) *rx = rx_mode == 2 ? *tx : rx_mode;\n    \
     *host_clk = l & 1;\n    \
     *can_clk = (l >> 1) & 1;\n    \
     m->eval();\n    \
     const uint8_t irq = *irq_p != 0;\n    \
     out[k] = (uint8_t)((*tx != 0) | (irq << 1) | ((*bus_off != 0) << 2) | ((*clkout != 0) << 3));\n    \
     if (*ack != ack0 || *dat != dat0 || irq == stop_irq) return k + 1;\n  \
     }\n  \
     return n;"
}
