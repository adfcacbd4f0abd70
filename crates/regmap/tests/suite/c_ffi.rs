//! The C driver, built as a shared library against the generated header,
//! driven from Rust through `host_io_callback.c`: the same path a simulator
//! shim takes. Behind the callbacks sits a target that knows nothing but the
//! register map: what each address means in each mode, write masks, reset
//! values. A write the map says has no effect is recorded, so the test
//! proves the driver follows the access rules (configuration in reset mode,
//! buffers in operating mode) and not just that its bytes land somewhere.

use libloading::{Library, Symbol};
use regmap::generate::{self, GenOptions};
use regmap::{lookup, Access, Mode, OpMode, Register, Target};
use std::cell::RefCell;
use std::collections::HashMap;
use std::ffi::{c_int, c_ulong, c_void};
use std::path::Path;
use std::process::Command;

const BASE: usize = 0x4000;

#[repr(C)]
#[derive(Default)]
struct CanDev {
    base: usize,
    view: c_int,
    overruns: c_ulong,
}

#[repr(C)]
#[derive(Default, Debug, Clone, PartialEq)]
struct CanFrame {
    id: u32,
    extended: u8,
    rtr: u8,
    dlc: u8,
    data: [u8; 8],
}

#[repr(C)]
struct CanConfig {
    btr0: u8,
    btr1: u8,
    ocr: u8,
    cdr: u8,
    acr: [u8; 4],
    amr: [u8; 4],
    single_filter: u8,
    irq_enable: u8,
}

#[repr(C)]
#[derive(Default, Debug)]
struct CanErrors {
    sr: u8,
    ir: u8,
    has_capture: u8,
    ecc: u8,
    alc: u8,
    rxerr: u8,
    txerr: u8,
    bus_off: u8,
    error_warning: u8,
}

/// A register file made of the map alone. Registers the two views share by
/// name (SR, BTR0, CDR, ...) are one byte; the reset bit is MOD.RM in the
/// PeliCAN view and CR.RR in the BasicCAN view (the flows below only switch
/// views in reset mode, where both read 1 after their reset values).
#[derive(Default)]
struct MapTarget {
    store: HashMap<(&'static str, u8), u8>,
    /// Writes the map says have no effect: (mode, op mode, address, value).
    ignored: Vec<(Mode, OpMode, u8, u8)>,
    /// Accesses outside the map.
    outside: Vec<usize>,
}

fn key(r: &Register) -> &'static str {
    r.name
}

impl MapTarget {
    fn set(&mut self, name: &'static str, i: u8, v: u8) {
        self.store.insert((name, i), v);
    }
    fn get_named(&self, name: &'static str, i: u8) -> Option<u8> {
        self.store.get(&(name, i)).copied()
    }
    fn get(&self, r: &Register, i: u8) -> u8 {
        self.get_named(key(r), i).unwrap_or(r.reset_hw.apply(0))
    }
    fn mode(&self) -> Mode {
        Mode::from_cdr(self.get_named("CDR", 0).unwrap_or(0))
    }
    fn opmode(&self) -> OpMode {
        let reset_bit = match self.mode() {
            Mode::PeliCan => self.get_named("MOD", 0).unwrap_or(1),
            Mode::BasicCan => self.get_named("CR", 0).unwrap_or(1),
        };
        if reset_bit & 1 != 0 { OpMode::Reset } else { OpMode::Operating }
    }
    fn offset(&mut self, addr: usize) -> Option<u8> {
        match addr.checked_sub(BASE).filter(|o| *o < 256) {
            Some(o) => Some(o as u8),
            None => {
                self.outside.push(addr);
                None
            }
        }
    }
    fn read(&mut self, addr: usize) -> u8 {
        let Some(a) = self.offset(addr) else { return 0xFF };
        match lookup(self.mode(), self.opmode(), Access::Read, a) {
            None => {
                self.outside.push(addr);
                0xFF
            }
            Some(v) => match v.target {
                Target::Register(r) => self.get(r, a - r.addr),
                Target::Constant(c) => c,
                Target::Nothing => unreachable!("reads always return something"),
            },
        }
    }
    fn write(&mut self, addr: usize, val: u8) {
        let Some(a) = self.offset(addr) else { return };
        let (mode, op) = (self.mode(), self.opmode());
        match lookup(mode, op, Access::Write, a) {
            None => self.outside.push(addr),
            Some(v) => match v.target {
                Target::Register(r) => {
                    let i = a - r.addr;
                    let new = (self.get(r, i) & !v.write_mask) | (val & v.write_mask);
                    self.set(key(r), i, new);
                }
                _ => self.ignored.push((mode, op, a, val)),
            },
        }
    }
}

thread_local! {
    static TARGET: RefCell<MapTarget> = RefCell::new(MapTarget::default());
}

extern "C" fn rd8(_ctx: *mut c_void, addr: usize) -> u8 {
    TARGET.with(|t| t.borrow_mut().read(addr))
}

extern "C" fn wr8(_ctx: *mut c_void, addr: usize, data: u8) {
    TARGET.with(|t| t.borrow_mut().write(addr, data))
}

type Rd8 = extern "C" fn(*mut c_void, usize) -> u8;
type Wr8 = extern "C" fn(*mut c_void, usize, u8);

fn build_driver(dir: &Path) -> std::path::PathBuf {
    generate::write_all(dir, &GenOptions::default()).unwrap();
    let c = Path::new(env!("CARGO_MANIFEST_DIR")).join("c");
    let lib = dir.join("libcandrv.so");
    let out = Command::new("gcc")
        .args(["-std=c99", "-Wall", "-Wextra", "-Werror", "-pedantic", "-shared", "-fPIC", "-I"])
        .arg(&c)
        .arg("-I")
        .arg(dir)
        .arg(c.join("can_driver.c"))
        .arg(c.join("host_io_callback.c"))
        .arg("-o")
        .arg(&lib)
        .output()
        .expect("cannot run gcc (is it installed?)");
    assert!(out.status.success(), "gcc failed:\n{}", String::from_utf8_lossy(&out.stderr));
    lib
}

const CFG: CanConfig = CanConfig {
    btr0: 0x41,
    btr1: 0x25,
    ocr: 0xDA,
    cdr: 0x07,
    acr: [0x11, 0x22, 0x33, 0x44],
    amr: [0xF1, 0xF2, 0xF3, 0xF4],
    single_filter: 1,
    irq_enable: 0x05,
};

/// One test: the C library keeps its callbacks in globals, so the flows run
/// one after the other on this thread.
#[test]
fn c_driver_through_ffi_follows_the_register_map_access_rules() {
    let tmp = tempfile::tempdir().unwrap();
    let path = build_driver(tmp.path());
    // SAFETY: the library is our own C code built just above; the symbol
    // types below match the prototypes in can_driver.h / host_io_callback.h.
    unsafe {
        let lib = Library::new(&path).unwrap();
        let set_cb: Symbol<unsafe extern "C" fn(Rd8, Wr8, *const c_void, *const c_void, *mut c_void)> =
            lib.get(b"host_io_set_callbacks").unwrap();
        let init: Symbol<unsafe extern "C" fn(*mut CanDev, usize, c_int, *const CanConfig) -> c_int> =
            lib.get(b"can_init").unwrap();
        let tx: Symbol<unsafe extern "C" fn(*mut CanDev, *const CanFrame) -> c_int> = lib.get(b"can_transmit").unwrap();
        let rx: Symbol<unsafe extern "C" fn(*mut CanDev, *mut CanFrame) -> c_int> = lib.get(b"can_receive").unwrap();
        let errs: Symbol<unsafe extern "C" fn(*mut CanDev, *mut CanErrors) -> c_int> =
            lib.get(b"can_read_errors").unwrap();
        set_cb(rd8, wr8, std::ptr::null(), std::ptr::null(), std::ptr::null_mut());

        // ---- PeliCAN, from the hardware reset state (BasicCAN, reset mode) ----
        TARGET.with(|t| *t.borrow_mut() = MapTarget::default());
        let mut dev = CanDev::default();
        assert_eq!(init(&mut dev, BASE, 1, &CFG), 0);
        TARGET.with(|t| {
            let t = t.borrow();
            assert_eq!(t.mode(), Mode::PeliCan);
            assert_eq!(t.opmode(), OpMode::Operating);
            assert_eq!(t.get_named("CDR", 0), Some(0x87));
            assert_eq!(t.get_named("MOD", 0), Some(0x08), "AFM kept, RM cleared");
            for (name, v) in [("BTR0", 0x41), ("BTR1", 0x25), ("OCR", 0xDA), ("IER", 0x05), ("ACR0", 0x11), ("ACR3", 0x44), ("AMR0", 0xF1), ("AMR3", 0xF4)] {
                assert_eq!(t.get_named(name, 0), Some(v), "{name}");
            }
            assert!(t.ignored.is_empty(), "writes the map ignores: {:?}", t.ignored);
            assert!(t.outside.is_empty(), "accesses outside the map: {:?}", t.outside);
        });

        TARGET.with(|t| t.borrow_mut().set("SR", 0, 0x0C));
        let f = CanFrame { id: 0x1234_5678, extended: 1, rtr: 0, dlc: 3, data: [0xD1, 0xD2, 0xD3, 0, 0, 0, 0, 0] };
        assert_eq!(tx(&mut dev, &f), 0);
        TARGET.with(|t| {
            let t = t.borrow();
            assert_eq!(t.get_named("TXFI", 0), Some(0x83));
            let txb: Vec<_> = (0..7).map(|i| t.get_named("TXB", i).unwrap_or(0)).collect();
            assert_eq!(txb, [0x91, 0xA2, 0xB3, 0xC0, 0xD1, 0xD2, 0xD3]);
            assert_eq!(t.get_named("CMR", 0), Some(0x01));
            assert!(t.ignored.is_empty(), "{:?}", t.ignored);
        });

        TARGET.with(|t| {
            let mut t = t.borrow_mut();
            t.set("RXFI", 0, 0x02);
            for (i, b) in [0xA5u8, 0x20, 0x11, 0x22].into_iter().enumerate() {
                t.set("RXB", i as u8, b);
            }
            t.set("SR", 0, 0x0D);
            t.set("ECC", 0, 0x48);
            t.set("ALC", 0, 0x05);
            t.set("TXERR", 0, 130);
        });
        let mut got = CanFrame::default();
        assert_eq!(rx(&mut dev, &mut got), 1);
        assert_eq!(got, CanFrame { id: 0x529, extended: 0, rtr: 0, dlc: 2, data: [0x11, 0x22, 0, 0, 0, 0, 0, 0] });
        TARGET.with(|t| assert_eq!(t.borrow().get_named("CMR", 0), Some(0x04), "released with RRB"));
        let mut e = CanErrors::default();
        assert_eq!(errs(&mut dev, &mut e), 0);
        assert_eq!((e.has_capture, e.ecc, e.alc, e.txerr), (1, 0x48, 5, 130));

        // ---- BasicCAN, starting from the PeliCAN view in operating mode ----
        TARGET.with(|t| {
            let mut t = t.borrow_mut();
            *t = MapTarget::default();
            t.set("CDR", 0, 0x80);
            t.set("MOD", 0, 0x00);
        });
        let mut dev = CanDev::default();
        assert_eq!(init(&mut dev, BASE, 0, &CFG), 0);
        TARGET.with(|t| {
            let t = t.borrow();
            assert_eq!(t.mode(), Mode::BasicCan);
            assert_eq!(t.opmode(), OpMode::Operating);
            for (name, v) in [("ACR", 0x11), ("AMR", 0xF1), ("BTR0", 0x41), ("BTR1", 0x25), ("OCR", 0xDA), ("CDR", 0x07)] {
                assert_eq!(t.get_named(name, 0), Some(v), "{name}");
            }
            assert_eq!(t.get_named("CR", 0), Some(0x24), "CR: TIE, RR cleared, CR.5 reads 1");
            assert!(t.ignored.is_empty(), "writes the map ignores: {:?}", t.ignored);
        });
        TARGET.with(|t| t.borrow_mut().set("SR", 0, 0x0C));
        let f = CanFrame { id: 0x529, extended: 0, rtr: 0, dlc: 1, data: [0x51, 0, 0, 0, 0, 0, 0, 0] };
        assert_eq!(tx(&mut dev, &f), 0);
        TARGET.with(|t| {
            let t = t.borrow();
            assert_eq!(t.get_named("TXID1", 0), Some(0xA5));
            assert_eq!(t.get_named("TXID2", 0), Some(0x21));
            assert_eq!(t.get_named("TXDATA", 0), Some(0x51));
            assert_eq!(t.get_named("CMR", 0).map(|c| c & 0x1F), Some(0x01), "TR only");
            assert!(t.ignored.is_empty() && t.outside.is_empty());
        });
        // In BasicCAN, the capture registers do not exist: the driver must not touch them.
        let mut e = CanErrors::default();
        assert_eq!(errs(&mut dev, &mut e), 0);
        assert_eq!(e.has_capture, 0);
        TARGET.with(|t| assert!(t.borrow().outside.is_empty()));
    }
}
