//! The simulated drive's touch-probe inputs: a sensor is on while the motor stands inside its
//! window, and a probe enabled through the encoder outputs latches the exact position of the
//! edge (where the motor crossed the window's boundary, between two ticks), as a real probe
//! input latches in hardware.

use super::config::ProbeInterface;
use super::increments::CounterWidth;
use super::probe::*;
use hli::layout::{NcEncoderIn, NcEncoderOut};

/// Latched edges of one probe input: `[rising, falling]`, each the raw count or none.
type Edges = [Option<i32>; 2];

/// The probe inputs of a simulated encoder.
#[derive(Debug, Clone)]
pub struct SimProbes {
    interface: ProbeInterface,
    width: CounterWidth,
    scale: f64,
    /// Sensor windows `[from, to]` of probe inputs 1 and 2, axis units.
    windows: [Option<[f64; 2]>; 2],
    latched: [Edges; 2],
}

impl SimProbes {
    /// Probe inputs with these sensor windows.
    pub fn new(
        interface: ProbeInterface,
        width: CounterWidth,
        scale: f64,
        windows: [Option<[f64; 2]>; 2],
    ) -> Self {
        Self {
            interface,
            width,
            scale,
            windows,
            latched: [[None; 2]; 2],
        }
    }

    /// Which edges of probe `k` the encoder outputs enable: `[rising, falling]`.
    fn enabled(&self, out: &NcEncoderOut, k: usize) -> [bool; 2] {
        match self.interface {
            ProbeInterface::None => [false; 2],
            ProbeInterface::Terminal if k == 0 => [
                out.nCtrl1 & TERMINAL_LATCH_POSITIVE != 0,
                out.nCtrl1 & TERMINAL_LATCH_NEGATIVE != 0,
            ],
            ProbeInterface::Terminal => [false; 2],
            ProbeInterface::Canopen => {
                let c = [out.nCtrl5, out.nCtrl6][k];
                let on = c & CANOPEN_ENABLE != 0;
                [
                    on && c & CANOPEN_POSITIVE != 0,
                    on && c & CANOPEN_NEGATIVE != 0,
                ]
            }
            ProbeInterface::Sercos => {
                let on = [out.nCtrl5, out.nCtrl6][k] & SERCOS_ENABLE != 0;
                [on, on]
            }
        }
    }

    /// The motor moved from `from` to `to` during this tick: enabled probes latch the edges
    /// they see (the first of each kind: first-event mode); a disabled probe forgets.
    pub fn step(&mut self, out: &NcEncoderOut, from: f64, to: f64, count_offset: i64) {
        for k in 0..2 {
            let enabled = self.enabled(out, k);
            let Some([lo, hi]) = self.windows[k] else {
                continue;
            };
            // Moving up the sensor switches on at `lo` and off at `hi`; moving down the other
            // way round.
            let (on_at, off_at) = if to >= from { (lo, hi) } else { (hi, lo) };
            let crossed = |p: f64| (from < p && p <= to) || (to <= p && p < from);
            for (edge, at) in [(0, on_at), (1, off_at)] {
                if !enabled[edge] {
                    self.latched[k][edge] = None;
                } else if self.latched[k][edge].is_none() && crossed(at) {
                    let count = (at * self.scale).round() as i64 + count_offset;
                    self.latched[k][edge] = Some(self.width.wrap(count));
                }
            }
        }
    }

    /// Writes the probe status and positions into the encoder inputs.
    pub fn report(&self, out: &NcEncoderOut, enc: &mut NcEncoderIn) {
        let value = |e: Option<i32>| e.unwrap_or(0);
        let [p1, p2] = self.latched;
        match self.interface {
            ProbeInterface::None => {}
            ProbeInterface::Terminal => {
                let e = p1[0].or(p1[1]);
                enc.nStatus1 = if e.is_some() { TERMINAL_LATCH_VALID } else { 0 };
                enc.nInData2 = value(e);
            }
            ProbeInterface::Canopen => {
                let status = |k: usize, edges: Edges| {
                    let mut s = u8::from([out.nCtrl5, out.nCtrl6][k] & CANOPEN_ENABLE != 0);
                    if edges[0].is_some() {
                        s |= CANOPEN_POSITIVE_STORED;
                    }
                    if edges[1].is_some() {
                        s |= CANOPEN_NEGATIVE_STORED;
                    }
                    s
                };
                enc.nStatus5 = status(0, p1);
                enc.nStatus6 = status(1, p2);
            }
            ProbeInterface::Sercos => {
                enc.nStatus5 = u8::from(p1[0].is_some());
                enc.nStatus6 = u8::from(p1[1].is_some());
                enc.nStatus7 = u8::from(p2[0].is_some());
                enc.nStatus8 = u8::from(p2[1].is_some());
            }
        }
        if matches!(
            self.interface,
            ProbeInterface::Canopen | ProbeInterface::Sercos
        ) {
            enc.nInData3 = value(p1[0]);
            enc.nInData4 = value(p1[1]);
            enc.nInData5 = value(p2[0]);
            enc.nInData6 = value(p2[1]);
        }
    }
}
