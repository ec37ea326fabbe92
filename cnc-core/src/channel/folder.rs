//! A channel's program folder: the PLC selects programs by file name (`SELECT` of the channel
//! control unit), and the machine loads and checks them here, between ticks, never in one.
//! A name is a plain file name (no path, no leading dot), a file is read up to a bound.

use super::program::LoadedProgram;
use crate::nc::decode::DecoderSetup;
use crate::nc::interp::SearchPath;
use hli::enums::ChannelCommandError;
use hli::layout::PROGRAM_NAME_LEN;
use std::io::Read;
use std::path::PathBuf;

/// The largest program file a channel reads (bytes).
pub const MAX_PROGRAM_BYTES: u64 = 16 << 20;

/// Where a channel finds the programs the PLC selects, and what they are checked with.
#[derive(Debug, Clone)]
pub struct ProgramFolder {
    /// The folder.
    pub dir: PathBuf,
    /// The channel's machine data.
    pub setup: DecoderSetup,
    /// Where `L name` looks after the program's own folder.
    pub search: SearchPath,
}

/// A program name as the PLC wrote it: fixed room, no allocation in the tick.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ProgramName {
    bytes: [u8; PROGRAM_NAME_LEN],
}

impl ProgramName {
    /// The name in `bytes` (NUL-padded), checked: a plain file name of `A-Z a-z 0-9 _ - .`,
    /// not starting with a dot, at most 63 bytes.
    pub fn parse(bytes: &[u8; PROGRAM_NAME_LEN]) -> Result<ProgramName, ChannelCommandError> {
        let end = bytes.iter().position(|&b| b == 0).unwrap_or(bytes.len());
        let name = &bytes[..end];
        let plain = |b: &u8| b.is_ascii_alphanumeric() || matches!(b, b'_' | b'-' | b'.');
        let padded = bytes[end..].iter().all(|&b| b == 0);
        if name.is_empty() || end == bytes.len() || name[0] == b'.' || !padded {
            return Err(ChannelCommandError::BadName);
        }
        if !name.iter().all(plain) {
            return Err(ChannelCommandError::BadName);
        }
        Ok(ProgramName { bytes: *bytes })
    }

    /// The name as text.
    pub fn as_str(&self) -> &str {
        hli::layout::nul_padded_str(&self.bytes).unwrap_or("")
    }

    /// The bytes as the unit carries them.
    pub fn bytes(&self) -> &[u8; PROGRAM_NAME_LEN] {
        &self.bytes
    }
}

/// Why a program could not be selected: the code the PLC reads and the text beside it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct SelectRefusal {
    /// The code.
    pub code: ChannelCommandError,
    /// The text (a check's first diagnostic, FILE:LINE:COL).
    pub message: String,
}

impl ProgramFolder {
    /// Reads and checks program `name` for a channel with `axes`.
    pub fn load(
        &self,
        name: &ProgramName,
        axes: &[String],
    ) -> Result<LoadedProgram, SelectRefusal> {
        let path = self.dir.join(name.as_str());
        let refuse = |code, message: String| SelectRefusal { code, message };
        let file = std::fs::File::open(&path).map_err(|e| {
            refuse(
                ChannelCommandError::ProgramNotFound,
                format!("{}: {e}", path.display()),
            )
        })?;
        let mut src = String::new();
        let read = file.take(MAX_PROGRAM_BYTES + 1).read_to_string(&mut src);
        let invalid = ChannelCommandError::ProgramInvalid;
        match read {
            Err(e) => return Err(refuse(invalid, format!("{}: {e}", path.display()))),
            Ok(n) if n as u64 > MAX_PROGRAM_BYTES => {
                return Err(refuse(
                    invalid,
                    format!("{}: larger than {MAX_PROGRAM_BYTES} bytes", path.display()),
                ))
            }
            Ok(_) => {}
        }
        LoadedProgram::load_with(
            &path.display().to_string(),
            &src,
            axes,
            &self.setup,
            Some(self.dir.clone()),
            &self.search,
        )
        .map_err(|e| {
            let first = e.diagnostics.first().map(|d| d.render(&e.name));
            refuse(invalid, first.unwrap_or_else(|| e.to_string()))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn name(text: &str) -> [u8; PROGRAM_NAME_LEN] {
        hli::layout::nul_padded(text)
    }

    #[test]
    fn names_are_plain_file_names() {
        assert_eq!(
            ProgramName::parse(&name("part_1.nc")).unwrap().as_str(),
            "part_1.nc"
        );
        for bad in ["", "../etc/passwd", "a/b.nc", ".hidden", "a b", "ü.nc"] {
            assert_eq!(
                ProgramName::parse(&name(bad)),
                Err(ChannelCommandError::BadName),
                "{bad:?}"
            );
        }
        let mut garbage = name("a.nc");
        garbage[10] = b'x';
        assert_eq!(
            ProgramName::parse(&garbage),
            Err(ChannelCommandError::BadName)
        );
        assert_eq!(
            ProgramName::parse(&[b'a'; PROGRAM_NAME_LEN]),
            Err(ChannelCommandError::BadName)
        );
    }
}
