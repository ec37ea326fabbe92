//! The cam engine's configuration: the tables it starts with, one `[[cam_table]]` each, read
//! from a JSON cam file beside the machine configuration (docs/cams.md), and its build.
//!
//! ```toml
//! [[cam_table]]
//! file = "cams/lift.json"   # a JSON cam file
//! id = 3                    # 1..=255; the file's own id, if it has one, must agree
//! ```

use super::CamEngine;
use crate::cam::online::CamStore;
use crate::cam::CamProfile;
use crate::machine::engine::Engine;
use crate::machine::engines::{
    config_of, section, Config, ConfigInput, EngineDef, EngineSetup, SetupError,
};
use std::sync::Arc;

/// The cam engine in the engine set ([`crate::machine::engines::STANDARD`]).
pub const ENGINE: EngineDef = EngineDef {
    name: "cam",
    sections: &["cam_table"],
    configure,
    build,
};

/// One `[[cam_table]]` table.
#[derive(Debug, serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct CamTableFile {
    file: String,
    id: Option<u32>,
}

/// A cam table of the setup that the store refused.
#[derive(Debug, thiserror::Error)]
#[error("[[cam_table]] {id}: {error}")]
pub struct CamTableError {
    /// Its table ID.
    pub id: u32,
    /// Why.
    pub error: crate::cam::CamError,
}

/// The cam tables by ID, each file read and checked.
fn configure(input: &ConfigInput<'_>) -> Result<Config, SetupError> {
    let files: Vec<CamTableFile> = section(input.sections, "cam_table")?;
    let mut tables: Vec<(u32, CamProfile)> = Vec::with_capacity(files.len());
    for t in &files {
        let (path, text) = (input.open)(&t.file).map_err(|e| format!("[[cam_table]] file: {e}"))?;
        let at = path.display();
        if !text.trim_start().starts_with('{') {
            let e = format!("[[cam_table]] {at}: a scenario takes JSON cam files (docs/cams.md)");
            return Err(e.into());
        }
        let cam = crate::cam::file::parse(text.as_bytes(), Default::default())
            .map_err(|e| format!("[[cam_table]] {at}: {e}"))?;
        let id = table_id(cam.id, t.id).map_err(|e| format!("[[cam_table]] {at}: {e}"))?;
        if tables.iter().any(|(other, _)| *other == id) {
            return Err(format!("[[cam_table]] {at}: id {id} is taken by another table").into());
        }
        tables.push((id, cam.profile));
    }
    Ok(Arc::new(tables))
}

/// A cam table's ID: the file's or the configuration's (they must agree), in 1..=255.
fn table_id(in_file: Option<u32>, in_config: Option<u32>) -> Result<u32, String> {
    let id = match (in_file, in_config) {
        (Some(a), Some(b)) if a != b => {
            return Err(format!("the file has id {a}, the scenario says {b}"))
        }
        (Some(id), _) | (None, Some(id)) => id,
        (None, None) => return Err("no id (give `id = 1..255`)".to_string()),
    };
    if !(1..=255).contains(&id) {
        return Err(format!("id {id} is outside 1..255"));
    }
    Ok(id)
}

/// The cam engine of a machine with cam tables or single axes: a PLC may load tables and
/// couple any time (an idle engine costs a pass over empty slots).
fn build(setup: &EngineSetup, config: &Config) -> Result<Option<Box<dyn Engine>>, SetupError> {
    let tables: &Vec<(u32, CamProfile)> = config_of(config)?;
    if tables.is_empty() && setup.single_axes == 0 {
        return Ok(None);
    }
    let mut store = CamStore::new();
    for (id, profile) in tables {
        store
            .insert(*id, profile.clone())
            .map_err(|error| CamTableError { id: *id, error })?;
    }
    Ok(Some(Box::new(CamEngine::new(store, setup.axes()))))
}
