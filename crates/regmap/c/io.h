/*
 * io.h: host stand-in for the Nios II HAL <io.h>, so code written against
 * the generated *_regs.h compiles and runs on the host.
 *
 * Every access goes through six functions (8, 16 and 32 bits wide). host_io_mem.c implements them
 * over a plain byte array (for unit tests); a simulator shim implements
 * them by running bus cycles on the simulated core instead.
 */
#ifndef HOST_STANDIN_IO_H
#define HOST_STANDIN_IO_H

#include <stdint.h>

uint8_t host_io_read8(uintptr_t addr);
void host_io_write8(uintptr_t addr, uint8_t data);
uint16_t host_io_read16(uintptr_t addr);
void host_io_write16(uintptr_t addr, uint16_t data);
uint32_t host_io_read32(uintptr_t addr);
void host_io_write32(uintptr_t addr, uint32_t data);

/* Address arithmetic as the HAL defines it: NATIVE counts 32-bit words,
 * DYNAMIC counts bytes. */
#define __IO_CALC_ADDRESS_NATIVE(BASE, REGNUM) \
    ((void *)((uintptr_t)(BASE) + (uintptr_t)(REGNUM) * 4u))
#define __IO_CALC_ADDRESS_DYNAMIC(BASE, OFFSET) \
    ((void *)((uintptr_t)(BASE) + (uintptr_t)(OFFSET)))

#define IORD_8DIRECT(BASE, OFFSET) \
    host_io_read8((uintptr_t)(BASE) + (uintptr_t)(OFFSET))
#define IOWR_8DIRECT(BASE, OFFSET, DATA) \
    host_io_write8((uintptr_t)(BASE) + (uintptr_t)(OFFSET), (uint8_t)(DATA))
#define IORD_16DIRECT(BASE, OFFSET) \
    host_io_read16((uintptr_t)(BASE) + (uintptr_t)(OFFSET))
#define IOWR_16DIRECT(BASE, OFFSET, DATA) \
    host_io_write16((uintptr_t)(BASE) + (uintptr_t)(OFFSET), (uint16_t)(DATA))
#define IORD(BASE, REGNUM) \
    host_io_read32((uintptr_t)(BASE) + (uintptr_t)(REGNUM) * 4u)
#define IOWR(BASE, REGNUM, DATA) \
    host_io_write32((uintptr_t)(BASE) + (uintptr_t)(REGNUM) * 4u, (uint32_t)(DATA))

#endif /* HOST_STANDIN_IO_H */
