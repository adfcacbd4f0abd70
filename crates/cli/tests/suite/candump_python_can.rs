//! `cancosim run --candump` checked by a real parser: python-can's
//! `CanutilsLogReader` (the reader python-can uses for `candump -l` files),
//! installed from PyPI into a scratch directory by the test. When pip or
//! the network is missing, the test says so and skips; our own reader's
//! round trip (`cosim/tests/suite/candump.rs`) and the replay tests
//! (`scenario/tests/suite/candump_replay.rs`) still check the format.

use cosim::candump::{LogKind, err, parse_log};
use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..")
}

const PYTHON_CAN: &str = "python-can==4.6.1";

/// python-can installed under `dir`, or why not.
fn install_python_can(dir: &std::path::Path) -> Result<(), String> {
    if dir.join("can").join("io").join("canutils.py").exists() {
        return Ok(());
    }
    let out = Command::new("python3")
        .args(["-m", "pip", "install", "--quiet", "--disable-pip-version-check", "--no-input", "--timeout", "20", "--retries", "1", "--target"])
        .arg(dir)
        .arg(PYTHON_CAN)
        .output()
        .map_err(|e| format!("python3 not runnable: {e}"))?;
    if !out.status.success() {
        return Err(format!("pip install {PYTHON_CAN} failed: {}", String::from_utf8_lossy(&out.stderr).lines().last().unwrap_or("")));
    }
    Ok(())
}

/// Each message python-can reads from `log`: `t id ext rtr dlc data err`.
const READER: &str = r#"
import sys, can
for m in can.CanutilsLogReader(sys.argv[1]):
    data = bytes(m.data or b"").hex().upper()
    print(f"{m.timestamp:.6f} {m.arbitration_id:X} {int(m.is_extended_id)} {int(m.is_remote_frame)} {m.dlc} {data or '-'} {int(m.is_error_frame)}")
"#;

#[test]
fn python_can_reads_our_logs_as_we_wrote_them() {
    let scratch = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join("candump-python-can");
    std::fs::create_dir_all(&scratch).unwrap();
    let py = scratch.join("site");
    if let Err(why) = install_python_can(&py) {
        eprintln!("SKIPPED python_can_reads_our_logs_as_we_wrote_them: {why} (needs python3, pip and PyPI)");
        return;
    }
    // Frames of every kind (extended, remote with DLC, DLC > 8), lost
    // arbitration, bus errors of every type with counters, passive and bus-off.
    let mut checked = 0;
    for s in ["pelican-frame-kinds", "pelican-arbitration", "pelican-error-kinds", "de2-thesis", "pelican-bus-off-recovery"] {
        let log = scratch.join(format!("{s}.log"));
        let out = Command::new(env!("CARGO_BIN_EXE_cancosim"))
            .args(["run", &format!("tb/{s}.toml"), "--candump"])
            .arg(&log)
            .current_dir(root())
            .output()
            .unwrap();
        assert!(out.status.success(), "{s}: {}", String::from_utf8_lossy(&out.stdout));
        let text = std::fs::read_to_string(&log).unwrap();
        // python-can 4.6 does not read can-utils' `_X` raw DLC suffix
        // (candump -8): those lines are checked by our reader only.
        let (raw_dlc, plain): (Vec<&str>, Vec<&str>) = text.lines().partition(|l| l.contains('_'));
        let plain_path = scratch.join(format!("{s}.plain.log"));
        std::fs::write(&plain_path, plain.join("\n") + "\n").unwrap();
        assert_eq!(parse_log(&text, s).unwrap().len(), text.lines().count());
        assert_eq!(raw_dlc.len(), if s == "pelican-frame-kinds" { 2 } else { 0 }, "{s}: {raw_dlc:?}");
        let ours = parse_log(&plain.join("\n"), s).unwrap();
        let py_out = Command::new("python3").env("PYTHONPATH", &py).args(["-c", READER]).arg(&plain_path).output().unwrap();
        assert!(py_out.status.success(), "{s}: python-can failed: {}", String::from_utf8_lossy(&py_out.stderr));
        let theirs: Vec<String> = String::from_utf8(py_out.stdout).unwrap().lines().map(str::to_string).collect();
        assert_eq!(theirs.len(), ours.len(), "{s}: python-can read {} messages, we wrote {}", theirs.len(), ours.len());
        for (o, t) in ours.iter().zip(&theirs) {
            let f: Vec<&str> = t.split(' ').collect();
            assert_eq!(f[0], fmt_t(o.t_us), "{s}: timestamp of {t}");
            match &o.kind {
                LogKind::Frame(fr) => {
                    use can_proto::FrameTrait;
                    assert_eq!(f[1], format!("{:X}", fr.raw_id()), "{s}: {t}");
                    assert_eq!(f[2], if fr.is_extended() { "1" } else { "0" }, "{s}: {t}");
                    assert_eq!(f[3], if fr.is_remote_frame() { "1" } else { "0" }, "{s}: {t}");
                    assert_eq!(f[4], fr.dlc_raw().to_string(), "{s}: {t}");
                    let data: String = fr.data().iter().map(|b| format!("{b:02X}")).collect();
                    assert_eq!(f[5], if data.is_empty() { "-".to_string() } else { data }, "{s}: {t}");
                    assert_eq!(f[6], "0", "{s}: {t}");
                }
                // python-can flags bus errors as error frames; other error
                // classes (controller state, lost arbitration, bus-off) it
                // reads as plain messages with the class bits as the ID.
                LogKind::Error { id, data } => {
                    if id & err::BUSERROR != 0 {
                        assert_eq!(f[6], "1", "{s}: {t}");
                    } else {
                        assert_eq!(f[1], format!("{:X}", id & 0x1FFF_FFFF), "{s}: {t}");
                        let d: String = data.iter().map(|b| format!("{b:02X}")).collect();
                        assert_eq!(f[5], d, "{s}: {t}");
                    }
                }
            }
            checked += 1;
        }
    }
    eprintln!("python-can ({PYTHON_CAN}) read {checked} lines as written");
    assert!(checked > 100, "{checked}");
}

fn fmt_t(us: u64) -> String {
    format!("{}.{:06}", us / 1_000_000, us % 1_000_000)
}
