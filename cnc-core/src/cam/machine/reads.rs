//! MC_CamRead's answers: a table's slave dynamics at one master position, its characteristic
//! values, sampled values and rows (in parts of `CAM_VALUES_PER_REPLY`), and the 40 values of
//! MC_CamInfoData for a coupled slave.

use super::{CamEngine, Queued, Slave, TABLE_INVALID};
use crate::axis::AxisSet;
use crate::cam::{CamProfile, ProfileCursor, TableErrorCode, TableType};
use crate::setpoint::Kinematic;
use hli::calls::cam::CamCouplingError;
use hli::calls::cam::{
    CamReadCall, CamReadKind, CamScalingMode, CamValuesReply, TableOrganisation,
    CAM_VALUES_PER_REPLY,
};
use hli::calls::{decode_body, reply, HandlerResult};
use hli::wire::AcyclicRequest;

/// The values a read made: all of them, or (`from` > 0) only those from index `from` on.
struct Made {
    values: Vec<f64>,
    /// How many values the whole answer has.
    total: usize,
    columns: u32,
    /// The index of `values[0]` in the whole answer.
    from: usize,
}

impl Made {
    /// All `values` of a one-column answer.
    fn all(values: Vec<f64>, total: usize) -> Made {
        Made {
            values,
            total,
            columns: 1,
            from: 0,
        }
    }
}

/// A value that must be finite, or the refusal.
fn finite(v: f64) -> Result<f64, u32> {
    v.is_finite()
        .then_some(v)
        .ok_or(CamCouplingError::BadParameter.raw())
}

impl CamEngine {
    pub(super) fn read(&self, request: &AcyclicRequest, axes: &AxisSet) -> HandlerResult {
        let call: CamReadCall = decode_body(request)?;
        let id = request.target;
        let per = match call.part_len as usize {
            0 => CAM_VALUES_PER_REPLY,
            n => n.min(CAM_VALUES_PER_REPLY),
        };
        let skip = call.part as usize * per;
        if call.what == CamReadKind::Queued.raw() {
            // Asked every PLC cycle while MC_CamScaling waits: answered without allocating.
            return self.queued_reply(id as usize);
        }
        // A values read makes only the part asked for; the others make all and are cut here.
        let answer = match CamReadKind::from_raw(call.what) {
            Some(CamReadKind::SlaveDynamics) => self.slave_dynamics(id, &call),
            Some(CamReadKind::Characteristics) => self.table(id).and_then(|p| {
                // `a`: the master velocity the values are for (0: the normed values, 1.0).
                let normed = crate::cam::CharacValues::normed(p);
                let at = if call.a == 0.0 {
                    Some(normed)
                } else {
                    normed.rescaled(call.a)
                };
                let mut values: Vec<f64> = at
                    .ok_or(CamCouplingError::BadParameter.raw())?
                    .fields()
                    .iter()
                    .map(|(_, v)| *v)
                    .collect();
                values.extend_from_slice(&self.organisation(id, p).values());
                let n = values.len();
                Ok(Made::all(values, n))
            }),
            Some(CamReadKind::Values) => self.sampled_values(id, &call, skip, per),
            Some(CamReadKind::Rows) => self.rows_part(id, skip, per, call.rows),
            Some(CamReadKind::Info) => self.info(id as usize, &call, axes).map(|v| {
                let n = v.len();
                Made::all(v, n)
            }),
            // Answered above, without allocating.
            Some(CamReadKind::Queued) => Err(CamCouplingError::UnknownMode.raw()),
            None => Err(CamCouplingError::UnknownMode.raw()),
        };
        let made = match answer {
            Ok(made) => made,
            Err(e) => {
                return reply(&CamValuesReply {
                    error_id: e,
                    ..CamValuesReply::default()
                })
            }
        };
        let mut out = CamValuesReply {
            total: made.total as u32,
            columns: made.columns,
            ..CamValuesReply::default()
        };
        for (o, v) in out
            .values
            .iter_mut()
            .zip(made.values.iter().skip(skip - made.from.min(skip)))
            .take(per)
        {
            *o = *v;
            out.count += 1;
        }
        reply(&out)
    }

    /// The organisation fields of stored table `id` (periodic as MC_CamTableSelect chose).
    fn organisation(&self, id: u32, p: &CamProfile) -> TableOrganisation {
        let (rows, columns) = match p {
            CamProfile::Table(t) => (t.len(), 2),
            CamProfile::MotionFunction(f) => (f.points().len(), 1),
        };
        TableOrganisation {
            table_id: id,
            rows: u32::try_from(rows).unwrap_or(u32::MAX),
            columns,
            table_type: u32::from(p.table_type_raw()),
            periodic: self.select_periodic(id, p),
        }
    }

    /// Stored table `id`, or the refusal.
    fn table(&self, id: u32) -> Result<&CamProfile, u32> {
        self.store.get(id).map_err(|_| TABLE_INVALID)
    }

    /// Position, velocity and acceleration at master position `call.a` (clamped to the
    /// table's range), as far as the table type gives them.
    fn slave_dynamics(&self, id: u32, call: &CamReadCall) -> Result<Made, u32> {
        let p = self.table(id)?;
        let x = finite(call.a)?;
        let (lo, hi) = p.master_range();
        let s = p.eval(
            x.clamp(lo.min(hi), lo.max(hi)),
            &mut ProfileCursor::default(),
        );
        // What each table type gives (seed 5.1.7): motion functions all three,
        // equidistant tables position and velocity, others position.
        let v = match p {
            CamProfile::MotionFunction(_) => [s.position, s.velocity, s.acceleration],
            CamProfile::Table(t) if t.table_type() == TableType::Equidistant => {
                [s.position, s.velocity, 0.0]
            }
            CamProfile::Table(_) => [s.position, 0.0, 0.0],
        };
        Ok(Made::all(v.to_vec(), 3))
    }

    /// The part of `per` values from value `skip` on of the table sampled from `call.a` to
    /// `call.b` in steps of `call.c`: per row the master position and the quantities
    /// `call.mask` names.
    fn sampled_values(
        &self,
        id: u32,
        call: &CamReadCall,
        skip: usize,
        per: usize,
    ) -> Result<Made, u32> {
        let p = self.table(id)?;
        let (from, to, step) = (finite(call.a)?, finite(call.b)?, finite(call.c)?);
        if call.mask == 0 || call.mask > 15 {
            return Err(crate::cam::CamError::ValueMask { mask: call.mask }.code() as u32);
        }
        let rows = crate::cam::charac::sample_count(from, to, step, 1 << 20)
            .map_err(|e| e.code() as u32)?;
        let columns = 1 + call.mask.count_ones();
        let cols = columns as usize;
        let total = rows * cols;
        // Only the rows of the part asked for are evaluated.
        let mut values = Vec::with_capacity(per);
        let mut cursor = ProfileCursor::default();
        let mut row_cache: Option<(usize, [f64; 5])> = None;
        for i in skip..(skip + per).min(total) {
            let (row, col) = (i / cols, i % cols);
            let cells = match row_cache {
                Some((r, c)) if r == row => c,
                _ => {
                    let x = from + step * row as f64;
                    let c = sample_row(p, x, call.mask, &mut cursor);
                    row_cache = Some((row, c));
                    c
                }
            };
            values.push(cells[col]);
        }
        Ok(Made {
            values,
            total,
            columns,
            from: skip,
        })
    }

    /// The part of `per` values from value `skip` on of a position table's first `rows` rows
    /// (0: all; more than it has: 0x4B36), master and slave per row.
    fn rows_part(&self, id: u32, skip: usize, per: usize, rows: u32) -> Result<Made, u32> {
        match self.table(id) {
            Ok(CamProfile::Table(t)) => {
                let rows = match rows as usize {
                    0 => t.len(),
                    n if n <= t.len() => n,
                    _ => return Err(TableErrorCode::NumRowsInvalid as u32),
                };
                let total = rows * 2;
                // Only the rows of this part.
                let values: Vec<f64> = (skip..(skip + per).min(total))
                    .filter_map(|i| t.row_at(i / 2).map(|r| r[i % 2]))
                    .collect();
                Ok(Made {
                    values,
                    total,
                    columns: 2,
                    from: skip,
                })
            }
            Ok(_) => Err(TableErrorCode::McTableTypeInvalid as u32),
            Err(e) => Err(e),
        }
    }

    /// What slave `slave`'s coupling waits to activate: a scaling, a switch, a point change
    /// of its table (1.0 or 0.0 each), as the reply; no allocation.
    fn queued_reply(&self, slave: usize) -> HandlerResult {
        let Some(s) = self.slaves.get(slave).and_then(Option::as_ref) else {
            return reply(&CamValuesReply {
                error_id: CamCouplingError::NotCamCoupled.raw(),
                ..CamValuesReply::default()
            });
        };
        let points = self.store.queue(s.table).is_ok_and(|q| q.is_queued());
        let mut out = CamValuesReply {
            total: 3,
            columns: 1,
            count: 3,
            ..CamValuesReply::default()
        };
        out.values[..3].copy_from_slice(&[
            flag(s.scale.is_some()),
            flag(s.switch.is_some()),
            flag(points),
        ]);
        reply(&out)
    }

    /// The 40 values of MC_CamInfoData for slave `slave`, at the master's set-point or at
    /// `call.a`.
    pub(super) fn info(
        &self,
        slave: usize,
        call: &CamReadCall,
        axes: &AxisSet,
    ) -> Result<Vec<f64>, u32> {
        let coupled = self.slaves.get(slave).and_then(Option::as_ref);
        // After a fault, the last valid state: at the master position of the last tick the
        // coupling ran (seed 000 5.1.15).
        let lost = self.lost.get(slave).and_then(Option::as_ref);
        let (s, master_now) = match (coupled, lost) {
            (Some(s), _) => {
                let now = axes
                    .axis(s.master)
                    .map_or(s.master_before, |a| a.setpoint().position);
                (s, now)
            }
            // Unless another engine has coupled the axis since.
            (None, Some(s)) if axes.axis(slave).is_some_and(|a| a.coupling().is_none()) => {
                (s, s.master_before)
            }
            (None, _) => return Err(CamCouplingError::NotCamCoupled.raw()),
        };
        let stored = self.store.get(s.table).map_err(|_| TABLE_INVALID)?;
        let profile = s.own.as_ref().unwrap_or(stored);
        let at = if call.flags & 1 != 0 {
            if !call.a.is_finite() {
                return Err(CamCouplingError::BadParameter.raw());
            }
            call.a
        } else {
            master_now
        };
        let mut values = Vec::with_capacity(40);
        values.extend_from_slice(&coupling_info(s, profile));
        // MC_MoveSuperimposed's offset since coupling: its sum, and part of the slave's
        // set position.
        let superimposed = axes.axis(slave).map_or(0.0, |a| a.superimposed_offset());
        let mut positions = position_info(s, profile, at);
        positions[1] = superimposed;
        positions[3] += superimposed;
        values.extend_from_slice(&positions);
        values.extend_from_slice(&self.queue_info(s));
        Ok(values)
    }

    /// MC_CamInfoData's values 25 to 40: the queued rescaling, the table's queued point
    /// change and online scaling modes, the queued switch.
    fn queue_info(&self, s: &Slave) -> [f64; 16] {
        let (scale_q, scale_mode, scale_modes) = match s.scale {
            Some(Queued::Scale {
                activation, modes, ..
            }) => (true, activation.raw(), modes),
            _ => (
                false,
                (0, 0.0),
                (CamScalingMode::UserDefined, CamScalingMode::UserDefined),
            ),
        };
        let queue_mode = self
            .store
            .queue(s.table)
            .map(|q| (q.is_queued(), q.mode().raw()))
            .unwrap_or((false, (0, 0.0)));
        let online = self.online_scaling[s.table as usize];
        let (switch_q, switch_id, switch_mode, switch_modes) = match s.switch {
            Some(Queued::Switch {
                table,
                activation,
                modes,
                ..
            }) => (true, table, activation.raw(), modes),
            _ => (
                false,
                0,
                (0, 0.0),
                (CamScalingMode::UserDefined, CamScalingMode::UserDefined),
            ),
        };
        [
            flag(scale_q),
            f64::from(scale_mode.0),
            scale_mode.1,
            f64::from(scale_modes.0.raw()),
            f64::from(scale_modes.1.raw()),
            flag(queue_mode.0),
            f64::from(queue_mode.1 .0),
            queue_mode.1 .1,
            f64::from(online.0.raw()),
            f64::from(online.1.raw()),
            flag(switch_q),
            f64::from(switch_id),
            f64::from(switch_mode.0),
            switch_mode.1,
            f64::from(switch_modes.0.raw()),
            f64::from(switch_modes.1.raw()),
        ]
    }
}

/// One sampled row: the master position `x`, then position, velocity, acceleration and jerk
/// as far as `mask` names them (bits 0 to 3), the rest 0.
fn sample_row(p: &CamProfile, x: f64, mask: u32, cursor: &mut ProfileCursor) -> [f64; 5] {
    let s = p.eval(x, cursor);
    let mut c = [x, 0.0, 0.0, 0.0, 0.0];
    let mut k = 1;
    for (bit, v) in [s.position, s.velocity, s.acceleration, s.jerk]
        .iter()
        .enumerate()
    {
        if mask & (1 << bit) != 0 {
            c[k] = *v;
            k += 1;
        }
    }
    c
}

/// 1.0 for true, 0.0 for false.
fn flag(b: bool) -> f64 {
    f64::from(u8::from(b))
}

/// MC_CamInfoData's values 1 to 18: the table, its shape and range, where the coupling was
/// made, its start modes and scaling.
fn coupling_info(s: &Slave, profile: &CamProfile) -> [f64; 18] {
    let (first, period) = s.law.range();
    let first_slave = profile.eval(first, &mut ProfileCursor::default()).position;
    let (rows, columns, interpolation) = match profile {
        CamProfile::MotionFunction(f) => (f.points().len(), 1, 0),
        CamProfile::Table(t) => (t.len(), 2, t.interpolation().raw()),
    };
    let sc = s.law.scaling;
    [
        f64::from(s.table),
        f64::from(profile.table_type_raw()),
        flag(s.law.periodic),
        f64::from(interpolation),
        rows as f64,
        f64::from(columns),
        first,
        first_slave,
        period,
        s.law.stroke(),
        s.coupled_at.0,
        s.coupled_at.1,
        flag(!s.law.start.master_relative()),
        flag(!s.law.start.slave_relative()),
        sc.master_offset,
        sc.slave_offset,
        sc.master_scaling,
        sc.slave_scaling,
    ]
}

/// MC_CamInfoData's values 19 to 24 at master position `at`: the slave's offset of the
/// cycles run since coupling, the superimposed sum (0 here, the axis's), the master and slave
/// positions (the slave's without the superimposed offset), the cam's master coordinate and
/// its unscaled value.
fn position_info(s: &Slave, profile: &CamProfile, at: f64) -> [f64; 6] {
    let standing = Kinematic {
        position: at,
        ..Kinematic::default()
    };
    let (slave_set, cam) = s
        .law
        .slave(profile, &mut ProfileCursor::default(), &standing);
    let sc = s.law.scaling;
    let raw_cam = (slave_set.position - s.law.slave_origin - sc.slave_offset)
        / if sc.slave_scaling != 0.0 {
            sc.slave_scaling
        } else {
            1.0
        };
    [
        sc.slave_scaling * s.law.stroke() * s.law.cycles_since_coupling(at) as f64,
        0.0,
        at,
        slave_set.position,
        cam.x,
        raw_cam,
    ]
}
