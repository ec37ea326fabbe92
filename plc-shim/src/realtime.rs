//! Real-time options of a cyclic process (the CNC's tick loop, the PLC's cycle): SCHED_FIFO
//! priority, CPU pinning, locked memory with a pre-faulted stack, timer slack, a bound on the
//! CPUs' wake-up latency. They come from
//! the machine configuration and from flags (flags win); each one the system refuses is left
//! out with one warning, and the process runs on without it.

use serde::Deserialize;

/// Stack pre-faulted when memory is locked.
const PREFAULT_STACK: usize = 512 * 1024;

/// The options; all off by default.
#[derive(Debug, Clone, Default, PartialEq, Eq, clap::Args, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RealtimeOptions {
    /// Run the cyclic thread under SCHED_FIFO at this priority (1..=99).
    #[arg(long = "rt-priority")]
    pub priority: Option<i32>,
    /// Pin the cyclic thread to this CPU.
    #[arg(long = "rt-cpu")]
    pub cpu: Option<usize>,
    /// Lock all memory (mlockall) and pre-fault the stack.
    #[arg(long = "rt-lock-memory")]
    #[serde(default)]
    pub lock_memory: bool,
    /// Timer slack of the cyclic thread, ns (1 is the least).
    #[arg(long = "rt-timer-slack-ns")]
    pub timer_slack_ns: Option<u64>,
    /// Hold every CPU's wake-up latency at most this many us (`/dev/cpu_dma_latency`, as
    /// cyclictest does): no deep idle state delays the tick's wake-up.
    #[arg(long = "rt-cpu-wake-latency-us")]
    pub cpu_wake_latency_us: Option<u32>,
    /// How the CNC wakes the PLC for a tick in real time: `event` (iceoryx2's event, the
    /// default), `futex` (the PLC sleeps on the low word of the CNC's heartbeat in the
    /// segment, the CNC wakes it with one `futex(2)` call) or `spin` (as `futex`, but the PLC
    /// wakes by a timed sleep shortly before the tick is due and spins on that word until the
    /// tick is done, at most half a cycle (and 500 us) past its due time, before it sleeps on
    /// it: its wake-up no longer waits for the scheduler after the tick; it takes a core for
    /// the spin). The CNC hands its choice to the PLC it spawns.
    #[arg(long = "rt-wake", value_enum)]
    pub wake: Option<WakePath>,
}

/// How a sleeping PLC is woken for a tick.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, clap::ValueEnum, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum WakePath {
    /// iceoryx2's event service ("tick done").
    #[default]
    Event,
    /// A futex on the low word of the CNC's heartbeat in the segment.
    Futex,
    /// A timed sleep to shortly before the tick is due, a bounded spin on the heartbeat's
    /// word, then its futex.
    Spin,
}

impl WakePath {
    /// Its name on the command line.
    pub fn name(self) -> &'static str {
        match self {
            WakePath::Event => "event",
            WakePath::Futex => "futex",
            WakePath::Spin => "spin",
        }
    }

    /// Whether the CNC wakes the PLC on the heartbeat's word (`futex` and `spin`).
    pub fn on_the_word(self) -> bool {
        matches!(self, WakePath::Futex | WakePath::Spin)
    }
}

impl RealtimeOptions {
    /// These options where set, `file`'s elsewhere.
    pub fn over(&self, file: &RealtimeOptions) -> RealtimeOptions {
        RealtimeOptions {
            priority: self.priority.or(file.priority),
            cpu: self.cpu.or(file.cpu),
            lock_memory: self.lock_memory || file.lock_memory,
            timer_slack_ns: self.timer_slack_ns.or(file.timer_slack_ns),
            cpu_wake_latency_us: self.cpu_wake_latency_us.or(file.cpu_wake_latency_us),
            wake: self.wake.or(file.wake),
        }
    }

    /// The options for the PLC process a CNC with these options spawns: one priority below
    /// the CNC's thread (the tick comes first), the same memory lock and timer slack, no CPU
    /// of its own (the scenario's `[realtime_plc]` can pin it), except that a PLC that spins
    /// for its ticks (`--rt-wake spin`) beside a CNC pinned to a CPU goes to another (the
    /// lowest other: CPU 0, or 1 beside a CNC on 0), so its spin never takes the tick's core.
    pub fn for_plc(&self) -> RealtimeOptions {
        let beside = match (self.wake, self.cpu) {
            (Some(WakePath::Spin), Some(cpu)) => Some(usize::from(cpu == 0)),
            _ => None,
        };
        RealtimeOptions {
            priority: self.priority.map(|p| p.saturating_sub(1).max(1)),
            cpu: beside,
            lock_memory: self.lock_memory,
            timer_slack_ns: self.timer_slack_ns,
            // The CNC's request holds for the whole machine.
            cpu_wake_latency_us: None,
            // Both ends wake the same way.
            wake: self.wake,
        }
    }

    /// The options the latency benchmarks run the CNC with: SCHED_FIFO 80, locked memory,
    /// timer slack 1 ns and no deep idle state (as cyclictest does by default); no CPU.
    pub fn measured() -> RealtimeOptions {
        RealtimeOptions {
            priority: Some(80),
            cpu: None,
            lock_memory: true,
            timer_slack_ns: Some(1),
            cpu_wake_latency_us: Some(0),
            wake: None,
        }
    }

    /// Whether any option is set.
    pub fn any(&self) -> bool {
        *self != RealtimeOptions::default()
    }

    /// The same options as command-line flags (for a process this one spawns).
    pub fn to_args(&self) -> Vec<String> {
        let mut args = Vec::new();
        if let Some(p) = self.priority {
            args.extend(["--rt-priority".to_string(), p.to_string()]);
        }
        if let Some(c) = self.cpu {
            args.extend(["--rt-cpu".to_string(), c.to_string()]);
        }
        if self.lock_memory {
            args.push("--rt-lock-memory".into());
        }
        if let Some(t) = self.timer_slack_ns {
            args.extend(["--rt-timer-slack-ns".to_string(), t.to_string()]);
        }
        if let Some(us) = self.cpu_wake_latency_us {
            args.extend(["--rt-cpu-wake-latency-us".to_string(), us.to_string()]);
        }
        if let Some(w) = self.wake {
            args.extend(["--rt-wake".to_string(), w.name().to_string()]);
        }
        args
    }

    /// Applies the options to the calling thread and process. Each refused one is left out
    /// with one warning on stderr naming `who`; returns the ones in force, for the report.
    pub fn apply(&self, who: &str) -> Vec<String> {
        let mut applied = Vec::new();
        #[cfg(target_os = "linux")]
        {
            use cnc_os::realtime as rt;
            let mut attempt = |name: String, result: std::io::Result<()>| match result {
                Ok(()) => applied.push(name),
                Err(e) => {
                    eprintln!("{who}: real-time option {name} refused ({e}); running without it")
                }
            };
            if self.lock_memory {
                let locked = rt::lock_memory();
                if locked.is_ok() {
                    rt::prefault_stack(PREFAULT_STACK);
                }
                attempt("locked memory".into(), locked);
            }
            if let Some(ns) = self.timer_slack_ns {
                attempt(format!("timer slack {ns} ns"), rt::set_timer_slack(ns));
            }
            if let Some(us) = self.cpu_wake_latency_us {
                attempt(
                    format!("CPU wake-up latency <= {us} us"),
                    rt::hold_cpu_wake_latency(us),
                );
            }
            if let Some(cpu) = self.cpu {
                attempt(format!("CPU {cpu}"), rt::pin_to_cpu(cpu));
            }
            if let Some(p) = self.priority {
                attempt(format!("SCHED_FIFO {p}"), rt::set_fifo_priority(p));
            }
        }
        #[cfg(not(target_os = "linux"))]
        if self.any() {
            eprintln!("{who}: real-time options need Linux; running without them");
        }
        match self.wake {
            Some(WakePath::Futex) => applied.push("wake-up by futex".into()),
            Some(WakePath::Spin) => applied.push("wake-up by a timed sleep and a spin".into()),
            _ => {}
        }
        applied
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spinning_plc_goes_beside_a_pinned_cnc() {
        let cnc = |cpu, wake| RealtimeOptions {
            cpu,
            wake,
            ..RealtimeOptions::default()
        };
        let spin = Some(WakePath::Spin);
        assert_eq!(cnc(Some(1), spin).for_plc().cpu, Some(0));
        assert_eq!(cnc(Some(0), spin).for_plc().cpu, Some(1));
        assert_eq!(cnc(Some(3), spin).for_plc().cpu, Some(0));
        assert_eq!(cnc(None, spin).for_plc().cpu, None);
        assert_eq!(cnc(Some(1), Some(WakePath::Futex)).for_plc().cpu, None);
        assert_eq!(WakePath::Spin.name(), "spin");
    }

    #[test]
    fn flags_win_over_the_file_and_round_trip_as_arguments() {
        let file = RealtimeOptions {
            priority: Some(70),
            cpu: Some(1),
            lock_memory: false,
            timer_slack_ns: Some(1000),
            cpu_wake_latency_us: Some(0),
            wake: Some(WakePath::Futex),
        };
        let flags = RealtimeOptions {
            priority: Some(80),
            ..RealtimeOptions::default()
        };
        let o = flags.over(&file);
        assert_eq!(
            (o.priority, o.cpu, o.timer_slack_ns),
            (Some(80), Some(1), Some(1000))
        );
        assert_eq!(
            o.to_args(),
            [
                "--rt-priority",
                "80",
                "--rt-cpu",
                "1",
                "--rt-timer-slack-ns",
                "1000",
                "--rt-cpu-wake-latency-us",
                "0",
                "--rt-wake",
                "futex"
            ]
        );
        assert_eq!(
            o.for_plc().wake,
            Some(WakePath::Futex),
            "both ends wake alike"
        );
    }

    #[test]
    fn a_refused_option_is_left_out_and_the_rest_applies() {
        let o = RealtimeOptions {
            priority: Some(1000),
            timer_slack_ns: Some(50_000),
            ..RealtimeOptions::default()
        };
        assert_eq!(o.apply("test"), vec!["timer slack 50000 ns".to_string()]);
    }
}
