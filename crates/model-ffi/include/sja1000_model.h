/*
 * sja1000_model.h: the golden SJA1000 model as a scoreboard for a C, C++
 * or SystemVerilog (DPI-C) test bench. Library: libsja1000_model.so
 * (crates/model-ffi, `cargo build --release -p model-ffi`).
 *
 * The bench reports what its DUT does, when it does it:
 *   - every rising edge of the DUT's CAN clock (clk_i): the rx level and,
 *     to compare, the DUT's tx_o, irq_on, bus_off_on;
 *   - every host access, at the host clock edge at which the DUT samples
 *     the request for the first time (sja1000_model_request);
 *   - every read's data, at its ack (sja1000_model_compare_read).
 * The model takes an access at the CAN clock the DUT's core profile
 * declares (profile "rtl": our can_top, 3rd CAN edge for a read, 4th for a
 * write). Comparisons are the command line's: tx at sample points, SR/IR
 * reads matching any model value within the profile's status tolerance
 * (48 CAN clocks for "rtl"), every other register exactly, irq/bus-off
 * pins within the pin tolerance. The first difference stops the
 * comparison and becomes the diagnosis text.
 *
 * Levels: 1 = recessive on rx/tx. A handle is not thread-safe.
 */
#ifndef SJA1000_MODEL_H
#define SJA1000_MODEL_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct Sja1000Model sja1000_model;

/* A model for the DUT described by `profile` ("rtl", "opencores-can", a
 * .toml path; NULL or "" = "rtl"; "immediate" = every access taken at the
 * call) with its CAN clock at `can_hz`. NULL on error, see last_error. */
sja1000_model *sja1000_model_new(const char *profile, double can_hz);
/* Why the last sja1000_model_new of this thread returned NULL. */
const char *sja1000_model_last_error(void);
void sja1000_model_free(sja1000_model *m);

/* The test's name, for the diagnosis's first line. */
void sja1000_model_set_name(sja1000_model *m, const char *name);
/* The host bus the accesses come through: "wishbone" (default), "avalon",
 * "pio", "axi4-lite", "apb", "regport" or "motorola"; the model takes them
 * at the CAN clock the profile declares for that bus. 0, or -1 for an
 * unknown name (the reason in sja1000_model_last_error). */
int sja1000_model_set_host_bus(sja1000_model *m, const char *name);
/* Hardware reset of the model (the DUT's reset input). */
void sja1000_model_reset(sja1000_model *m);

/* One CAN clock, nothing compared; returns the model's tx. */
int sja1000_model_clock(sja1000_model *m, int rx);
/* One CAN clock, then the DUT's pins compared (-1: that pin is not
 * compared); returns the model's tx. */
int sja1000_model_clock_compare(sja1000_model *m, int rx, int dut_tx, int dut_irq_n, int dut_bus_on);

/* A host access presented to the DUT (write: 1), at the host edge where
 * the DUT samples it; taken at the profile's CAN clock. */
void sja1000_model_request(sja1000_model *m, int write, uint8_t addr, uint8_t data);
/* A write / read the model takes now (no comparison). */
void sja1000_model_write(sja1000_model *m, uint8_t addr, uint8_t data);
int sja1000_model_read(sja1000_model *m, uint8_t addr);
/* The DUT's read of addr returned dut_data: compared; returns the
 * model's value. An SR read may be judged only later (see open_clocks). */
int sja1000_model_compare_read(sja1000_model *m, uint8_t addr, uint8_t dut_data);
/* Register value without side effects. */
int sja1000_model_peek(sja1000_model *m, uint8_t addr);

/* CAN clocks still needed before every comparison so far is judged. */
int sja1000_model_open_clocks(sja1000_model *m);
/* End of the test: a transmission still pending becomes a diagnosis.
 * Returns 1 if the run failed. */
int sja1000_model_finish(sja1000_model *m);
/* 1 once the DUT diverged (or finish found a stuck transfer). */
int sja1000_model_failed(sja1000_model *m);
/* The diagnosis ("" if none); valid until the next call on m. */
const char *sja1000_model_diagnosis(sja1000_model *m);

/* Register reads / tx sample points compared so far. */
uint64_t sja1000_model_compared_reads(sja1000_model *m);
uint64_t sja1000_model_compared_bits(sja1000_model *m);

#ifdef __cplusplus
}
#endif

#endif /* SJA1000_MODEL_H */
