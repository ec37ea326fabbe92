//! The standard engine set of a machine, in its tick order. Each engine's machine file
//! declares one [`EngineDef`]: the keys of the machine configuration it reads, how it turns
//! them into its own configuration when the configuration is loaded (`configure`), and how it
//! is built from that (`build`, which leaves it out when the machine has nothing for it).
//! [`STANDARD`] lists them, one line per engine. The order matters: an engine later in the
//! list sees the set-points of this tick of the axes the ones before it drive (the flying
//! saw, last, follows a master a cam or a FIFO group moves).
//!
//! The application reads its own keys of a scenario and hands every key an engine declared
//! ([`sections`]) to [`configure`] untouched: it names no engine, and an engine's keys,
//! their checks and their error texts live in the engine's file.

use super::Engine;
use std::any::Any;
use std::path::PathBuf;
use std::sync::Arc;

/// What every engine of a machine is built with: the machine beside its configuration.
#[derive(Debug, Clone, Copy)]
pub struct EngineSetup {
    /// Axes of all channels, in the machine's axis numbering before the single axes.
    pub channel_axes: usize,
    /// Single axes (PLCopen axes), numbered after the channel axes.
    pub single_axes: usize,
    /// The CNC cycle in seconds.
    pub cycle_s: f64,
}

impl EngineSetup {
    /// Every axis of the machine.
    pub fn axes(&self) -> usize {
        self.channel_axes + self.single_axes
    }
}

/// What an engine's configuration is made from when the machine configuration is loaded.
pub struct ConfigInput<'a> {
    /// The keys of the machine configuration the engine declared, as given (a key that is
    /// not given is absent).
    pub sections: &'a toml::Table,
    /// Every axis's name in the machine's numbering (channel axes `CHANNEL.AXIS` first).
    pub axis_names: &'a [String],
    /// How many of them are channel axes.
    pub channel_axes: usize,
    /// Reads a file the configuration names (relative to it): its resolved path and text,
    /// or why not.
    pub open: &'a OpenFile<'a>,
}

/// Reads a file a configuration names: its resolved path and text, or why not.
pub type OpenFile<'a> = dyn Fn(&str) -> Result<(PathBuf, String), String> + 'a;

/// Makes an engine from the setup and its configuration, or `None` when the machine has
/// nothing for it.
pub type Build = fn(&EngineSetup, &Config) -> Result<Option<Box<dyn Engine>>, SetupError>;

/// An engine's own configuration, made by its `configure` and read back by its `build`.
pub type Config = Arc<dyn Any + Send + Sync>;

/// Why an engine could not be configured or made (the engine's own error, whose text names
/// the configuration key).
pub type SetupError = Box<dyn std::error::Error + Send + Sync>;

/// An engine as the machine's configuration knows it.
#[derive(Debug, Clone, Copy)]
pub struct EngineDef {
    /// The engine's name (its errors' prefix).
    pub name: &'static str,
    /// The top-level keys of the machine configuration it reads (`gear` for `[[gear]]`).
    pub sections: &'static [&'static str],
    /// Its configuration from those keys, checked.
    pub configure: fn(&ConfigInput<'_>) -> Result<Config, SetupError>,
    /// The engine for a machine, or `None` when the machine has nothing for it.
    pub build: Build,
}

/// An engine without keys of its own: its configuration is empty.
pub fn no_config(_: &ConfigInput<'_>) -> Result<Config, SetupError> {
    Ok(Arc::new(()))
}

/// An engine's configuration read back as its own type `T` (what its `configure` made).
pub fn config_of<T: Any + Send + Sync>(config: &Config) -> Result<&T, SetupError> {
    config
        .downcast_ref::<T>()
        .ok_or_else(|| "an engine was built from another engine's configuration".into())
}

/// The standard engines in their tick order: one line per engine.
pub const STANDARD: &[EngineDef] = &[
    crate::gear::ENGINE,
    crate::cam::machine::ENGINE,
    crate::fifo::machine::ENGINE,
    crate::saw::machine::ENGINE,
];

/// Engines outside this crate, registered once per process ([`register_extension`]).
static EXTENSIONS: std::sync::OnceLock<&'static [EngineDef]> = std::sync::OnceLock::new();

/// Registers engines outside this crate, once per process and before the first machine
/// configuration is read (a program's `main`, a test's first line): they join the machine
/// after the [`STANDARD`] engines, in the order given. A name or configuration key that is
/// taken is refused; registering the same engines again is allowed, others are refused.
pub fn register_extension(engines: &'static [EngineDef]) -> Result<(), SetupError> {
    for (i, engine) in engines.iter().enumerate() {
        let before = || STANDARD.iter().chain(&engines[..i]);
        if before().any(|e| e.name == engine.name) {
            return Err(format!("engine {}: the name is taken", engine.name).into());
        }
        let taken = |key: &&&str| before().any(|e| e.sections.contains(*key));
        if let Some(key) = engine.sections.iter().find(taken) {
            return Err(format!("engine {}: the key `{key}` is taken", engine.name).into());
        }
    }
    let set = EXTENSIONS.get_or_init(|| engines);
    if core::ptr::eq(*set, engines) {
        Ok(())
    } else {
        Err("other extension engines are registered already".into())
    }
}

/// The engines of every machine in their tick order: the [`STANDARD`] ones, then the
/// registered extensions.
pub fn all() -> impl Iterator<Item = &'static EngineDef> + Clone {
    let extensions: &'static [EngineDef] = EXTENSIONS.get().copied().unwrap_or(&[]);
    STANDARD.iter().chain(extensions)
}

/// Every configuration key an engine reads.
pub fn sections() -> impl Iterator<Item = &'static str> {
    all().flat_map(|e| e.sections.iter().copied())
}

/// The configurations of the engines ([`all`]), one each in their order.
#[derive(Clone)]
pub struct EngineConfigs(Vec<Config>);

impl core::fmt::Debug for EngineConfigs {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        write!(f, "EngineConfigs({} engines)", self.0.len())
    }
}

/// Every engine's configuration ([`all`]) from the keys in `input.sections` (each engine
/// sees only the keys it declared). A key two engines declare is refused.
pub fn configure(input: &ConfigInput<'_>) -> Result<EngineConfigs, SetupError> {
    let mut configs = Vec::with_capacity(all().count());
    for (i, engine) in all().enumerate() {
        for key in engine.sections {
            if let Some(other) = all().take(i).find(|e| e.sections.contains(key)) {
                return Err(format!(
                    "`{key}` is read by two engines: {} and {}",
                    other.name, engine.name
                )
                .into());
            }
        }
        let own: toml::Table = input
            .sections
            .iter()
            .filter(|(key, _)| engine.sections.contains(&key.as_str()))
            .map(|(key, value)| (key.clone(), value.clone()))
            .collect();
        configs.push((engine.configure)(&ConfigInput {
            sections: &own,
            ..*input
        })?);
    }
    Ok(EngineConfigs(configs))
}

/// The engines of a machine ([`all`]), made from `setup` and their configurations in their
/// tick order.
pub fn standard(
    setup: &EngineSetup,
    configs: &EngineConfigs,
) -> Result<Vec<Box<dyn Engine>>, SetupError> {
    let mut engines = Vec::with_capacity(configs.0.len());
    for (engine, config) in all().zip(&configs.0) {
        engines.extend((engine.build)(setup, config)?);
    }
    Ok(engines)
}

/// A configuration section as `T` (serde), or `T::default()` when the key is not given; the
/// error names the key.
pub fn section<T: serde::de::DeserializeOwned + Default>(
    sections: &toml::Table,
    key: &str,
) -> Result<T, SetupError> {
    match sections.get(key) {
        None => Ok(T::default()),
        Some(value) => value
            .clone()
            .try_into()
            .map_err(|e| format!("[[{key}]]: {}", e.message()).into()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_two_engines_read_one_key() {
        let mut keys: Vec<&str> = sections().collect();
        let n = keys.len();
        keys.sort_unstable();
        keys.dedup();
        assert_eq!(keys.len(), n);
    }

    #[test]
    fn a_machine_without_engine_keys_configures_and_builds() {
        let open = |_: &str| Err("no files".to_string());
        let input = ConfigInput {
            sections: &toml::Table::new(),
            axis_names: &["X".to_string()],
            channel_axes: 0,
            open: &open,
        };
        let configs = configure(&input).unwrap();
        let setup = EngineSetup {
            channel_axes: 0,
            single_axes: 1,
            cycle_s: 0.001,
        };
        // A single axis: the cams and the saw; no gear and no FIFO group without their keys.
        let names: Vec<&str> = standard(&setup, &configs)
            .unwrap()
            .iter()
            .map(|e| e.name())
            .collect();
        assert!(
            names.contains(&"cam") && names.contains(&"flying saw"),
            "{names:?}"
        );
        assert!(
            !names.contains(&"gear") && !names.contains(&"fifo"),
            "{names:?}"
        );
    }

    #[test]
    fn an_extension_may_not_take_a_name_or_a_key() {
        static NAME: &[EngineDef] = &[EngineDef {
            name: "saw",
            ..crate::saw::machine::ENGINE
        }];
        let e = register_extension(NAME).unwrap_err().to_string();
        assert_eq!(e, "engine saw: the name is taken");
        static KEY: &[EngineDef] = &[EngineDef {
            name: "mine",
            sections: &["gear"],
            ..crate::saw::machine::ENGINE
        }];
        let e = register_extension(KEY).unwrap_err().to_string();
        assert_eq!(e, "engine mine: the key `gear` is taken");
    }
}
