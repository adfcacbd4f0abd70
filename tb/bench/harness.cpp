// Raw C++ Verilator harness for the bench's self-test loopback workload
// (crates/bench): the physical limit of RTL co-simulation. One
// clock drives both wb_clk_i and clk_i (24 MHz, 40 clocks per bit with
// BTR0/BTR1 = 0x41/0x25), rx_i is tied to tx_o, and a blocking Wishbone
// classic master plays the same register sequence as crates/bench
// (src/workload.rs) and tb/bench/bench_tb.v. Frames come from the shared
// xorshift32 generator so every run of every simulator sends the same bits.
//
// Usage: harness <frames> <seed>
// Prints: BENCH frames=<n> cycles=<clock cycles> errors=<mismatches> maxrss_kb=<VmHWM>
#include <cstdio>
#include <cstdlib>
#include <cstdint>
#include <cstring>
#include <memory>
#include "verilated.h"
#include "Vcan_top.h"

static std::unique_ptr<VerilatedContext> ctx;
static std::unique_ptr<Vcan_top> top;
static uint64_t cycles = 0;
static const uint64_t IRQ_TIMEOUT_CYCLES = 200 * 40;
static const int ACK_TIMEOUT_CYCLES = 200;

// One clock cycle: rx_i follows tx_o (loopback), rising edge, falling edge.
static inline void cycle() {
    top->rx_i = top->tx_o;
    top->wb_clk_i = 1;
    top->clk_i = 1;
    top->eval();
    top->wb_clk_i = 0;
    top->clk_i = 0;
    top->eval();
    cycles++;
}

static void die(const char* what, unsigned a) {
    std::fprintf(stderr, "harness: %s (address 0x%02X, cycle %llu)\n", what, a, (unsigned long long)cycles);
    std::exit(2);
}

// Wishbone classic access: pins set after a falling edge, held until the
// rising edge that shows wb_ack_o, released before the next rising edge.
static uint8_t wb(bool we, uint8_t adr, uint8_t dat) {
    top->wb_cyc_i = 1;
    top->wb_stb_i = 1;
    top->wb_we_i = we;
    top->wb_adr_i = adr;
    top->wb_dat_i = dat;
    int waited = 0;
    do {
        cycle();
        if (++waited > ACK_TIMEOUT_CYCLES) die("no wb_ack_o", adr);
    } while (!top->wb_ack_o);
    uint8_t q = top->wb_dat_o;
    top->wb_cyc_i = 0;
    top->wb_stb_i = 0;
    top->wb_we_i = 0;
    cycle();
    return q;
}
static void wr(uint8_t a, uint8_t d) { wb(true, a, d); }
static uint8_t rd(uint8_t a) { return wb(false, a, 0); }

static void idle(uint64_t n) {
    for (uint64_t i = 0; i < n; i++) cycle();
}

static void wait_irq() {
    uint64_t n = 0;
    while (top->irq_on) {
        cycle();
        if (++n > IRQ_TIMEOUT_CYCLES) die("irq_on never went low", 3);
    }
}

// The shared frame generator (see crates/bench/src/workload.rs).
static uint32_t rng_state;
static uint32_t next_u32() {
    uint32_t x = rng_state;
    x ^= x << 13;
    x ^= x >> 17;
    x ^= x << 5;
    rng_state = x;
    return x;
}

static long vm_hwm_kb() {
    FILE* f = std::fopen("/proc/self/status", "r");
    if (!f) return -1;
    char line[256];
    long kb = -1;
    while (std::fgets(line, sizeof line, f))
        if (std::strncmp(line, "VmHWM:", 6) == 0) kb = std::strtol(line + 6, nullptr, 10);
    std::fclose(f);
    return kb;
}

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: %s <frames> <seed>\n", argv[0]);
        return 1;
    }
    unsigned long frames = std::strtoul(argv[1], nullptr, 10);
    unsigned long long seed = std::strtoull(argv[2], nullptr, 10);
    rng_state = (uint32_t)seed;
    if (rng_state == 0) rng_state = 1;

    ctx.reset(new VerilatedContext);
    top.reset(new Vcan_top{ctx.get()});
    top->wb_rst_i = 1;
    top->rx_i = 1;
    idle(8);
    top->wb_rst_i = 0;
    idle(8);

    // Configuration: reset mode, PeliCAN, 40 clocks per bit, accept all,
    // RI and TI interrupts, then operating mode with self test.
    wr(0, 0x01);
    wr(31, 0x80);
    wr(0, 0x01);
    wr(6, 0x41);
    wr(7, 0x25);
    for (uint8_t a = 16; a < 20; a++) wr(a, 0x00);
    for (uint8_t a = 20; a < 24; a++) wr(a, 0xFF);
    wr(4, 0x03);
    wr(0, 0x04);
    idle(12 * 40);

    unsigned long errors = 0;
    for (unsigned long k = 0; k < frames; k++) {
        uint32_t id = next_u32() & 0x7FF;
        uint8_t data[8];
        for (int i = 0; i < 8; i++) data[i] = (uint8_t)(next_u32() & 0xFF);
        uint8_t tx[11] = {0x08, (uint8_t)(id >> 3), (uint8_t)((id & 7) << 5)};
        std::memcpy(tx + 3, data, 8);
        for (int i = 0; i < 11; i++) wr(16 + i, tx[i]);
        wr(1, 0x10);  // CMR: self reception request
        uint8_t ir = 0;
        for (;;) {
            wait_irq();
            idle(2 * 40);  // SETTLE_BITS
            ir |= rd(3);
            if ((ir & 0x03) == 0x03) break;
            idle(40);
        }
        uint8_t sr = rd(2);
        if ((sr & 0x09) != 0x09) errors++;  // TCS and RBS
        for (int i = 0; i < 11; i++) {
            uint8_t mask = (i == 2) ? 0xF0 : 0xFF;
            if ((rd(16 + i) & mask) != (tx[i] & mask)) errors++;
        }
        wr(1, 0x04);  // CMR: release receive buffer
    }
    top->final();
    std::printf("BENCH frames=%lu cycles=%llu errors=%lu maxrss_kb=%ld\n", frames, (unsigned long long)cycles, errors,
                vm_hwm_kb());
    return errors == 0 ? 0 : 3;
}
