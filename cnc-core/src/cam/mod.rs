//! Cam profiles (seed 000, chapters 3 and 4.2): the slave position as a function of the
//! master position, given as a motion function (points joined by motion laws) or as a
//! position table. The modules below are pure computation: no axes, no time. The cam engine
//! that couples real axes through these profiles is `machine`, beside them (the engine's
//! home is this folder).
//!
//! * `piece` — the closed-form building block (polynomial + sinusoids) every law is made of;
//! * `law` — `FunctionType` and how each law fills a segment;
//! * `motion_function` — points, checks, boundary values, evaluation;
//! * `table` — position tables and their interpolations;
//! * `charac` — characteristic values and value tables;
//! * `online` — queued point changes, validated whole before they apply;
//! * `coupling` — the coupling law of a slave to a master through a cam, activation and
//!   scaling modes;
//! * `multi_table` — the multi-table slave: profile tables in series, corrections beside;
//! * `file` — the JSON cam file and the binary table file;
//! * `error` — refusals with the seed's error codes;
//! * `machine` — the cam engine on the machine seam: its tick, calls and configuration.
//!
//! Evaluation (`CamProfile::eval`) allocates nothing and costs O(1) per call while the master
//! sweeps, through a cursor the caller keeps.

pub mod charac;
pub mod coupling;
pub mod error;
pub mod file;
pub mod law;
pub mod machine;
pub mod motion_function;
pub mod multi_table;
pub mod online;
pub mod piece;
pub mod table;

pub use charac::CharacValues;
pub use error::{CamError, Field, TableErrorCode};
pub use law::FunctionType;
pub use motion_function::{MotionFunction, MotionFunctionPoint, PointType};
pub use table::{PositionTable, TableType};

/// Slave position and its derivatives with respect to the master position.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Sample {
    /// Slave position.
    pub position: f64,
    /// dy/dx.
    pub velocity: f64,
    /// d2y/dx2.
    pub acceleration: f64,
    /// d3y/dx3.
    pub jerk: f64,
}

impl Sample {
    /// A slave standing at `position`.
    pub fn at_rest(position: f64) -> Sample {
        Sample {
            position,
            ..Sample::default()
        }
    }
}

/// `x` folded into the period `[first, first + period)` of a cyclic profile (`period` > 0),
/// and how many periods were folded (negative below `first`): the cam coupling and the
/// multi-table slave count a cyclic table's cycles this way.
pub(crate) fn fold_period(x: f64, first: f64, period: f64) -> (f64, i64) {
    let mut cycle = ((x - first) / period).floor();
    let mut local = x - cycle * period;
    // Rounding may leave `local` a hair outside the period.
    if local >= first + period {
        cycle += 1.0;
        local -= period;
    } else if local < first {
        cycle -= 1.0;
        local += period;
    }
    (local, cycle as i64)
}

/// Value and four derivatives of one closed-form piece at a master position.
pub(crate) type PieceEval<'a> = &'a dyn Fn(f64) -> [f64; 5];

/// Visits each piece: its master range (ascending) and its evaluation.
pub(crate) type PieceVisitor<'a> = dyn FnMut(f64, f64, PieceEval<'_>) + 'a;

/// A cam profile: a motion function or a position table.
#[derive(Debug, Clone, PartialEq)]
pub enum CamProfile {
    /// Points joined by motion laws.
    MotionFunction(MotionFunction),
    /// A position table.
    Table(PositionTable),
}

/// A cursor for either kind of profile.
#[derive(Debug, Clone, Copy, Default)]
pub struct ProfileCursor {
    function: motion_function::Cursor,
    table: table::TableCursor,
}

impl CamProfile {
    /// The raw (unscaled) slave values at master `x`.
    #[inline]
    pub fn eval(&self, x: f64, cursor: &mut ProfileCursor) -> Sample {
        match self {
            CamProfile::MotionFunction(f) => f.eval(x, &mut cursor.function),
            CamProfile::Table(t) => t.eval(x, &mut cursor.table).sample,
        }
    }

    /// First and last master position.
    pub fn master_range(&self) -> (f64, f64) {
        match self {
            CamProfile::MotionFunction(f) => f.master_range(),
            CamProfile::Table(t) => t.master_range(),
        }
    }

    /// Slave position at the end of the master range.
    pub fn end_position(&self) -> f64 {
        let (_, end) = self.master_range();
        self.eval(end, &mut ProfileCursor::default()).position
    }

    /// `MC_TableType` number of the profile.
    pub fn table_type_raw(&self) -> u16 {
        match self {
            CamProfile::MotionFunction(_) => 22,
            CamProfile::Table(t) => match t.table_type() {
                TableType::Equidistant => 10,
                TableType::NonEquidistant => 11,
            },
        }
    }

    /// Every closed-form piece over the master range (in ascending master order) with a
    /// function giving value and four derivatives.
    pub(crate) fn for_each_piece(&self, f: &mut PieceVisitor<'_>) {
        match self {
            CamProfile::MotionFunction(mf) => mf.for_each_piece(f),
            CamProfile::Table(t) => {
                let rows: Vec<[f64; 2]> = t.rows().collect();
                for w in rows.windows(2) {
                    let (a, b) = (w[0][0], w[1][0]);
                    let mid = 0.5 * (a + b);
                    let eval = |x: f64| {
                        // Seed the cursor inside the interval so its own formula is used at
                        // both of its ends.
                        let mut c = table::TableCursor::default();
                        t.eval(mid, &mut c);
                        let s = t.eval_interval_of(mid, x, &mut c);
                        [s.position, s.velocity, s.acceleration, s.jerk, 0.0]
                    };
                    f(a, b, &eval);
                }
            }
        }
    }
}
