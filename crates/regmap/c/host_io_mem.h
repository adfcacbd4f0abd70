/* host_io_mem.h: the byte array behind host_io_mem.c, for tests to inspect. */
#ifndef HOST_IO_MEM_H
#define HOST_IO_MEM_H

#include <stdint.h>

#define HOST_IO_MEM_SIZE 0x10000u

extern uint8_t host_io_mem[HOST_IO_MEM_SIZE];
extern unsigned long host_io_reads;
extern unsigned long host_io_writes;

#endif
