#!/usr/bin/env python3
"""Runs every benchmark of the workspace and writes one markdown report.

    python3 tests/bench-suite.py            # the full suite -> docs/benchmarks/README.md
    python3 tests/bench-suite.py --smoke    # every bench, counts cut, dev build -> out/bench/README.md (CI)
    python3 tests/bench-suite.py --only scaling,cam --out /tmp/report

Peers the benches compare with (cyclictest from rt-tests, LinuxCNC's rs274 from
linuxcnc-uspace) are installed with apt-get when they are missing and this runs as root;
otherwise, or when that fails, the report names them as skipped. Every bench prints its
targets as `TARGET | what | figure | verdict` lines; the report gathers them in one table,
each figure beside its in-run baseline, followed by every bench's own output. The exit
status is 1 when a bench fails to run to its end (a missed target is reported, not failed).
"""

import argparse
import datetime
import os
import platform
import shutil
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent

# (package, bench, what it measures, its in-run baselines). The order is the report's.
BENCHES = [
    ("hli-transport", "handshake", "cross-process handshake round trip",
     "flag ping-pong, iceoryx2 pub-sub and event ping-pong, Unix socket"),
    ("kinematics", "kinematics", "robot kinematics per call", "rs-opw-kinematics"),
    ("cnc-core", "nc_parse", "NC parse + decode", "LinuxCNC rs274"),
    ("cnc-app", "nc_check", "`cnc check` whole process", "LinuxCNC rs274 (whole process)"),
    ("cnc-core", "axes", "axis layer per axis-tick", "image reads and writes only"),
    ("cnc-app", "channels", "channel tick, examples 3 and 4, the demo twin",
     "idle channels, the path before the machine tick"),
    ("cnc-core", "cam", "cam evaluation", "binary search with linear interpolation"),
    ("cnc-core", "cam_slave", "a cam slave in the machine tick", "an uncoupled axis"),
    ("cnc-core", "fifo", "FIFO group tick, rows across processes",
     "standing axes, a transport-only handler"),
    ("cnc-core", "saw", "flying-saw planning per command", "rsruckig"),
    ("cnc-core", "contour", "continuous path against exact stop",
     "exact stop, a lower bound, LinuxCNC's planner, the exact-stop channel tick"),
    ("cnc-app", "scaling", "machine tick against machine size", "its own smallest size"),
    ("cnc-app", "tick_latency", "tick start lateness, whole processes", "cyclictest"),
    ("cnc-opcua", "lateness", "tick lateness with an OPC UA client of 1,000 items",
     "the same run without the client"),
    ("plc-st", "st", "Structured Text: a 1,000-statement cycle, a 10,000-line load",
     "the same arithmetic in Rust"),
    ("plc-shim", "st_programs", "the turntable PLC program: ST against Rust",
     "the same program in Rust, the same image"),
    ("cnc-app", "demo_st", "the demo machine's PLC program: ST against Rust, whole processes",
     "cnc demo with the Rust program"),
]

# Peer program -> Debian package.
PEERS = {"cyclictest": "rt-tests", "rs274": "linuxcnc-uspace"}


def run(cmd, **kw):
    return subprocess.run(cmd, capture_output=True, text=True, **kw)


def install_peers(allowed):
    """Each peer: 'present', 'installed now' or 'skipped: why'."""
    state = {}
    updated = False
    for program, package in PEERS.items():
        if shutil.which(program):
            state[program] = "present"
            continue
        if not allowed:
            state[program] = f"skipped: not installed (--no-install; apt-get install {package})"
            continue
        if os.geteuid() != 0 or not shutil.which("apt-get"):
            state[program] = f"skipped: not installed (needs root and apt-get: {package})"
            continue
        env = dict(os.environ, DEBIAN_FRONTEND="noninteractive")
        r = run(["apt-get", "install", "-y", "-qq", package], env=env)
        if r.returncode != 0 and not updated:
            updated = True
            run(["apt-get", "update", "-qq"], env=env)
            r = run(["apt-get", "install", "-y", "-qq", package], env=env)
        if r.returncode == 0 and shutil.which(program):
            state[program] = f"installed now ({package})"
        else:
            tail = (r.stderr.strip().splitlines() or ["no output"])[-1]
            state[program] = f"skipped: apt-get install {package} failed: {tail}"
    return state


def first_line(cmd):
    try:
        r = run(cmd)
        return (r.stdout.strip().splitlines() or ["?"])[0]
    except OSError:
        return "?"


def machine():
    model, cores = "?", os.cpu_count()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                model = line.split(":", 1)[1].strip()
                break
        mem = next(line for line in Path("/proc/meminfo").read_text().splitlines()
                   if line.startswith("MemTotal"))
        mem_gib = int(mem.split()[1]) / 1024 / 1024
    except (OSError, StopIteration, ValueError):
        mem_gib = 0.0
    return [
        ("CPU", f"{model}, {cores} logical cores"),
        ("memory", f"{mem_gib:.1f} GiB"),
        ("kernel", f"{platform.release()} ({platform.version()})"),
        ("rustc", first_line(["rustc", "-V"])),
        ("commit", first_line(["git", "-C", str(ROOT), "rev-parse", "--short", "HEAD"])),
        ("date", datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")),
    ]


# Benches the smoke mode leaves out, and why (clippy --all-targets still compiles them).
SMOKE_SKIPS = {
    "lateness": "its release build of the OPC UA stack and its real-time runs cost CI over three "
                "minutes of the twenty; the full suite runs it",
}


def run_bench(package, bench, env):
    """(exit code, seconds, the bench's own output)."""
    t0 = time.monotonic()
    if env.get("CNC_BENCH_SMOKE") == "1" and bench in SMOKE_SKIPS:
        return 0, 0.0, f"skipped in smoke mode: {SMOKE_SKIPS[bench]}\n"
    cmd = ["cargo", "bench", "-q", "-p", package, "--bench", bench]
    if env.get("CNC_BENCH_SMOKE") == "1":
        # A smoke run asserts no figure: it runs the benches in the build `cargo test
        # --workspace` has just made (dev profile, the workspace's feature set) instead of
        # compiling the workspace a third time in release (four to six minutes of CI's twenty).
        cmd = ["cargo", "bench", "-q", "--workspace", "--profile", "dev", "--bench", bench]
    r = run(cmd, cwd=ROOT, env=env)
    seconds = time.monotonic() - t0
    text = r.stdout
    if r.returncode != 0:
        text += "\n" + "\n".join(r.stderr.strip().splitlines()[-30:])
    return r.returncode, seconds, text


def targets(text):
    rows = []
    for line in text.splitlines():
        if line.startswith("TARGET |"):
            cells = [c.strip() for c in line.split("|")[1:]]
            if len(cells) >= 3:
                rows.append((cells[0], cells[1], " | ".join(cells[2:])))
    return rows


def report(results, peers, smoke, wall, out_dir):
    out = ["# Benchmark report", ""]
    if smoke:
        out.append("Written by `python3 tests/bench-suite.py --smoke`: a smoke run, every count"
                   " cut; no figure is meant.")
    else:
        out.append("Written by `python3 tests/bench-suite.py`. Every figure is from this one run,"
                   " on this machine, beside its baseline measured in the same run:")
    out.append("")
    out += ["| machine | |", "| --- | --- |"]
    out += [f"| {k} | {v} |" for k, v in machine()]
    out += ["", "Peers: " + "; ".join(f"`{p}` {s}" for p, s in peers.items()) + ".", ""]
    out += ["## Targets", "",
            "| bench | target | figure (in-run baseline) | verdict |", "| --- | --- | --- | --- |"]
    counts = {"met": 0, "missed": 0, "other": 0}
    for (package, bench, _, _), (code, _, text) in zip(BENCHES, results):
        rows = targets(text) if code == 0 else [("runs to its end", "-", "FAILED")]
        for what, figure, verdict in rows:
            if smoke and verdict != "FAILED":
                verdict = "smoke"
            key = "met" if verdict == "met" else "missed" if verdict.startswith("MISSED") or verdict == "FAILED" else "other"
            counts[key] += 1
            out.append(f"| {bench} | {what} | {figure} | {verdict} |")
    out += ["", f"{counts['met']} met, {counts['missed']} missed, {counts['other']} skipped or not judged;"
            f" the suite took {wall / 60:.1f} min.", ""]
    if (out_dir / "scaling.svg").exists() and not smoke:
        out += ["![tick cost against machine size](scaling.svg)", ""]
    out += ["## Each bench", ""]
    for (package, bench, what, baseline), (code, seconds, text) in zip(BENCHES, results):
        status = "ran to its end" if code == 0 else f"FAILED (exit {code})"
        out += [f"### {bench}: {what}", "",
                f"`cargo bench -p {package} --bench {bench}`; in-run baseline: {baseline};"
                f" {status} in {seconds:.0f} s.", "", "```text", text.rstrip(), "```", ""]
    return "\n".join(out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--smoke", action="store_true", help="CNC_BENCH_SMOKE=1: seconds, no figures")
    ap.add_argument("--no-install", action="store_true", help="do not apt-get missing peers")
    ap.add_argument("--only", help="comma-separated bench names")
    ap.add_argument("--out", help="report folder (default docs/benchmarks, out/bench with --smoke)")
    args = ap.parse_args()
    global BENCHES
    if args.only:
        wanted = set(args.only.split(","))
        unknown = wanted - {b for _, b, _, _ in BENCHES}
        if unknown:
            sys.exit(f"bench-suite: unknown bench(es): {', '.join(sorted(unknown))}")
        BENCHES = [b for b in BENCHES if b[1] in wanted]
    out_dir = Path(args.out) if args.out else ROOT / ("out/bench" if args.smoke else "docs/benchmarks")
    out_dir.mkdir(parents=True, exist_ok=True)
    peers = install_peers(not args.no_install)
    env = dict(os.environ, CNC_BENCH_OUT=str(out_dir))
    if args.smoke:
        env["CNC_BENCH_SMOKE"] = "1"
    t0 = time.monotonic()
    results = []
    for package, bench, _, _ in BENCHES:
        print(f"bench-suite: {package} {bench} ...", flush=True)
        results.append(run_bench(package, bench, env))
        code, seconds, _ = results[-1]
        print(f"bench-suite: {bench} {'ok' if code == 0 else f'FAILED ({code})'} in {seconds:.0f} s", flush=True)
    text = report(results, peers, args.smoke, time.monotonic() - t0, out_dir)
    (out_dir / "README.md").write_text(text + "\n")
    print(f"bench-suite: report {out_dir / 'README.md'}")
    failed = [b for (_, b, _, _), (c, _, _) in zip(BENCHES, results) if c != 0]
    if failed:
        print(f"bench-suite: failed: {', '.join(failed)}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
