//! The decoders under fuzzing, one function per target, shared by the stable mutation
//! harness (`cnc-core/app/tests/it/fuzz.rs`) and the cargo-fuzz targets (`tests/fuzz`), which
//! include this file with `#[path]`. Each takes any bytes, must not panic, and checks that what
//! decodes holds finite numbers. The including module names the `scenarios` folder
//! (`SCENARIOS`) the call target builds its machines from.

use cnc_app::scenario::Scenario;
use std::path::PathBuf;

pub fn nc(bytes: &[u8]) {
    let text = String::from_utf8_lossy(bytes);
    let axes: Vec<String> = ["X", "Y", "Z", "A", "B", "C"].map(String::from).to_vec();
    let _ = cnc_core::nc::check::check_source(&text, &axes);
}

pub fn scenario(bytes: &[u8]) {
    let text = String::from_utf8_lossy(bytes);
    let _ = Scenario::parse("fuzz.toml", &text, |name| {
        Ok((PathBuf::from(name), "%p\nG1 X10 F600\nM30\n".to_string()))
    });
}

pub fn timeline(bytes: &[u8]) {
    let text = String::from_utf8_lossy(bytes);
    let _ = plc_shim::timeline::Timeline::parse("fuzz.toml", &text);
}

pub fn cam(bytes: &[u8]) {
    use cnc_core::cam::file::{parse, BinaryOptions};
    let Ok(file) = parse(bytes, BinaryOptions::default()) else {
        return;
    };
    let (start, end) = file.profile.master_range();
    assert!(
        start.is_finite() && end.is_finite(),
        "master range {start}..{end}"
    );
    let mut cursor = Default::default();
    for k in 0..=8 {
        let x = start + (end - start) * f64::from(k) / 8.0;
        let s = file.profile.eval(x, &mut cursor);
        assert!(
            s.position.is_finite() && s.velocity.is_finite() && s.acceleration.is_finite(),
            "at {x}: {s:?}"
        );
    }
}

/// A FIFO file of `ending` written to a scratch file and read to its end.
pub fn fifo(bytes: &[u8], ending: &str) {
    let dir = std::env::temp_dir().join(format!("cncplc-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(format!("case.{ending}"));
    std::fs::write(&path, bytes).unwrap();
    let Ok(mut reader) = plc_shim::fifo_file::RowReader::open(&path) else {
        return;
    };
    let mut rows = vec![0.0; reader.columns() * 64];
    // Files are small: a bound on the reads, not on the file.
    for _ in 0..10_000 {
        match reader.read_rows(&mut rows) {
            Ok(0) | Err(_) => return,
            Ok(n) => assert!(rows[..n].iter().all(|v| v.is_finite()), "{:?}", &rows[..n]),
        }
    }
}

pub fn fifo_csv(bytes: &[u8]) {
    fifo(bytes, "csv");
}

pub fn fifo_binary(bytes: &[u8]) {
    fifo(bytes, "fifo");
}

/// Machines that hold every engine, kept from one case to the next as in a long run (in the
/// test's thread: an in-process machine holds the service ports, which stay on their thread).
type Machines = std::cell::RefCell<Vec<(cnc_app::scenario::InProcess, f64)>>;

thread_local! {
    static MACHINES: Machines = {
        let scenarios = ["axes-plcopen", "cam-data", "fifo-blocks", "saw-blocks"];
        let load = |name: &&str| {
            let s = Scenario::load(&super::SCENARIOS.join(name).join("scenario.toml")).unwrap();
            (cnc_app::scenario::InProcess::new(&s, 0).unwrap(), s.cycle_s)
        };
        std::cell::RefCell::new(scenarios.iter().map(load).collect())
    };
}

/// A call frame or bulk call of any kind, target and body (the layout of the cargo-fuzz
/// target `calls`: machine, kind, target, body), then a few ticks with finite set-points.
pub fn calls(bytes: &[u8]) {
    use hli::calls::CallKind;
    if bytes.len() < 10 {
        return;
    }
    let word = |i: usize| u32::from_le_bytes([bytes[i], bytes[i + 1], bytes[i + 2], bytes[i + 3]]);
    let Some(kind) = CallKind::decode(word(1) % 64) else {
        return;
    };
    let (target, body) = (word(5) % 48, &bytes[9..]);
    MACHINES.with(|machines| {
        let mut machines = machines.borrow_mut();
        let at = usize::from(bytes[0]) % machines.len();
        let (run, cycle_s) = &mut machines[at];
        if kind.is_bulk() {
            let values: Vec<f64> = body
                .chunks_exact(8)
                .map(|c| f64::from_le_bytes(c.try_into().unwrap()))
                .collect();
            let columns = u32::from(bytes[0] >> 4) % 8;
            let rows = (values.len() as u32).checked_div(columns).unwrap_or(0);
            let header = hli::wire::BulkHeader {
                kind: kind.raw(),
                target,
                columns,
                rows,
            };
            let used = ((columns * rows) as usize).min(values.len());
            let _ = run.machine.dispatch_bulk(&header, &values[..used]);
        } else {
            let mut request: hli::wire::AcyclicRequest = bytemuck::Zeroable::zeroed();
            let n = body.len().min(hli::wire::ACYCLIC_BODY_SIZE);
            request.kind = kind.raw();
            request.target = target;
            request.body[..n].copy_from_slice(&body[..n]);
            request.body_len = n as u32;
            let view = hli::views::CncView::new(&run.memory);
            let _ = run.machine.dispatch(&view, kind, &request);
        }
        for _ in 0..4 {
            run.step(*cycle_s);
        }
        for i in 0..run.machine.axes().len() {
            let s = run.machine.axes().axis(i).unwrap().setpoint();
            assert!(
                s.position.is_finite() && s.velocity.is_finite(),
                "axis {i}: {s:?}"
            );
        }
    });
}
