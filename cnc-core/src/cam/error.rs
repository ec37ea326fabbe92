//! Why a cam profile is refused: the seed's table error codes, each refusal with the point or
//! row that caused it.
//!
//! The seed names nine codes (0x4B30..0x4B38) but not which refusal takes which; the mapping
//! below is ours and `docs/cams.md` lists it.

use std::fmt;

/// The seed's `MC_TableErrorCodes`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u32)]
pub enum TableErrorCode {
    /// `MC_ERROR_POINTER_INVALID`: no data where data was expected.
    PointerInvalid = 0x4B30,
    /// `MC_ERROR_ARRAYSIZE_INVALID`: the byte size does not match rows and columns.
    ArraySizeInvalid = 0x4B31,
    /// `MC_ERROR_CAMTABLEID_INVALID`: a table ID outside 1..=255.
    CamTableIdInvalid = 0x4B32,
    /// `MC_ERROR_POINTID_INVALID`: a point that cannot be used (index, type, values).
    PointIdInvalid = 0x4B33,
    /// `MC_ERROR_NUMPOINTS_INVALID`: too few active points.
    NumPointsInvalid = 0x4B34,
    /// `MC_ERROR_MCTABLETYPE_INVALID`: an unknown table type or a type/interpolation clash.
    McTableTypeInvalid = 0x4B35,
    /// `MC_ERROR_NUMROWS_INVALID`: too few or too many rows, or a row with a bad value.
    NumRowsInvalid = 0x4B36,
    /// `MC_ERROR_NUMCOLUMNS_INVALID`: a column count other than the type needs.
    NumColumnsInvalid = 0x4B37,
    /// `MC_ERROR_INCREMENT_INVALID`: master positions not strictly monotonic, not equidistant,
    /// or a sampling increment that does not advance.
    IncrementInvalid = 0x4B38,
}

impl TableErrorCode {
    /// The seed's constant name.
    pub fn name(self) -> &'static str {
        match self {
            Self::PointerInvalid => "MC_ERROR_POINTER_INVALID",
            Self::ArraySizeInvalid => "MC_ERROR_ARRAYSIZE_INVALID",
            Self::CamTableIdInvalid => "MC_ERROR_CAMTABLEID_INVALID",
            Self::PointIdInvalid => "MC_ERROR_POINTID_INVALID",
            Self::NumPointsInvalid => "MC_ERROR_NUMPOINTS_INVALID",
            Self::McTableTypeInvalid => "MC_ERROR_MCTABLETYPE_INVALID",
            Self::NumRowsInvalid => "MC_ERROR_NUMROWS_INVALID",
            Self::NumColumnsInvalid => "MC_ERROR_NUMCOLUMNS_INVALID",
            Self::IncrementInvalid => "MC_ERROR_INCREMENT_INVALID",
        }
    }
}

/// A quantity of a point or row.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Field {
    /// Master position.
    Master,
    /// Slave position.
    Slave,
    /// Slave velocity.
    Velocity,
    /// Slave acceleration.
    Acceleration,
    /// Slave jerk, or the symmetry of a rest-to-rest law.
    Jerk,
}

impl fmt::Display for Field {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Field::Master => "master position",
            Field::Slave => "slave position",
            Field::Velocity => "velocity",
            Field::Acceleration => "acceleration",
            Field::Jerk => "jerk",
        })
    }
}

/// A refused cam profile, change or request.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
pub enum CamError {
    /// Table IDs are 1..=255.
    #[error("cam table ID {id} is outside 1..255")]
    TableId {
        /// The ID given.
        id: u32,
    },
    /// Point indices start at 1 and rise by one without gaps.
    #[error(
        "point {found}: point indices must be 1, 2, 3, ... without gaps (expected {expected})"
    )]
    PointIndex {
        /// The index found.
        found: u32,
        /// The index expected at that place.
        expected: u32,
    },
    /// A relative index that does not lead to the next point over ignored points only.
    #[error("point {point}: relative index {rel} of the next point skips an active point or leaves the function")]
    RelIndex {
        /// The point.
        point: u32,
        /// Its relative index.
        rel: i64,
    },
    /// A function type the controller does not know.
    #[error("point {point}: unknown function type {raw}")]
    UnknownFunctionType {
        /// The point.
        point: u32,
        /// The raw value.
        raw: u32,
    },
    /// A point type the controller does not know.
    #[error("point {point}: unknown point type {raw:#06x}")]
    UnknownPointType {
        /// The point.
        point: u32,
        /// The raw value.
        raw: u32,
    },
    /// NaN or infinity in a point.
    #[error("point {point}: {field} is not a finite number")]
    PointNotFinite {
        /// The point.
        point: u32,
        /// Which value.
        field: Field,
    },
    /// NaN or infinity in a table row.
    #[error("row {row}: {field} is not a finite number")]
    RowNotFinite {
        /// The row, counted from 0.
        row: usize,
        /// Which value.
        field: Field,
    },
    /// Master positions of active points go back or stand still.
    #[error("point {point}: master position {master} does not continue the strictly monotonic master positions (previous {previous})")]
    MasterNotMonotonic {
        /// The point.
        point: u32,
        /// Its master position.
        master: f64,
        /// The previous active point's master position.
        previous: f64,
    },
    /// Table master positions go back or stand still.
    #[error("row {row}: master position {master} is not above the previous row's {previous}")]
    RowNotAscending {
        /// The row, counted from 0.
        row: usize,
        /// Its master position.
        master: f64,
        /// The previous row's master position.
        previous: f64,
    },
    /// An equidistant table whose master step changes.
    #[error("row {row}: master step {step} differs from the table's step {expected}")]
    NotEquidistant {
        /// The row, counted from 0.
        row: usize,
        /// The step into this row.
        step: f64,
        /// The first step.
        expected: f64,
    },
    /// Rows whose step, slope, period or spline is not a finite number (rows closer than
    /// the arithmetic resolves, or a range wider than it holds).
    #[error("row {row}: the rows around it cannot be interpolated (step or slope not finite)")]
    NotInterpolable {
        /// The row, counted from 0.
        row: usize,
    },
    /// Fewer than two active points.
    #[error("a motion function needs at least 2 active points, found {active}")]
    TooFewPoints {
        /// Active (not ignored) points.
        active: usize,
    },
    /// Too few or too many rows.
    #[error("{rows} rows; this table needs {min} to {max}")]
    Rows {
        /// Rows given.
        rows: usize,
        /// The least this table type and interpolation need.
        min: usize,
        /// The most accepted.
        max: usize,
    },
    /// A row or table with the wrong column count.
    #[error("row {row}: {cols} columns, a position table has 2 (master, slave)")]
    Columns {
        /// The row (0 for a file header).
        row: usize,
        /// Columns found.
        cols: usize,
    },
    /// A binary table whose size disagrees with its header.
    #[error("binary table of {found} bytes, its header announces {expected}")]
    ArraySize {
        /// Bytes expected from the header.
        expected: usize,
        /// Bytes found.
        found: usize,
    },
    /// No data at all.
    #[error("the table holds no data")]
    NoData,
    /// An interpolation the table type does not allow (4-point needs equidistant rows).
    #[error("4-point interpolation needs an equidistant table")]
    InterpolationNeedsEquidistant,
    /// The symmetry of a rest-to-rest law outside (-0.5, 0.5).
    #[error("point {point}: symmetry {value} outside (-0.5, 0.5)")]
    Symmetry {
        /// The point that starts the segment.
        point: u32,
        /// The value of its jerk/symmetry field.
        value: f64,
    },
    /// The laws or the point type meeting at a point demand different values.
    #[error("point {point}: {field} {demanded} demanded by the {by} contradicts {other}")]
    BoundaryConflict {
        /// The point.
        point: u32,
        /// The quantity in conflict.
        field: Field,
        /// The value one side demands.
        demanded: f64,
        /// Who demands it.
        by: Demand,
        /// The value fixed by the point type or the other segment.
        other: f64,
    },
    /// A law that cannot be built from its boundary values (a singular system).
    #[error("point {point}: the segment's law cannot meet its boundary values")]
    Unbuildable {
        /// The point that starts the segment.
        point: u32,
    },
    /// A sampling request whose increment does not reach the end or yields too many rows.
    #[error("increment {increment} from {from} to {to} is not usable (zero, wrong sign or more than {max_rows} rows)")]
    Increment {
        /// First master position.
        from: f64,
        /// Last master position.
        to: f64,
        /// Step.
        increment: f64,
        /// The most rows produced.
        max_rows: usize,
    },
    /// A value mask outside 1..=15.
    #[error("value mask {mask} selects no column or unknown columns (1 position, 2 velocity, 4 acceleration, 8 jerk)")]
    ValueMask {
        /// The mask given.
        mask: u32,
    },
    /// A point write outside the function.
    #[error("points {first}..{last} are not all in the function (1..{count})")]
    WriteRange {
        /// First point written.
        first: u32,
        /// Last point written.
        last: u32,
        /// Points in the function.
        count: u32,
    },
    /// A change request while the online-change mode refuses changes.
    #[error("online changes are switched off for this cam")]
    ChangesOff,
    /// An activation at an axis position the master has already passed.
    #[error("activation position {position} already passed (master at {master})")]
    ActivationPassed {
        /// The requested position.
        position: f64,
        /// Where the master stands.
        master: f64,
    },
    /// An activation mode the seed marks as not implemented or not valid for this operation.
    #[error("activation mode {mode} is not available for online changes")]
    ActivationMode {
        /// Raw mode value.
        mode: u32,
    },
    /// A profile of a kind that does not support the request (points of a table).
    #[error("cam table {id} is not a motion function")]
    NotMotionFunction {
        /// The table ID.
        id: u32,
    },
    /// A table type name or number the controller does not know.
    #[error("unknown table type (equidistant, non_equidistant)")]
    UnknownTableType,
    /// An interpolation name the controller does not know.
    #[error("unknown interpolation (linear, 4point, spline)")]
    UnknownInterpolation,
    /// No profile under this ID.
    #[error("no cam table with ID {id}")]
    NoSuchTable {
        /// The table ID.
        id: u32,
    },
}

/// Who demands a boundary value at a point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Demand {
    /// The segment that ends at the point.
    SegmentBefore,
    /// The segment that starts at the point.
    SegmentAfter,
}

impl fmt::Display for Demand {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Demand::SegmentBefore => "segment ending here",
            Demand::SegmentAfter => "segment starting here",
        })
    }
}

impl CamError {
    /// The seed's error code for this refusal.
    pub fn code(&self) -> TableErrorCode {
        use TableErrorCode as C;
        match self {
            CamError::TableId { .. } | CamError::NoSuchTable { .. } => C::CamTableIdInvalid,
            CamError::PointIndex { .. }
            | CamError::RelIndex { .. }
            | CamError::UnknownFunctionType { .. }
            | CamError::UnknownPointType { .. }
            | CamError::PointNotFinite { .. }
            | CamError::Symmetry { .. }
            | CamError::BoundaryConflict { .. }
            | CamError::Unbuildable { .. }
            | CamError::WriteRange { .. } => C::PointIdInvalid,
            CamError::MasterNotMonotonic { .. }
            | CamError::RowNotAscending { .. }
            | CamError::NotEquidistant { .. }
            | CamError::NotInterpolable { .. }
            | CamError::Increment { .. }
            | CamError::ActivationPassed { .. } => C::IncrementInvalid,
            CamError::TooFewPoints { .. } => C::NumPointsInvalid,
            CamError::Rows { .. } | CamError::RowNotFinite { .. } => C::NumRowsInvalid,
            CamError::Columns { .. } | CamError::ValueMask { .. } => C::NumColumnsInvalid,
            CamError::ArraySize { .. } => C::ArraySizeInvalid,
            CamError::NoData => C::PointerInvalid,
            CamError::InterpolationNeedsEquidistant
            | CamError::ChangesOff
            | CamError::ActivationMode { .. }
            | CamError::NotMotionFunction { .. }
            | CamError::UnknownTableType
            | CamError::UnknownInterpolation => C::McTableTypeInvalid,
        }
    }
}
