//! The standard function blocks on their instances' memory (the offsets are
//! [`crate::layout::std_fb`]'s): the timers on the cycle's clock, the edges, the counters and
//! the bistables; and the standard functions' values.

use super::{ops, Exec, Fault, V};
use crate::check::std_lib::StdFb;
use crate::ir::{Ex, StdFn};
use crate::types::Elem;

type Run<T> = Result<T, Fault>;

/// Timer state at byte 2: running (bit 0), the last IN (bit 1), TOF's delay finished (bit 2);
/// the start at byte 16 (ns).
const STATE: usize = 2;
const START: usize = 16;

impl Exec<'_> {
    #[inline(never)]
    pub(super) fn std_fn(&mut self, f: StdFn, t: Elem, args: &[Ex], base: u32) -> Run<V> {
        // At most MAX_STD_VALUES (the lowering refuses more): no allocation for them.
        let mut values = [V::I(0); crate::ir::MAX_STD_VALUES];
        let n = args.len().min(values.len());
        for (v, a) in values.iter_mut().zip(args) {
            *v = self.eval(a, base)?;
        }
        let v = match f {
            // The cycle's clock: TIME in whole ms (wrapping as TIME does), LTIME in ns.
            StdFn::Now if t == Elem::LTime => Ok(V::I(self.st.now_ns)),
            StdFn::Now => Ok(V::I(ops::wrap(self.st.now_ns / 1_000_000, t))),
            StdFn::MemCpy | StdFn::MemSet | StdFn::MemCmp => self.bytes_fn(f, &values),
            _ => ops::standard(f, t, &values[..n]),
        };
        if v == Err(Fault::MuxSelector) {
            return Err(self.fault_with(Fault::MuxSelector, [values[0].int(), 0, 0]));
        }
        v
    }

    /// MEMCPY, MEMSET, MEMCMP on the program's own memory (the image's leaves are read and
    /// written one at a time, by their rules: a pointer into it is [`Fault::ImageCopy`]).
    fn bytes_fn(&mut self, f: StdFn, v: &[V]) -> Run<V> {
        let n = v[2].int();
        let to = self.own_span(v[0].int(), n)?;
        match f {
            StdFn::MemSet => self.st.memory[to].fill(v[1].int() as u8),
            StdFn::MemCmp => {
                let from = self.own_span(v[1].int(), n)?;
                let m = &self.st.memory;
                return Ok(V::I(match m[to].cmp(&m[from]) {
                    std::cmp::Ordering::Less => -1,
                    std::cmp::Ordering::Equal => 0,
                    std::cmp::Ordering::Greater => 1,
                }));
            }
            _ => {
                let from = self.own_span(v[1].int(), n)?;
                self.st.memory.copy_within(from, to.start);
            }
        }
        Ok(V::I(n))
    }

    /// The `n` bytes of the program's own memory from where tagged pointer `p` points.
    fn own_span(&self, p: i64, n: i64) -> Run<std::ops::Range<usize>> {
        let n = usize::try_from(n).map_err(|_| Fault::OutOfRange)?;
        match super::pointed(p)? {
            super::Loc::Image(_) => Err(Fault::ImageCopy),
            super::Loc::Own(at) => {
                let end = at.checked_add(n).filter(|e| *e <= self.st.memory.len());
                Ok(at..end.ok_or(Fault::BadPointer)?)
            }
        }
    }

    fn flag(&self, at: usize) -> Run<bool> {
        Ok(self.read_own(at, Elem::Bool)?.int() != 0)
    }

    fn set_flag(&mut self, at: usize, v: bool) -> Run<()> {
        self.write_own(at, Elem::Bool, V::I(i64::from(v)))
    }

    pub(super) fn run_std_fb(&mut self, fb: StdFb, at: usize) -> Run<()> {
        match fb {
            StdFb::Ton | StdFb::Tof | StdFb::Tp => self.timer(fb, at),
            StdFb::RTrig | StdFb::FTrig => {
                let (clk, last) = (self.flag(at)?, self.flag(at + 2)?);
                let q = if fb == StdFb::RTrig {
                    clk && !last
                } else {
                    !clk && last
                };
                self.set_flag(at + 1, q)?;
                self.set_flag(at + 2, clk)
            }
            StdFb::Ctu | StdFb::Ctd => self.counter(fb, at),
            StdFb::Ctud => self.up_down(at),
            StdFb::Rs => {
                let (set, reset, q) = (self.flag(at)?, self.flag(at + 1)?, self.flag(at + 2)?);
                self.set_flag(at + 2, !reset && (set || q))
            }
            StdFb::Sr => {
                let (set, reset, q) = (self.flag(at)?, self.flag(at + 1)?, self.flag(at + 2)?);
                self.set_flag(at + 2, set || (!reset && q))
            }
        }
    }

    /// TON, TOF and TP: PT and ET are TIME (ms), the clock the cycle's.
    fn timer(&mut self, fb: StdFb, at: usize) -> Run<()> {
        let input = self.flag(at)?;
        let pt = i64::from(self.read_own(at + 4, Elem::Time)?.int() as i32).max(0);
        let state = self.read_own(at + STATE, Elem::Byte)?.int();
        let (running, last_in, mut done) = (state & 1 != 0, state & 2 != 0, state & 4 != 0);
        let start = self.read_own(at + START, Elem::LInt)?.int();
        let elapsed = ((self.st.now_ns - start) / 1_000_000).clamp(0, pt);
        let (mut q, mut et, mut run) = (false, 0, running);
        match fb {
            StdFb::Ton if input => {
                if !running {
                    self.write_own(at + START, Elem::LInt, V::I(self.st.now_ns))?;
                    run = true;
                }
                et = if running { elapsed } else { 0 };
                q = running && elapsed >= pt || pt == 0;
            }
            StdFb::Ton => run = false,
            StdFb::Tof if input => {
                q = true;
                run = false;
                done = false;
            }
            StdFb::Tof => {
                let was_on = self.flag(at + 1)?;
                if was_on && !running {
                    self.write_own(at + START, Elem::LInt, V::I(self.st.now_ns))?;
                    run = true;
                }
                et = match (running, done) {
                    (true, _) => elapsed,
                    (false, true) => pt,
                    (false, false) => 0,
                };
                q = (was_on && !running && pt > 0) || (running && elapsed < pt);
                run = run && q;
                // A finished delay holds ET at PT until IN rises again.
                done = done || (was_on && !q);
            }
            _ => {
                // TP: a rising IN starts a pulse of PT that nothing cuts short.
                if input && !last_in && !running {
                    self.write_own(at + START, Elem::LInt, V::I(self.st.now_ns))?;
                    run = true;
                }
                let pulse_elapsed = if running { elapsed } else { 0 };
                q = run && pulse_elapsed < pt;
                et = if run {
                    pulse_elapsed
                } else if input {
                    pt
                } else {
                    0
                };
                run = q;
            }
        }
        self.set_flag(at + 1, q)?;
        self.write_own(at + 8, Elem::Time, V::I(et))?;
        let state = i64::from(run) | (i64::from(input) << 1) | (i64::from(done) << 2);
        self.write_own(at + STATE, Elem::Byte, V::I(state))
    }

    /// CTUD: RESET before LOAD before the edges; rising edges of both CU and CD at once
    /// leave CV as it is; CV stays within INT.
    fn up_down(&mut self, at: usize) -> Run<()> {
        let (cu, cd) = (self.flag(at)?, self.flag(at + 1)?);
        let (reset, load) = (self.flag(at + 2)?, self.flag(at + 3)?);
        let (up, down) = (cu && !self.flag(at + 6)?, cd && !self.flag(at + 7)?);
        let pv = self.read_own(at + 8, Elem::Int)?.int();
        let mut cv = self.read_own(at + 10, Elem::Int)?.int();
        if reset {
            cv = 0;
        } else if load {
            cv = pv;
        } else if up && !down && cv < i64::from(i16::MAX) {
            cv += 1;
        } else if down && !up && cv > i64::from(i16::MIN) {
            cv -= 1;
        }
        self.write_own(at + 10, Elem::Int, V::I(cv))?;
        self.set_flag(at + 4, cv >= pv)?;
        self.set_flag(at + 5, cv <= 0)?;
        self.set_flag(at + 6, cu)?;
        self.set_flag(at + 7, cd)
    }

    /// CTU and CTD: the counter's edge input, RESET or LOAD, PV and CV as INT.
    fn counter(&mut self, fb: StdFb, at: usize) -> Run<()> {
        let (edge_in, clear, last) = (self.flag(at)?, self.flag(at + 1)?, self.flag(at + 3)?);
        let pv = self.read_own(at + 4, Elem::Int)?.int();
        let mut cv = self.read_own(at + 6, Elem::Int)?.int();
        let rising = edge_in && !last;
        if fb == StdFb::Ctu {
            if clear {
                cv = 0;
            } else if rising && cv < i64::from(i16::MAX) {
                cv += 1;
            }
            self.set_flag(at + 2, cv >= pv)?;
        } else {
            if clear {
                cv = pv;
            } else if rising && cv > i64::from(i16::MIN) {
                cv -= 1;
            }
            self.set_flag(at + 2, cv <= 0)?;
        }
        self.write_own(at + 6, Elem::Int, V::I(cv))?;
        self.set_flag(at + 3, edge_in)
    }
}
