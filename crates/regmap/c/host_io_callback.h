/*
 * host_io_callback.h: the stand-in io.h functions forwarded to callbacks
 * registered at run time, so a simulator (Rust, through FFI) can answer
 * the driver's IORD/IOWR with bus cycles on the simulated core.
 *
 * The macros cannot return errors: a callback that fails (bus timeout)
 * should record the failure on its side and return 0xFF for reads.
 */
#ifndef HOST_IO_CALLBACK_H
#define HOST_IO_CALLBACK_H

#include <stdint.h>

typedef uint8_t (*host_io_read8_fn)(void *ctx, uintptr_t addr);
typedef void (*host_io_write8_fn)(void *ctx, uintptr_t addr, uint8_t data);
typedef uint32_t (*host_io_read32_fn)(void *ctx, uintptr_t addr);
typedef void (*host_io_write32_fn)(void *ctx, uintptr_t addr, uint32_t data);

/* Registers the callbacks. read8/write8 are required. A NULL read32 or
 * write32 forwards 32-bit accesses (IORD/IOWR, PIO registers) to the 8-bit
 * callbacks: bits 7..0 at the same byte address, upper bits read as 0. */
void host_io_set_callbacks(host_io_read8_fn read8, host_io_write8_fn write8,
                           host_io_read32_fn read32, host_io_write32_fn write32,
                           void *ctx);

#endif
