//! How a cam couples a slave to a master (seed 000, chapters 4.3 to 4.5 and 5.1.4, the data
//! types of 5.1.16): the master position is offset, measured from the coupling position when
//! the master is relative, divided by the master scaling, and (cyclic cams) folded into the
//! cam's master period with a cycle counter; the profile gives the raw slave value, which is
//! multiplied by the slave scaling (the stroke per period too), offset, and measured from the
//! slave's coupling position when the slave is relative:
//!
//! ```text
//! x      = (MO + Pm - [Pmc]) / MS            cam master coordinate (unwrapped)
//! local  = x folded into [first, first + period), cycle = how many periods were folded
//! Ps     = [Psc] + SO + SS * (T(local) + SH * (cycle - cycle at coupling))
//! ```
//!
//! The stroke counts from the coupling on: a slave always couples in the cam's base cycle
//! (seed 5.1.4), wherever the master stands, and falls back into it when it couples again;
//! switches and rescalings carry the count on.
//!
//! Velocity, acceleration and jerk follow from the chain rule with the master's own
//! derivatives, so a coupled slave moves as smoothly as its master and its profile allow.
//! Also here: which activation mode goes with which start and scaling mode (5.1.16.13), and
//! the automatic offsets that keep the master's place in the cam and the slave's position
//! when a coupling is switched or rescaled (5.1.16.14). Pure computation: the cam engine
//! (`crate::cam::machine`) feeds in the axes.

use super::online::{ActivationMode, EdgeCrossing, MasterNow};
use super::{CamProfile, ProfileCursor};
use crate::setpoint::Kinematic;
use hli::calls::cam::{CamActivationMode, CamScalingMode, CamStartMode};

/// `MC_CamActivationMode` as couplings and scalings use it (the online change of points uses
/// [`ActivationMode`], without the deletion).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Activation {
    /// 0: at once (in the next tick).
    Instantaneous,
    /// 1: when the master's position within the cam passes this value (in any cycle).
    AtMasterCamPos(f64),
    /// 2: when the master axis passes this absolute position.
    AtMasterAxisPos(f64),
    /// 3: at the next cycle boundary (a cyclic cam) or range edge (a linear one).
    NextCycle,
    /// 4: the seed marks it "not yet implemented"; refused.
    NextCycleOnce,
    /// 5: for point data only.
    AsSoonAsPossible,
    /// 6: nothing is changed.
    Off,
    /// 7: a queued, not yet active switch is dropped.
    DeleteQueuedData,
}

impl Activation {
    /// From the raw mode and its position.
    pub fn from_raw(raw: u32, position: f64) -> Option<Activation> {
        CamActivationMode::from_raw(raw).map(|mode| Activation::new(mode, position))
    }

    /// The mode with its position (the modes without one ignore it).
    pub fn new(mode: CamActivationMode, position: f64) -> Activation {
        match mode {
            CamActivationMode::Instantaneous => Activation::Instantaneous,
            CamActivationMode::AtMasterCamPos => Activation::AtMasterCamPos(position),
            CamActivationMode::AtMasterAxisPos => Activation::AtMasterAxisPos(position),
            CamActivationMode::NextCycle => Activation::NextCycle,
            CamActivationMode::NextCycleOnce => Activation::NextCycleOnce,
            CamActivationMode::AsSoonAsPossible => Activation::AsSoonAsPossible,
            CamActivationMode::Off => Activation::Off,
            CamActivationMode::DeleteQueuedData => Activation::DeleteQueuedData,
        }
    }

    /// The mode on the wire, without its position.
    pub fn mode(self) -> CamActivationMode {
        match self {
            Activation::Instantaneous => CamActivationMode::Instantaneous,
            Activation::AtMasterCamPos(_) => CamActivationMode::AtMasterCamPos,
            Activation::AtMasterAxisPos(_) => CamActivationMode::AtMasterAxisPos,
            Activation::NextCycle => CamActivationMode::NextCycle,
            Activation::NextCycleOnce => CamActivationMode::NextCycleOnce,
            Activation::AsSoonAsPossible => CamActivationMode::AsSoonAsPossible,
            Activation::Off => CamActivationMode::Off,
            Activation::DeleteQueuedData => CamActivationMode::DeleteQueuedData,
        }
    }

    /// The timing rule, for the modes that wait (`None` for the others).
    pub fn timing(self) -> Option<ActivationMode> {
        Some(match self {
            Activation::Instantaneous => ActivationMode::Instantaneous,
            Activation::AtMasterCamPos(p) => ActivationMode::AtMasterCamPos(p),
            Activation::AtMasterAxisPos(p) => ActivationMode::AtMasterAxisPos(p),
            Activation::NextCycle => ActivationMode::NextCycle,
            _ => return None,
        })
    }
}

/// Why a coupling, switch or scaling is refused before anything changes.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum CouplingError {
    /// A scaling or offset that is NaN or infinite, or a master scaling of 0.
    #[error("{what} {value} is not usable (finite, master scaling not 0)")]
    Parameter {
        /// Which value.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// The seed's tables forbid this combination (5.1.16.3, 5.1.16.13, 5.1.16.14).
    #[error("activation mode {activation} with start mode {start} (master auto-offset {master_auto}) is not allowed when {when}")]
    Combination {
        /// Raw activation mode.
        activation: u32,
        /// Raw start mode.
        start: u32,
        /// Whether the master offset was to be computed.
        master_auto: bool,
        /// "coupling", "switching" or "scaling".
        when: &'static str,
    },
    /// An activation position the master has passed already in its direction of travel.
    #[error("activation position {position} already passed (master at {master})")]
    Passed {
        /// The activation position.
        position: f64,
        /// The master now.
        master: f64,
    },
}

/// Offsets and scalings of a coupling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scaling {
    /// MO, added to the master position first.
    pub master_offset: f64,
    /// SO, added to the slave position last.
    pub slave_offset: f64,
    /// MS, divides the master position (not 0).
    pub master_scaling: f64,
    /// SS, multiplies the slave values and the stroke.
    pub slave_scaling: f64,
}

impl Default for Scaling {
    fn default() -> Self {
        Scaling {
            master_offset: 0.0,
            slave_offset: 0.0,
            master_scaling: 1.0,
            slave_scaling: 1.0,
        }
    }
}

impl Scaling {
    /// Refuses values that are not finite or so extreme that the law could overflow: offsets
    /// beyond 1e12, a master scaling below 1e-6 or above 1e6 in magnitude (0 included), a
    /// slave scaling above 1e6 in magnitude.
    pub fn check(&self) -> Result<(), CouplingError> {
        let values = [
            ("master offset", self.master_offset, 0.0, 1e12),
            ("slave offset", self.slave_offset, 0.0, 1e12),
            ("master scaling", self.master_scaling, 1e-6, 1e6),
            ("slave scaling", self.slave_scaling, 0.0, 1e6),
        ];
        for (what, value, min, max) in values {
            let magnitude = value.abs();
            if !(value.is_finite() && magnitude >= min && magnitude <= max) {
                return Err(CouplingError::Parameter { what, value });
            }
        }
        Ok(())
    }
}

/// Where the master stands in a cam.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct CamPosition {
    /// Cam master coordinate, not folded.
    pub x: f64,
    /// Folded into the master range (cyclic), or `x` itself (linear).
    pub local: f64,
    /// Periods folded (cyclic), 0 for a linear cam.
    pub cycle: i64,
}

/// One coupling: the law `Ps(Pm)` of the module docs, with the profile's geometry.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CamLaw {
    /// Offsets and scalings.
    pub scaling: Scaling,
    /// Absolute or relative, per side.
    pub start: CamStartMode,
    /// Cyclic (continued period by period) or linear (held at its edges).
    pub periodic: bool,
    /// Pmc: the master position at coupling (0 when the master is absolute).
    pub master_origin: f64,
    /// Psc: the slave position at coupling (0 when the slave is absolute).
    pub slave_origin: f64,
    first: f64,
    period: f64,
    stroke: f64,
    /// The cycle the master was in at coupling (the base cycle).
    cycle0: i64,
}

impl CamLaw {
    /// The law for `profile` coupled with the master at `master` and the slave at `slave`
    /// (the origins of the relative sides).
    pub fn new(
        profile: &CamProfile,
        scaling: Scaling,
        start: CamStartMode,
        periodic: bool,
        master: f64,
        slave: f64,
    ) -> CamLaw {
        let mut law = CamLaw {
            scaling,
            start,
            periodic,
            master_origin: if start.master_relative() { master } else { 0.0 },
            slave_origin: if start.slave_relative() { slave } else { 0.0 },
            first: 0.0,
            period: 0.0,
            stroke: 0.0,
            cycle0: 0,
        };
        law.take_geometry(profile);
        law.cycle0 = law.locate(master).cycle;
        law
    }

    /// Reads the master range and the stroke of `profile` (again after an online change).
    pub fn take_geometry(&mut self, profile: &CamProfile) {
        let (a, b) = profile.master_range();
        let (first, last) = (a.min(b), a.max(b));
        let mut cursor = ProfileCursor::default();
        let y0 = profile.eval(first, &mut cursor).position;
        let y1 = profile.eval(last, &mut cursor).position;
        self.first = first;
        self.period = last - first;
        self.stroke = y1 - y0;
    }

    /// First master position of the cam and its master period (range).
    pub fn range(&self) -> (f64, f64) {
        (self.first, self.period)
    }

    /// Cycles of the cam since the coupling (the stroke counter) at master position `master`.
    pub fn cycles_since_coupling(&self, master: f64) -> i64 {
        self.locate(master).cycle - self.cycle0
    }

    /// Slave stroke per master period (raw, before the slave scaling).
    pub fn stroke(&self) -> f64 {
        self.stroke
    }

    /// Where master position `master` lies in the cam.
    pub fn locate(&self, master: f64) -> CamPosition {
        let s = &self.scaling;
        let x = (s.master_offset + master - self.master_origin) / s.master_scaling;
        if !self.periodic || self.period <= 0.0 {
            return CamPosition {
                x,
                local: x,
                cycle: 0,
            };
        }
        let (local, cycle) = super::fold_period(x, self.first, self.period);
        CamPosition { x, local, cycle }
    }

    /// The slave set-point for the master set-point `master`, and where the master lies in
    /// the cam. A linear cam holds the slave at its edge value outside its range.
    pub fn slave(
        &self,
        profile: &CamProfile,
        cursor: &mut ProfileCursor,
        master: &Kinematic,
    ) -> (Kinematic, CamPosition) {
        let at = self.locate(master.position);
        let s = &self.scaling;
        let last = self.first + self.period;
        let raw = if !self.periodic && (at.local < self.first || at.local > last) {
            let edge = at.local.clamp(self.first, last);
            super::Sample::at_rest(profile.eval(edge, cursor).position)
        } else {
            profile.eval(at.local, cursor)
        };
        let y = raw.position + self.stroke * (at.cycle - self.cycle0) as f64;
        // Derivatives of the cam master coordinate in time.
        let xd = master.velocity / s.master_scaling;
        let xdd = master.acceleration / s.master_scaling;
        let xddd = master.jerk / s.master_scaling;
        let ss = s.slave_scaling;
        let slave = Kinematic {
            position: self.slave_origin + s.slave_offset + ss * y,
            velocity: ss * raw.velocity * xd,
            acceleration: ss * (raw.acceleration * xd * xd + raw.velocity * xdd),
            jerk: ss
                * (raw.jerk * xd * xd * xd
                    + 3.0 * raw.acceleration * xd * xdd
                    + raw.velocity * xddd),
        };
        (slave, at)
    }

    /// The master's motion in the cam over one tick, for activation rules.
    pub fn master_now(&self, before: f64, now: f64) -> MasterNow {
        let (a, b) = (self.locate(before), self.locate(now));
        let last = self.first + self.period;
        let crossed = |edge: f64| (a.x < edge && edge <= b.x) || (b.x <= edge && edge < a.x);
        // A linear cam's "cycle" ends at its range edges: forward past its end, backward past
        // its start (where its values continue into the next or previous cycle).
        let edge = match self.periodic {
            true => None,
            false if a.x < last && last <= b.x => Some((last, true)),
            false if b.x <= self.first && self.first < a.x => Some((self.first, false)),
            false => None,
        };
        let cycle_changed = if self.periodic {
            a.cycle != b.cycle
        } else {
            crossed(self.first) || crossed(last)
        };
        let s = &self.scaling;
        MasterNow {
            axis: (before, now),
            cam: (a.local, b.local),
            cycle_changed,
            edge: edge.map(|(x, end)| EdgeCrossing {
                axis: x * s.master_scaling - s.master_offset + self.master_origin,
                end,
            }),
        }
    }

    /// The law after a switch to `profile` or a rescaling with `requested` at master
    /// position `master`, with the slave at `slave`: each side's scaling mode decides what
    /// is taken (Off keeps the side as it is); master auto-offset keeps the master's share of
    /// the cam's cycle, slave auto-offset keeps the slave's position (master first, then
    /// slave, as the seed orders them). A relative side takes its new origin from here.
    #[allow(clippy::too_many_arguments)]
    pub fn rescaled(
        &self,
        profile: &CamProfile,
        requested: Scaling,
        modes: (CamScalingMode, CamScalingMode),
        start: CamStartMode,
        periodic: bool,
        master: f64,
        slave: f64,
        switched: bool,
        edge: Option<EdgeCrossing>,
    ) -> CamLaw {
        let (master_mode, slave_mode) = modes;
        // At a linear cam's edge the change is anchored on the edge itself (with the slave
        // there), so the next cam takes over exactly where this one ended.
        let master = edge.map_or(master, |e| e.axis);
        let mut scaling = self.scaling;
        if master_mode != CamScalingMode::Off {
            scaling.master_offset = requested.master_offset;
            scaling.master_scaling = requested.master_scaling;
        }
        if slave_mode != CamScalingMode::Off {
            scaling.slave_offset = requested.slave_offset;
            scaling.slave_scaling = requested.slave_scaling;
        }
        // A switch re-anchors relative sides here; a rescaling keeps the coupling's origins
        // (a relative side's origin is its position at coupling, an absolute side's is 0).
        let (start, master_at, slave_at) = if switched {
            (start, master, slave)
        } else {
            (self.start, self.master_origin, self.slave_origin)
        };
        let mut law = CamLaw::new(profile, scaling, start, periodic, master_at, slave_at);
        if master_mode == CamScalingMode::AutoOffset {
            let old = self.locate(master);
            let share = match edge {
                // Past the end: the next cycle's start; back past the start: the previous end.
                Some(e) => f64::from(u8::from(!e.end)),
                None => self.share_of_cycle(old),
            };
            let x = law.first + share * law.period;
            let s = &mut law.scaling;
            s.master_offset = x * s.master_scaling - master + law.master_origin;
        }
        // The stroke count goes on across a switch or a rescaling: the cycles since the
        // coupling stay what they were (only coupling anew starts in the base cycle).
        let cycles = self.locate(master).cycle - self.cycle0;
        law.cycle0 = law.locate(master).cycle - cycles;
        if slave_mode == CamScalingMode::AutoOffset {
            let mut cursor = ProfileCursor::default();
            let standing = Kinematic {
                position: master,
                ..Kinematic::default()
            };
            let (now, _) = law.slave(profile, &mut cursor, &standing);
            law.scaling.slave_offset += slave - now.position;
        }
        law
    }

    /// How far into its cycle the master is, as a fraction of the period (a linear cam
    /// passed at its end continues from the beginning of the next). The cycles themselves
    /// are counted apart (`cycle0`).
    fn share_of_cycle(&self, at: CamPosition) -> f64 {
        if self.period <= 0.0 {
            return 0.0;
        }
        let share = (at.local - self.first) / self.period;
        if share > 1.0 {
            share - 1.0
        } else {
            share
        }
    }
}

/// Whether `activation` may couple an uncoupled slave with `start` (seed 5.1.16.13, table
/// "coupling with cam tables"): never with master auto-offset; the cam-position and
/// next-cycle modes only with an absolute master (a relative master has no cam coordinate
/// before it is coupled).
pub fn check_couple(
    activation: Activation,
    start: CamStartMode,
    master_auto: bool,
) -> Result<(), CouplingError> {
    let allowed = !master_auto
        && match activation {
            Activation::Instantaneous | Activation::AtMasterAxisPos(_) => true,
            Activation::AtMasterCamPos(_) | Activation::NextCycle => !start.master_relative(),
            _ => false,
        };
    refuse_unless(allowed, activation, start, master_auto, "coupling")
}

/// Whether `activation` may switch a coupled slave to another cam with `start` (table
/// "switching of cam tables"): every timed mode and the deletion; master auto-offset only
/// with an absolute master.
pub fn check_switch(
    activation: Activation,
    start: CamStartMode,
    master_auto: bool,
) -> Result<(), CouplingError> {
    let deletion = matches!(activation, Activation::DeleteQueuedData);
    check_change(activation, start, master_auto, deletion, "switching")
}

/// Whether `activation` may rescale a coupling (5.1.16.13, "scaling of cam tables"): every
/// timed mode and Off; master auto-offset contradicts a relative master here too (5.1.16.3).
pub fn check_scaling(
    activation: Activation,
    start: CamStartMode,
    master_auto: bool,
) -> Result<(), CouplingError> {
    let off = matches!(activation, Activation::Off);
    check_change(activation, start, master_auto, off, "scaling")
}

/// A change of a running coupling (`what`): the timed modes, or the one other mode the change
/// allows (`other`); master auto-offset only with an absolute master.
fn check_change(
    activation: Activation,
    start: CamStartMode,
    master_auto: bool,
    other: bool,
    what: &'static str,
) -> Result<(), CouplingError> {
    let timed = matches!(
        activation,
        Activation::Instantaneous
            | Activation::AtMasterCamPos(_)
            | Activation::AtMasterAxisPos(_)
            | Activation::NextCycle
    );
    let allowed = !(master_auto && start.master_relative()) && (timed || other);
    refuse_unless(allowed, activation, start, master_auto, what)
}

fn refuse_unless(
    allowed: bool,
    activation: Activation,
    start: CamStartMode,
    master_auto: bool,
    when: &'static str,
) -> Result<(), CouplingError> {
    if allowed {
        return Ok(());
    }
    Err(CouplingError::Combination {
        activation: activation.mode().raw(),
        start: start.raw(),
        master_auto,
        when,
    })
}

/// Refuses an axis-position activation the master has passed in its direction of travel
/// (rising when it stands), as the seed does for `AtMasterAxisPos`.
pub fn check_not_passed(activation: Activation, now: MasterNow) -> Result<(), CouplingError> {
    if let Activation::AtMasterAxisPos(position) = activation {
        if ActivationMode::AtMasterAxisPos(position).passed(now) {
            return Err(CouplingError::Passed {
                position,
                master: now.axis.1,
            });
        }
    }
    Ok(())
}
