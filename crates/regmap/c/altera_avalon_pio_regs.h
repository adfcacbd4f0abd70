/*
 * altera_avalon_pio_regs.h: host stand-in for the Altera PIO register
 * header (data = register 0, direction = 1, interruptmask = 2,
 * edgecapture = 3, word spaced), on top of the stand-in io.h.
 */
#ifndef HOST_STANDIN_ALTERA_AVALON_PIO_REGS_H
#define HOST_STANDIN_ALTERA_AVALON_PIO_REGS_H

#include <io.h>

#define IORD_ALTERA_AVALON_PIO_DATA(base) IORD(base, 0)
#define IOWR_ALTERA_AVALON_PIO_DATA(base, data) IOWR(base, 0, data)
#define IORD_ALTERA_AVALON_PIO_DIRECTION(base) IORD(base, 1)
#define IOWR_ALTERA_AVALON_PIO_DIRECTION(base, data) IOWR(base, 1, data)
#define IORD_ALTERA_AVALON_PIO_IRQ_MASK(base) IORD(base, 2)
#define IOWR_ALTERA_AVALON_PIO_IRQ_MASK(base, data) IOWR(base, 2, data)
#define IORD_ALTERA_AVALON_PIO_EDGE_CAP(base) IORD(base, 3)
#define IOWR_ALTERA_AVALON_PIO_EDGE_CAP(base, data) IOWR(base, 3, data)

#endif
