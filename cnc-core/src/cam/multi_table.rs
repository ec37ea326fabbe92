//! The multi-table slave (seed 000, chapter 4.6): one slave driven by up to eight tables at
//! once, each scaled on its own. Profile tables (a start table, work tables, a stop table)
//! take turns by their master ranges; correction tables run beside them for a stretch and
//! switch themselves off at their end. Each active table adds its weighted, scaled value:
//!
//! ```text
//! u_i    = MO_i + MS_i * Pm                          (the master slope multiplies here)
//! Ps_i   = SO_i + SS_i * (T_i(u_i folded) + SH_i * cycle_i)    cyclic profile tables
//! Ps_i   = SO_i + SS_i * T_i(u_i)                              linear tables, corrections
//! Ps     = sum of W_i * Ps_i over the profile tables whose range holds Pm
//!          + the corrections running + what finished corrections left behind
//! ```
//!
//! Where the seed leaves the hand-overs open, we keep the slave's position continuous:
//! * a correction's master offset is set when it starts, so that it starts at its table's
//!   first row (the seed: "set by the NC"); when it has run through, what it added stays
//!   (a correction that ends at 0 leaves nothing);
//! * a cyclic profile table asked to stop ends at its next cycle boundary; the next profile
//!   table in the list then starts there, at its first row, from the position reached;
//! * when no profile table's range holds the master, the slave stands where the profile
//!   left it.

use super::online::CamStore;
use super::{CamProfile, ProfileCursor};
use crate::setpoint::Kinematic;

/// Tables of one multi-table slave.
pub const MAX_MULTI_TABLES: usize = 8;

/// The scaling of one table (CamTableSetWeight): the call's body as the CNC received it (W,
/// MO, MS, SO, SS, RL, RH); its default is the neutral scaling.
pub type TableWeight = hli::calls::cam::CamTableWeightCall;

/// Why a weight or a multi-table coupling is refused.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum MultiTableError {
    /// A value that is NaN, a weight not above 0, a master slope of 0, or RL not below RH.
    #[error("{what} {value} is not usable")]
    Parameter {
        /// Which value.
        what: &'static str,
        /// The value.
        value: f64,
    },
    /// Tables and profile tables outside 1..=8 and 1..=tables.
    #[error("{tables} tables with {profiles} profile tables: 1..=8 tables, 1..=tables profiles")]
    Count {
        /// Tables given.
        tables: usize,
        /// Profile tables given.
        profiles: usize,
    },
    /// The table is not one of the coupling's, or not of the kind the command needs.
    #[error("table {0} is not a {1} of this coupling")]
    NotInCoupling(u32, &'static str),
    /// The table is active (a profile table whose range holds the master, a running
    /// correction): its scaling is set before it becomes active, never while it is.
    #[error("table {0} is active: its scaling is set before it becomes active")]
    Active(u32),
}

/// Refuses in a table's weight NaN, a weight not above 0, a master slope of 0 and RL not below
/// RH (ranges may be open: infinite), and magnitudes the law could overflow with (as
/// `coupling::Scaling::check`).
pub fn check_weight(w: &TableWeight) -> Result<(), MultiTableError> {
    let bounded = [
        ("weight", w.weight, 0.0, 1e6),
        ("master offset", w.master_offset, 0.0, 1e12),
        ("master slope", w.master_slope, 0.0, 1e6),
        ("slave offset", w.slave_offset, 0.0, 1e12),
        ("slave slope", w.slave_slope, 0.0, 1e6),
    ];
    for (what, value, min, max) in bounded {
        let magnitude = value.abs();
        if !(value.is_finite() && magnitude >= min && magnitude <= max) {
            return Err(MultiTableError::Parameter { what, value });
        }
    }
    let refuse = |what, value| Err(MultiTableError::Parameter { what, value });
    if w.weight <= 0.0 {
        return refuse("weight", w.weight);
    }
    if w.master_slope.abs() < 1e-6 {
        return refuse("master slope", w.master_slope);
    }
    if w.range_low.is_nan() || w.range_high.is_nan() || w.range_low >= w.range_high {
        return refuse("range low", w.range_low);
    }
    Ok(())
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Run {
    /// A correction not started, or run through.
    Idle,
    /// A correction waiting for the master to pass a position.
    Armed(f64),
    /// A correction to start with this tick.
    Starting,
    /// Counting.
    Running,
}

/// One table of the coupling.
#[derive(Debug, Clone, Copy)]
struct Entry {
    table: u32,
    profile: bool,
    periodic: bool,
    w: TableWeight,
    first: f64,
    period: f64,
    stroke: f64,
    run: Run,
    stop_at_cycle_end: bool,
    last_cycle: Option<i64>,
    cursor: ProfileCursor,
}

/// The coupling of one multi-table slave.
#[derive(Debug, Clone)]
pub struct MultiTableLaw {
    entries: [Option<Entry>; MAX_MULTI_TABLES],
    /// The profile's position while no profile table's range holds the master.
    held: f64,
    /// What finished corrections left behind.
    kept: f64,
    master_before: f64,
}

/// A table of a multi-table coupling as the engine hands it in: ID, profile or correction,
/// cyclic, its weight, and its profile (for its range and stroke).
pub struct TableSpec<'a> {
    /// Table ID.
    pub table: u32,
    /// A profile table (else a correction).
    pub profile: bool,
    /// Continued period by period (profile tables only; corrections are linear).
    pub periodic: bool,
    /// Its scaling.
    pub weight: TableWeight,
    /// The table.
    pub cam: &'a CamProfile,
}

impl MultiTableLaw {
    /// The coupling of `tables` (profile tables first), with the master at `master` and the
    /// slave at `slave` (where it stands while no profile table's range holds the master).
    pub fn new(
        tables: &[TableSpec<'_>],
        master: f64,
        slave: f64,
    ) -> Result<MultiTableLaw, MultiTableError> {
        let profiles = tables.iter().filter(|t| t.profile).count();
        if tables.is_empty() || tables.len() > MAX_MULTI_TABLES || profiles == 0 {
            return Err(MultiTableError::Count {
                tables: tables.len(),
                profiles,
            });
        }
        let mut entries = [None; MAX_MULTI_TABLES];
        for (slot, t) in entries.iter_mut().zip(tables) {
            check_weight(&t.weight)?;
            let (a, b) = t.cam.master_range();
            let (first, last) = (a.min(b), a.max(b));
            let mut c = ProfileCursor::default();
            let stroke = t.cam.eval(last, &mut c).position - t.cam.eval(first, &mut c).position;
            let mut w = t.weight;
            if !t.profile {
                // Corrections count everywhere while they run (the seed: set by the NC).
                w.range_low = f64::NEG_INFINITY;
                w.range_high = f64::INFINITY;
            }
            *slot = Some(Entry {
                table: t.table,
                profile: t.profile,
                periodic: t.profile && t.periodic,
                w,
                first,
                period: last - first,
                stroke,
                run: if t.profile { Run::Running } else { Run::Idle },
                stop_at_cycle_end: false,
                last_cycle: None,
                cursor: ProfileCursor::default(),
            });
        }
        Ok(MultiTableLaw {
            entries,
            held: slave,
            kept: 0.0,
            master_before: master,
        })
    }

    /// The tables of the coupling.
    pub fn tables(&self) -> impl Iterator<Item = u32> + '_ {
        self.entries.iter().flatten().map(|e| e.table)
    }

    /// Whether `table` is active now: a profile table whose range holds the master's last
    /// position, or a correction that runs or starts with the next tick.
    pub fn is_active(&self, table: u32) -> bool {
        let m = self.master_before;
        self.entries.iter().flatten().any(|e| {
            e.table == table
                && if e.profile {
                    e.w.range_low <= m && m < e.w.range_high
                } else {
                    matches!(e.run, Run::Starting | Run::Running)
                }
        })
    }

    /// CamTableSetWeight on `table` of the running coupling: its new scaling, taken when it
    /// becomes active (seed 000 4.6.3: the scaling is set before a table becomes active; a
    /// correction keeps the open range the NC gives it). Refused with nothing changed while
    /// the table is active, or when it is not one of the coupling's.
    pub fn set_weight(&mut self, table: u32, w: TableWeight) -> Result<(), MultiTableError> {
        check_weight(&w)?;
        if self.is_active(table) {
            return Err(MultiTableError::Active(table));
        }
        let mut found = false;
        for e in self
            .entries
            .iter_mut()
            .flatten()
            .filter(|e| e.table == table)
        {
            let (low, high) = (e.w.range_low, e.w.range_high);
            e.w = w;
            if !e.profile {
                (e.w.range_low, e.w.range_high) = (low, high);
            }
            found = true;
        }
        if found {
            Ok(())
        } else {
            Err(MultiTableError::NotInCoupling(table, "table"))
        }
    }

    /// Starts correction `table`: at once (`at` None) or when the master passes `at`.
    pub fn enable_correction(
        &mut self,
        table: u32,
        at: Option<f64>,
    ) -> Result<(), MultiTableError> {
        let e = self
            .entries
            .iter_mut()
            .flatten()
            .find(|e| e.table == table && !e.profile)
            .ok_or(MultiTableError::NotInCoupling(table, "correction table"))?;
        e.run = match at {
            None => Run::Starting,
            Some(p) => Run::Armed(p),
        };
        Ok(())
    }

    /// Ends cyclic profile table `table` at its next cycle boundary.
    pub fn stop_cyclic(&mut self, table: u32) -> Result<(), MultiTableError> {
        let e = self
            .entries
            .iter_mut()
            .flatten()
            .find(|e| e.table == table && e.profile && e.periodic)
            .ok_or(MultiTableError::NotInCoupling(
                table,
                "cyclic profile table",
            ))?;
        e.stop_at_cycle_end = true;
        Ok(())
    }

    /// The slave's set-point for the master's set-point `m`, the tables taken from `store`
    /// (a table gone from it counts as standing still).
    pub fn slave(&mut self, store: &CamStore, m: &Kinematic) -> Kinematic {
        let before = self.master_before;
        self.master_before = m.position;
        // Profile tables whose range holds the master. A cyclic one asked to stop ends at its
        // cycle boundary and hands over to the next; the pass repeats once so the table that
        // took over counts in this tick.
        let mut profile_sum = Kinematic::default();
        let mut any_profile = false;
        for _pass in 0..2 {
            let handed_over;
            (profile_sum, any_profile, handed_over) = self.profile_pass(store, m);
            if !handed_over {
                break;
            }
        }
        let mut out = if any_profile {
            self.held = profile_sum.position;
            profile_sum
        } else {
            Kinematic {
                position: self.held,
                ..Kinematic::default()
            }
        };
        // Corrections beside the profile.
        self.add_corrections(store, m, before, &mut out);
        out.position += self.kept;
        out
    }

    /// One pass over the profile tables: the sum of those whose range holds the master,
    /// whether any does, and whether a cyclic one ended and handed over.
    fn profile_pass(&mut self, store: &CamStore, m: &Kinematic) -> (Kinematic, bool, bool) {
        let cam = |id: u32| store.get(id).ok();
        let mut handed_over = false;
        let mut profile_sum = Kinematic::default();
        let mut any_profile = false;
        for i in 0..MAX_MULTI_TABLES {
            let Some(mut e) = self.entries[i] else {
                continue;
            };
            let Some(p) = cam(e.table) else { continue };
            if !e.profile {
                continue;
            }
            if !(e.w.range_low <= m.position && m.position < e.w.range_high) {
                // Out of its range: its cycle count starts afresh when it comes back.
                if let Some(out) = self.entries[i].as_mut() {
                    out.last_cycle = None;
                }
                continue;
            }
            let (c, cycle) = contribution(&mut e, p, m);
            let previous = e.last_cycle.replace(cycle);
            if let (true, true, Some(prev)) = (e.periodic, e.stop_at_cycle_end, previous) {
                if prev != cycle {
                    // The boundary crossed is the start of the later cycle.
                    let reached = value_at_cycle_start(&e, p, prev.max(cycle));
                    e.w.range_high = m.position;
                    e.stop_at_cycle_end = false;
                    self.entries[i] = Some(e);
                    self.hand_over(i, m.position, reached, store);
                    handed_over = true;
                    continue;
                }
            }
            self.entries[i] = Some(e);
            add(&mut profile_sum, &c);
            any_profile = true;
        }
        (profile_sum, any_profile, handed_over)
    }

    /// The corrections running at master position `m` (the master stood at `before` last
    /// tick) added to `out`: armed ones start when the master passes their position, a
    /// correction that ran through leaves what it added in `kept`.
    fn add_corrections(
        &mut self,
        store: &CamStore,
        m: &Kinematic,
        before: f64,
        out: &mut Kinematic,
    ) {
        let cam = |id: u32| store.get(id).ok();
        for i in 0..MAX_MULTI_TABLES {
            let Some(mut e) = self.entries[i] else {
                continue;
            };
            if e.profile {
                continue;
            }
            let Some(p) = cam(e.table) else { continue };
            // Where it starts: the activation position it passed, or here.
            let anchor = match e.run {
                Run::Armed(at)
                    if (before < at && at <= m.position) || (m.position <= at && at < before) =>
                {
                    Some(at)
                }
                Run::Starting => Some(m.position),
                _ => None,
            };
            if let Some(anchor) = anchor {
                // At its table's first row (the last one for a falling slope).
                let start = if e.w.master_slope > 0.0 {
                    e.first
                } else {
                    e.first + e.period
                };
                e.w.master_offset = start - e.w.master_slope * anchor;
                e.run = Run::Running;
            }
            if e.run == Run::Running {
                let u = e.w.master_offset + e.w.master_slope * m.position;
                let (c, _) = contribution(&mut e, p, m);
                // Run through in the direction it runs: past its last row (rising slope) or
                // its first (falling slope).
                let through = if e.w.master_slope > 0.0 {
                    u >= e.first + e.period
                } else {
                    u <= e.first
                };
                if through {
                    // Run through: what it added stays.
                    self.kept += c.position;
                    e.run = Run::Idle;
                } else {
                    add(out, &c);
                }
            }
            self.entries[i] = Some(e);
        }
    }

    /// Cyclic profile table `ended` ended at master position `at` with its contribution
    /// `reached`: the next profile table in the list starts there, at its first row, from
    /// that position.
    fn hand_over(&mut self, ended: usize, at: f64, reached: f64, store: &CamStore) {
        let next =
            (ended + 1..MAX_MULTI_TABLES).find(|&k| self.entries[k].is_some_and(|e| e.profile));
        let Some(k) = next else {
            self.held = reached;
            return;
        };
        let Some(e) = self.entries[k].as_mut() else {
            return;
        };
        let Ok(p) = store.get(e.table) else { return };
        if e.w.range_low <= at && at < e.w.range_high {
            // Counting already (in parallel): it goes on as it is, and what the ended table
            // reached stays in the position.
            self.kept += reached;
            return;
        }
        e.w.range_low = at;
        if e.w.range_high <= at {
            e.w.range_high = f64::INFINITY;
        }
        let start = if e.w.master_slope > 0.0 {
            e.first
        } else {
            e.first + e.period
        };
        e.w.master_offset = start - e.w.master_slope * at;
        let t0 = p.eval(start, &mut ProfileCursor::default()).position;
        // W (SO + SS T(start)) = reached.
        e.w.slave_offset = reached / e.w.weight - e.w.slave_slope * t0;
        e.last_cycle = None;
    }
}

fn add(sum: &mut Kinematic, c: &Kinematic) {
    sum.position += c.position;
    sum.velocity += c.velocity;
    sum.acceleration += c.acceleration;
    sum.jerk += c.jerk;
}

/// One table's weighted, scaled value and its cycle counter.
fn contribution(e: &mut Entry, p: &CamProfile, m: &Kinematic) -> (Kinematic, i64) {
    let w = e.w;
    let u = w.master_offset + w.master_slope * m.position;
    let (local, cycle) = fold(e, u);
    let last = e.first + e.period;
    let raw = if !e.periodic && (local < e.first || local > last) {
        super::Sample::at_rest(p.eval(local.clamp(e.first, last), &mut e.cursor).position)
    } else {
        p.eval(local, &mut e.cursor)
    };
    let y = raw.position + e.stroke * cycle as f64;
    let (du, ddu, dddu) = (
        w.master_slope * m.velocity,
        w.master_slope * m.acceleration,
        w.master_slope * m.jerk,
    );
    let k = w.weight * w.slave_slope;
    (
        Kinematic {
            position: w.weight * (w.slave_offset + w.slave_slope * y),
            velocity: k * raw.velocity * du,
            acceleration: k * (raw.acceleration * du * du + raw.velocity * ddu),
            jerk: k
                * (raw.jerk * du * du * du
                    + 3.0 * raw.acceleration * du * ddu
                    + raw.velocity * dddu),
        },
        cycle,
    )
}

/// A cyclic table's value where its cycle `cycle` begins.
fn value_at_cycle_start(e: &Entry, p: &CamProfile, cycle: i64) -> f64 {
    let w = &e.w;
    let y = p.eval(e.first, &mut ProfileCursor::default()).position + e.stroke * cycle as f64;
    w.weight * (w.slave_offset + w.slave_slope * y)
}

fn fold(e: &Entry, u: f64) -> (f64, i64) {
    if !e.periodic || e.period <= 0.0 {
        return (u, 0);
    }
    super::fold_period(u, e.first, e.period)
}
