//! Cam files: the JSON form of a motion function or a position table, and the binary table
//! file of the seed (a header of two unsigned shorts, rows and columns, then the rows as
//! doubles, little-endian, no separators).

use super::error::CamError;
use super::motion_function::{MotionFunction, MotionFunctionPoint, PointType};
use super::table::{PositionTable, TableType};
use super::{CamProfile, FunctionType};
use hli::calls::cam::CamInterpolation;
use serde::Deserialize;
use std::path::Path;

/// Why a cam file could not be loaded.
#[derive(Debug, thiserror::Error)]
pub enum LoadError {
    /// The file could not be read.
    #[error("cannot read: {0}")]
    Io(#[from] std::io::Error),
    /// Not JSON of the expected form.
    #[error("not a cam file: {0}")]
    Json(#[from] serde_json::Error),
    /// Read, but refused.
    #[error("error {code:#06X} ({name}): {0}", code = .0.code() as u32, name = .0.code().name())]
    Cam(#[from] CamError),
}

/// A loaded cam file.
#[derive(Debug, Clone, PartialEq)]
pub struct CamFile {
    /// The table ID the file names, if any (checked to be 1..=255).
    pub id: Option<u32>,
    /// The profile.
    pub profile: CamProfile,
}

/// How to read a binary table, which carries no type of its own.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BinaryOptions {
    /// Interpolation of the table.
    pub interpolation: CamInterpolation,
    /// Whether the table continues cyclically.
    pub periodic: bool,
}

impl Default for BinaryOptions {
    fn default() -> Self {
        BinaryOptions {
            interpolation: CamInterpolation::Linear,
            periodic: false,
        }
    }
}

#[derive(Deserialize)]
#[serde(untagged)]
enum NameOrNumber {
    Number(u32),
    Name(String),
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct PointJson {
    index: u32,
    function: NameOrNumber,
    point_type: NameOrNumber,
    #[serde(default)]
    rel_index_next: i64,
    master: f64,
    slave: f64,
    #[serde(default)]
    velocity: f64,
    #[serde(default)]
    acceleration: f64,
    #[serde(default)]
    jerk: f64,
}

#[derive(Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
enum FileJson {
    MotionFunction {
        #[serde(default)]
        id: Option<u32>,
        points: Vec<PointJson>,
    },
    Table {
        #[serde(default)]
        id: Option<u32>,
        table_type: String,
        #[serde(default)]
        periodic: bool,
        #[serde(default)]
        interpolation: Option<String>,
        rows: Vec<Vec<f64>>,
    },
}

/// Reads a cam file: JSON if it starts with `{`, the binary table format otherwise.
pub fn load(path: &Path, binary: BinaryOptions) -> Result<CamFile, LoadError> {
    let bytes = std::fs::read(path)?;
    parse(&bytes, binary)
}

/// Parses cam file contents (see [`load`]).
pub fn parse(bytes: &[u8], binary: BinaryOptions) -> Result<CamFile, LoadError> {
    let first = bytes.iter().find(|b| !b.is_ascii_whitespace());
    if first == Some(&b'{') {
        return Ok(from_json(serde_json::from_slice(bytes)?)?);
    }
    let rows = read_binary(bytes)?;
    let table_type = if is_equidistant(&rows) {
        TableType::Equidistant
    } else {
        TableType::NonEquidistant
    };
    Ok(CamFile {
        id: None,
        profile: CamProfile::Table(PositionTable::new(
            &rows,
            table_type,
            binary.interpolation,
            binary.periodic,
        )?),
    })
}

fn from_json(file: FileJson) -> Result<CamFile, CamError> {
    let check_id = |id: Option<u32>| match id {
        Some(id) if !(1..=255).contains(&id) => Err(CamError::TableId { id }),
        other => Ok(other),
    };
    match file {
        FileJson::MotionFunction { id, points } => {
            let id = check_id(id)?;
            let points = points
                .iter()
                .map(point_from_json)
                .collect::<Result<Vec<_>, _>>()?;
            Ok(CamFile {
                id,
                profile: CamProfile::MotionFunction(MotionFunction::new(&points)?),
            })
        }
        FileJson::Table {
            id,
            table_type,
            periodic,
            interpolation,
            rows,
        } => {
            let id = check_id(id)?;
            let table_type = match table_type.to_ascii_lowercase().as_str() {
                "equidistant" | "10" => TableType::Equidistant,
                "non_equidistant" | "nonequidistant" | "11" => TableType::NonEquidistant,
                _ => return Err(CamError::UnknownTableType),
            };
            let interpolation = match interpolation.as_deref().map(str::to_ascii_lowercase) {
                None => CamInterpolation::Linear,
                Some(name) => match name.as_str() {
                    "linear" | "0" => CamInterpolation::Linear,
                    "4point" | "fourpoint" | "4_point" | "1" => CamInterpolation::FourPoint,
                    "spline" | "2" => CamInterpolation::Spline,
                    _ => return Err(CamError::UnknownInterpolation),
                },
            };
            let mut pairs = Vec::with_capacity(rows.len());
            for (row, r) in rows.iter().enumerate() {
                match r.as_slice() {
                    [m, s] => pairs.push([*m, *s]),
                    _ => return Err(CamError::Columns { row, cols: r.len() }),
                }
            }
            Ok(CamFile {
                id,
                profile: CamProfile::Table(PositionTable::new(
                    &pairs,
                    table_type,
                    interpolation,
                    periodic,
                )?),
            })
        }
    }
}

fn point_from_json(p: &PointJson) -> Result<MotionFunctionPoint, CamError> {
    let function = match &p.function {
        NameOrNumber::Number(n) => *n,
        NameOrNumber::Name(name) => FunctionType::from_name(name).map(FunctionType::raw).ok_or(
            CamError::UnknownFunctionType {
                point: p.index,
                raw: u32::MAX,
            },
        )?,
    };
    let point_type =
        match &p.point_type {
            NameOrNumber::Number(n) => *n,
            NameOrNumber::Name(name) => PointType::from_name(name).map(PointType::raw).ok_or(
                CamError::UnknownPointType {
                    point: p.index,
                    raw: u32::MAX,
                },
            )?,
        };
    Ok(MotionFunctionPoint {
        index: p.index,
        function,
        point_type,
        rel_index_next: p.rel_index_next,
        master: p.master,
        slave: p.slave,
        velocity: p.velocity,
        acceleration: p.acceleration,
        jerk: p.jerk,
    })
}

/// Rows of a binary table file.
pub fn read_binary(bytes: &[u8]) -> Result<Vec<[f64; 2]>, CamError> {
    if bytes.len() < 4 {
        return Err(CamError::NoData);
    }
    let rows = u16::from_le_bytes([bytes[0], bytes[1]]) as usize;
    let cols = u16::from_le_bytes([bytes[2], bytes[3]]) as usize;
    if cols != 2 {
        return Err(CamError::Columns { row: 0, cols });
    }
    let expected = 4 + rows * cols * 8;
    if bytes.len() != expected {
        return Err(CamError::ArraySize {
            expected,
            found: bytes.len(),
        });
    }
    let value = |i: usize| {
        let at = 4 + 8 * i;
        f64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"))
    };
    Ok((0..rows)
        .map(|r| [value(2 * r), value(2 * r + 1)])
        .collect())
}

/// The binary table file of `rows`.
pub fn write_binary(rows: &[[f64; 2]]) -> Result<Vec<u8>, CamError> {
    let n = u16::try_from(rows.len()).map_err(|_| CamError::Rows {
        rows: rows.len(),
        min: 2,
        max: u16::MAX as usize,
    })?;
    let mut out = Vec::with_capacity(4 + rows.len() * 16);
    out.extend_from_slice(&n.to_le_bytes());
    out.extend_from_slice(&2u16.to_le_bytes());
    for r in rows {
        out.extend_from_slice(&r[0].to_le_bytes());
        out.extend_from_slice(&r[1].to_le_bytes());
    }
    Ok(out)
}

fn is_equidistant(rows: &[[f64; 2]]) -> bool {
    let n = rows.len();
    if n < 2 {
        return false;
    }
    let step = (rows[n - 1][0] - rows[0][0]) / (n - 1) as f64;
    step > 0.0
        && step.is_finite()
        && rows.iter().enumerate().all(|(i, r)| {
            let expected = rows[0][0] + step * i as f64;
            (r[0] - expected).abs() <= super::table::equidistance_tolerance(step, expected)
        })
}
