//! LinuxCNC's trajectory planner as a peer in the same run: its uspace simulation started
//! headless (`linuxcnc` with the INI, HAL file and driver beside this file: a trivkins XYZ
//! machine, joints looped back, the DISPLAY a python driver using LinuxCNC's `linuxcnc`
//! module), the same programs with `G64 P<dev>`, the same velocity and acceleration limits
//! (LinuxCNC 2.9's planner has no jerk limit). Needs root (`rtapi_app`; `RTAPI_UID` and
//! `RTAPI_FIFO_PATH` are set for it) and `linuxcnc-uspace`; absent, the bench says so.

use std::path::{Path, PathBuf};
use std::process::Command;

const FILES: [(&str, &str); 3] = [
    ("contour.ini", include_str!("contour.ini")),
    ("contour.hal", include_str!("contour.hal")),
    ("driver.py", include_str!("driver.py")),
];

/// Why the peer did not run (printed by the bench).
pub fn unavailable() -> Option<String> {
    let found = Command::new("sh")
        .args(["-c", "command -v linuxcnc"])
        .output()
        .is_ok_and(|o| o.status.success());
    if !found {
        return Some("LinuxCNC not installed (apt-get install linuxcnc-uspace)".into());
    }
    let uid = Command::new("id").arg("-u").output().ok();
    let root = uid.is_some_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0");
    if !root {
        return Some("LinuxCNC's simulation needs root here (rtapi_app)".into());
    }
    None
}

/// Runs each program (name, start point, blocks) `repeats` times, interleaved, each from its
/// start point; the median time per program (first to last moving poll), or why it failed.
pub fn run(
    programs: &[(&str, [f64; 2], String)],
    dev: f64,
    feed_mm_min: f64,
    repeats: usize,
) -> Result<Vec<f64>, String> {
    let dir = std::env::temp_dir().join(format!("contour-peer-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let result = run_in(&dir, programs, (dev, feed_mm_min), repeats);
    let _ = std::fs::remove_dir_all(&dir);
    result
}

fn run_in(
    dir: &Path,
    programs: &[(&str, [f64; 2], String)],
    (dev, feed): (f64, f64),
    repeats: usize,
) -> Result<Vec<f64>, String> {
    use std::os::unix::fs::PermissionsExt;
    // rtapi_app binds its socket here as RTAPI_UID.
    std::fs::set_permissions(dir, std::fs::Permissions::from_mode(0o777))
        .map_err(|e| e.to_string())?;
    let d = dir.to_string_lossy().to_string();
    for (name, text) in FILES {
        let path = dir.join(name);
        std::fs::write(&path, text.replace("DIR", &d)).map_err(|e| e.to_string())?;
        if name.ends_with(".py") {
            let perm = std::fs::Permissions::from_mode(0o755);
            std::fs::set_permissions(&path, perm).map_err(|e| e.to_string())?;
        }
    }
    std::fs::write(dir.join("sim.var"), "").map_err(|e| e.to_string())?;
    std::fs::write(dir.join("tool.tbl"), "T1 P1 D0 Z0 ;\n").map_err(|e| e.to_string())?;
    let mut files: Vec<PathBuf> = Vec::new();
    for (name, [x0, y0], blocks) in programs {
        let path = dir.join(format!("{name}.ngc"));
        let mut text = format!("(PEER_START X{x0:.6} Y{y0:.6})\nG21 G90 G64 P{dev}\nG1 F{feed}\n");
        text.push_str(blocks);
        text.push_str("M2\n");
        std::fs::write(&path, text).map_err(|e| e.to_string())?;
        files.push(path);
    }
    let order: Vec<String> = (0..repeats)
        .flat_map(|_| files.iter().map(|f| f.to_string_lossy().to_string()))
        .collect();
    let out = dir.join("out.txt");
    let _ = std::fs::remove_file("/tmp/linuxcnc.lock");
    let status = Command::new("timeout")
        .args(["-k", "5", "600", "linuxcnc"])
        .arg(dir.join("contour.ini"))
        .current_dir(dir)
        .env("RTAPI_UID", "65534")
        .env("RTAPI_FIFO_PATH", dir.join("rtapi_fifo"))
        .env("PEER_PROGRAMS", order.join(":"))
        .env("PEER_OUT", &out)
        .output()
        .map_err(|e| e.to_string())?;
    let text = std::fs::read_to_string(&out)
        .map_err(|e| format!("no result ({e}); linuxcnc exited with {}", status.status))?;
    let mut times: Vec<Vec<f64>> = vec![Vec::new(); files.len()];
    for line in text.lines() {
        let (what, value) = line
            .rsplit_once(' ')
            .ok_or_else(|| format!("bad line {line:?}"))?;
        let k = files
            .iter()
            .position(|f| f.to_string_lossy() == what)
            .ok_or_else(|| format!("LinuxCNC: {line}"))?;
        let t: f64 = value.parse().map_err(|_| format!("bad time in {line:?}"))?;
        if t <= 0.0 {
            return Err(format!("LinuxCNC did not move for {what}"));
        }
        times[k].push(t);
    }
    times
        .into_iter()
        .map(|t| {
            if t.len() == repeats {
                Ok(bench_kit::median(t))
            } else {
                Err(format!("{} of {repeats} runs reported", t.len()))
            }
        })
        .collect()
}
