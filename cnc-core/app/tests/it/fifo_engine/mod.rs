//! The FIFO engine's part of a scenario file: a `[[fifo_group]]` out of range is refused at
//! load. The engine's own tests (set-points, override, refusals, members) run next to the
//! engine, on the library's machine harness (`cnc-core/src/fifo/engine_tests/`).

use cnc_app::scenario::Scenario;

/// A scenario's FIFO group out of range is refused at load with the group and the reason.
#[test]
fn a_bad_fifo_group_is_refused_at_load() {
    for (group, needle) in [
        (
            "dimension = 0\nrows = 10\nfifo_cycle_ms = 1.0\n",
            "FIFO dimension 0",
        ),
        (
            "dimension = 17\nrows = 10\nfifo_cycle_ms = 1.0\n",
            "FIFO dimension 17",
        ),
        (
            "dimension = 2\nrows = 1\nfifo_cycle_ms = 1.0\n",
            "FIFO length 1",
        ),
        (
            "dimension = 2\nrows = 10\nfifo_cycle_ms = 0.0\n",
            "FIFO cycle 0 s",
        ),
        (
            "dimension = 2\nrows = 10\nfifo_cycle_ms = -2.0\n",
            "FIFO cycle -0.002 s",
        ),
        (
            "dimension = 2\nrows = 10\nfifo_cycle_ms = 1.0\noverride = \"pt2\"\n",
            "needs pt2_t0_ms",
        ),
        (
            "dimension = 2\nrows = 10\nfifo_cycle_ms = 1.0\noverride = \"soft\"\n",
            "\"instant\" or \"pt2\"",
        ),
    ] {
        let toml =
            format!("cycle_ms = 1.0\nticks = 10\n[[axis]]\nname = \"X\"\n[[fifo_group]]\n{group}");
        let e = Scenario::parse("bad.toml", &toml, |f| panic!("{f}")).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("[[fifo_group]] 0") || text.contains(needle),
            "{text}"
        );
        assert!(text.contains(needle), "{text}");
    }
}
