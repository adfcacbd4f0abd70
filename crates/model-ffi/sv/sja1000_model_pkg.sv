// sja1000_model_pkg: the golden SJA1000 model as a scoreboard in a
// SystemVerilog bench, through DPI-C (libsja1000_model.so, header
// crates/model-ffi/include/sja1000_model.h). Link the bench with
// -lsja1000_model.
//
//   sja1000_model_pkg::sja1000_scoreboard sb = new("rtl", 24.0e6);
//   @(posedge wb_clk_i) if (cyc & stb & first) sb.request(we, adr, dat_w);
//   @(posedge wb_clk_i) if (ack & !we)         sb.compare_read(adr, dat_r);
//   @(posedge clk_i)    sb.clock(rx_i, tx_o, irq_on, bus_off_on);
//   final: sb.finish() == 0 or $fatal with sb.diagnosis()
`timescale 1ps/1ps
package sja1000_model_pkg;

  import "DPI-C" function chandle sja1000_model_new(input string profile, input real can_hz);
  import "DPI-C" function string  sja1000_model_last_error();
  import "DPI-C" function void    sja1000_model_free(input chandle m);
  import "DPI-C" function void    sja1000_model_set_name(input chandle m, input string name);
  import "DPI-C" function int     sja1000_model_set_host_bus(input chandle m, input string name);
  import "DPI-C" function void    sja1000_model_reset(input chandle m);
  import "DPI-C" function int     sja1000_model_clock(input chandle m, input int rx);
  import "DPI-C" function int     sja1000_model_clock_compare(input chandle m, input int rx,
                                                              input int dut_tx, input int dut_irq_n,
                                                              input int dut_bus_on);
  import "DPI-C" function void    sja1000_model_request(input chandle m, input int write,
                                                        input byte unsigned addr, input byte unsigned data);
  import "DPI-C" function void    sja1000_model_write(input chandle m, input byte unsigned addr,
                                                      input byte unsigned data);
  import "DPI-C" function int     sja1000_model_read(input chandle m, input byte unsigned addr);
  import "DPI-C" function int     sja1000_model_compare_read(input chandle m, input byte unsigned addr,
                                                             input byte unsigned dut_data);
  import "DPI-C" function int     sja1000_model_peek(input chandle m, input byte unsigned addr);
  import "DPI-C" function int     sja1000_model_open_clocks(input chandle m);
  import "DPI-C" function int     sja1000_model_finish(input chandle m);
  import "DPI-C" function int     sja1000_model_failed(input chandle m);
  import "DPI-C" function string  sja1000_model_diagnosis(input chandle m);
  import "DPI-C" function longint unsigned sja1000_model_compared_reads(input chandle m);
  import "DPI-C" function longint unsigned sja1000_model_compared_bits(input chandle m);

  // One golden model shadowing one DUT. Feed it every host access at its
  // launch edge (request), every read's data at its ack (compare_read),
  // every CAN clock (clock); check failed() or call finish() at the end.
  class sja1000_scoreboard;
    chandle h;

    // profile: "rtl" (our can_top), "opencores-can", a .toml path, or
    // "immediate" (accesses taken at the call); can_hz: the DUT's clk_i.
    function new(string profile = "rtl", real can_hz = 24.0e6);
      h = sja1000_model_new(profile, can_hz);
      if (h == null) $fatal(1, "sja1000_model_new: %s", sja1000_model_last_error());
    endfunction

    // The test's name, for the diagnosis's first line.
    function void set_name(string name);
      sja1000_model_set_name(h, name);
    endfunction

    // The host bus the accesses come through: "wishbone" (default),
    // "avalon", "pio", "axi4-lite", "apb", "regport" or "motorola"; the
    // profile's timing for it.
    function void set_host_bus(string name);
      if (sja1000_model_set_host_bus(h, name) != 0)
        $fatal(1, "sja1000_model_set_host_bus: %s", sja1000_model_last_error());
    endfunction

    // The DUT's reset input.
    function void reset();
      sja1000_model_reset(h);
    endfunction

    // One CAN clock: rx_i as the DUT sampled it, the DUT's pins after the
    // edge. Returns the model's tx.
    function bit clock(bit rx, bit dut_tx, bit dut_irq_n, bit dut_bus_on);
      return sja1000_model_clock_compare(h, int'(rx), int'(dut_tx), int'(dut_irq_n), int'(dut_bus_on)) != 0;
    endfunction

    // A host access presented to the DUT (at the first host edge it samples it).
    function void request(bit we, byte unsigned addr, byte unsigned data);
      sja1000_model_request(h, int'(we), addr, data);
    endfunction

    // The DUT's read data at the ack; returns the model's value.
    function byte unsigned compare_read(byte unsigned addr, byte unsigned dut_data);
      return byte'(sja1000_model_compare_read(h, addr, dut_data));
    endfunction

    function bit failed();
      return sja1000_model_failed(h) != 0;
    endfunction

    // CAN clocks to run before finish() so the last reads are judged.
    function int open_clocks();
      return sja1000_model_open_clocks(h);
    endfunction

    // End of test: 1 if the DUT diverged or a requested frame never went out.
    function bit finish();
      return sja1000_model_finish(h) != 0;
    endfunction

    // What happened, the figures, the root cause and the fix ("" if none).
    function string diagnosis();
      return sja1000_model_diagnosis(h);
    endfunction

    function longint unsigned compared_reads();
      return sja1000_model_compared_reads(h);
    endfunction

    function longint unsigned compared_bits();
      return sja1000_model_compared_bits(h);
    endfunction
  endclass

endpackage
