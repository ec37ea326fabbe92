//! A channel program ready to run: parsed and checked as a whole in one pass (a program with
//! any diagnostic is refused, never executed), keeping its tree and its jump table. Blocks are
//! decoded only when the channel reaches them.

use crate::nc::decode::{check_channel_axes, check_program, DecoderSetup, ZeroVars};
use crate::nc::interp::{ProgramSet, SearchPath};
use crate::nc::Diagnostic;
use std::path::{Path, PathBuf};

/// A checked program.
#[derive(Debug, Clone)]
pub struct LoadedProgram {
    /// Name for messages (file name or scenario key).
    pub name: String,
    /// The program with every subroutine file it calls.
    pub set: ProgramSet,
    /// The machine data its blocks are decoded with.
    pub setup: DecoderSetup,
}

/// A program refused at load.
#[derive(Debug, Clone, thiserror::Error)]
#[error("{}", render(.name, .diagnostics))]
pub struct ProgramError {
    /// Program name.
    pub name: String,
    /// Everything wrong with it.
    pub diagnostics: Vec<Diagnostic>,
}

fn render(name: &str, diagnostics: &[Diagnostic]) -> String {
    diagnostics
        .iter()
        .map(|d| d.render(name))
        .collect::<Vec<_>>()
        .join("\n")
}

impl LoadedProgram {
    /// Parses and checks `src` for a channel with `axes`, without machine data; subroutine
    /// files are looked for next to `name` when it names a file.
    pub fn load(name: &str, src: &str, axes: &[String]) -> Result<Self, ProgramError> {
        let dir = Path::new(name)
            .parent()
            .filter(|d| d.is_dir())
            .map(Path::to_path_buf);
        Self::load_with(
            name,
            src,
            axes,
            &DecoderSetup::default(),
            dir,
            &SearchPath::default(),
        )
    }

    /// Parses and checks `src` for a channel with `axes` and the machine data of `setup`;
    /// `L name` looks in `dir`, then in `search`.
    pub fn load_with(
        name: &str,
        src: &str,
        axes: &[String],
        setup: &DecoderSetup,
        dir: Option<PathBuf>,
        search: &SearchPath,
    ) -> Result<Self, ProgramError> {
        let refuse = |diagnostics| ProgramError {
            name: name.to_string(),
            diagnostics,
        };
        if let Err(message) = check_channel_axes(axes) {
            return Err(refuse(vec![Diagnostic::whole_program(message)]));
        }
        let (set, diagnostics) = check_program(
            name,
            src.to_string(),
            axes,
            setup,
            (dir.as_deref(), search),
            &ZeroVars,
            None,
        );
        if !diagnostics.is_empty() {
            return Err(refuse(diagnostics));
        }
        Ok(Self {
            name: name.to_string(),
            set,
            setup: setup.clone(),
        })
    }

    /// Number of blocks of the main file.
    pub fn len(&self) -> usize {
        self.set.main().tree.blocks.len()
    }

    /// Whether the main file has no blocks.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}
