//! Loading a program with the subroutine files its calls reach: a [`ProgramSet`], its calls
//! resolved and its control flow matched.

use super::with_file;
use crate::nc::ast::{Item, Program, Span};
use crate::nc::control::{match_control, JumpTable};
use crate::nc::{parse, Diagnostic};
use std::path::{Path, PathBuf};

/// One program file with its tree, jump table and resolved calls.
#[derive(Debug, Clone)]
pub struct Unit {
    /// The file name as given (for messages).
    pub name: String,
    /// The source text.
    pub src: String,
    /// The tree.
    pub tree: Program,
    /// The jumps of its `$` blocks.
    pub jumps: JumpTable,
    /// Per block with a call: where it goes (sorted by block).
    pub(super) calls: Vec<(u32, Callee)>,
    /// A subroutine file (its diagnostics name it; the main file's are named by the caller).
    pub(super) called: bool,
}

/// Where a call goes: blocks `blocks` of unit `unit`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Callee {
    pub(super) unit: u32,
    pub(super) start: u32,
    pub(super) end: u32,
}

/// A main program and every subroutine file it reaches.
#[derive(Debug, Clone)]
pub struct ProgramSet {
    /// `units[0]` is the main program.
    pub units: Vec<Unit>,
}

/// Where `L name` looks for files: the calling file's folder, then these folders.
#[derive(Debug, Clone, Default)]
pub struct SearchPath(pub Vec<PathBuf>);

impl ProgramSet {
    /// Parses `src` (named `name`, in folder `dir` when it is a file) and every file its calls
    /// reach, resolving calls and matching control flow. Every problem is a diagnostic with its
    /// file; the set is only runnable when there are none.
    pub fn load(
        name: &str,
        src: String,
        dir: Option<&Path>,
        search: &SearchPath,
    ) -> (Self, Vec<Diagnostic>) {
        let mut set = ProgramSet { units: Vec::new() };
        let mut diags = Vec::new();
        let mut dirs: Vec<Option<PathBuf>> = Vec::new();
        let mut paths: Vec<Option<PathBuf>> = Vec::new();
        set.add_unit(name.to_string(), src, &mut diags);
        dirs.push(dir.map(Path::to_path_buf));
        paths.push(None);
        let mut u = 0;
        while u < set.units.len() {
            let calls: Vec<(u32, Span, bool, String)> = {
                let unit = &set.units[u];
                unit.tree
                    .blocks
                    .iter()
                    .enumerate()
                    .flat_map(|(b, block)| {
                        unit.tree
                            .items_of(block)
                            .iter()
                            .filter_map(move |i| match i {
                                Item::Call { call, span } => {
                                    Some((b as u32, *span, call.local, call.name.clone()))
                                }
                                _ => None,
                            })
                    })
                    .collect()
            };
            for (b, span, local, callee) in calls {
                let target = if local {
                    set.local_callee(u, b, &callee, span, &mut diags)
                } else {
                    set.global_callee(u, &callee, span, &dirs, &mut paths, search, &mut diags)
                        .map(|unit| {
                            if dirs.len() < set.units.len() {
                                let dir = paths[unit as usize]
                                    .as_deref()
                                    .and_then(Path::parent)
                                    .map(Path::to_path_buf);
                                dirs.push(dir);
                            }
                            let main = &set.units[unit as usize].tree;
                            Callee {
                                unit,
                                start: main.main_start,
                                end: main.blocks.len() as u32,
                            }
                        })
                };
                if let Some(t) = target {
                    set.units[u].calls.push((b, t));
                }
            }
            u += 1;
        }
        (set, diags)
    }

    fn add_unit(&mut self, name: String, src: String, diags: &mut Vec<Diagnostic>) -> u32 {
        let (tree, parse_diags) = parse(&src);
        let (jumps, unmatched) = match_control(&tree);
        let mut unit_diags = parse_diags;
        for u in unmatched {
            unit_diags.push(Diagnostic::new(u.span, u.message, &src));
        }
        crate::nc::locate(&mut unit_diags, &src);
        let called = !self.units.is_empty();
        let file: std::sync::Arc<str> = name.as_str().into();
        diags.extend(unit_diags.into_iter().map(|mut d| {
            if called {
                d.file = Some(file.clone());
            }
            d
        }));
        self.units.push(Unit {
            name,
            src,
            tree,
            jumps,
            calls: Vec::new(),
            called,
        });
        (self.units.len() - 1) as u32
    }

    fn error(&self, unit: usize, span: Span, message: String, diags: &mut Vec<Diagnostic>) {
        let u = &self.units[unit];
        let mut d = Diagnostic::new(span, message, &u.src);
        let mut one = [d];
        crate::nc::locate(&mut one, &u.src);
        [d] = one;
        diags.push(with_file(d, u));
    }

    fn local_callee(
        &self,
        unit: usize,
        block: u32,
        name: &str,
        span: Span,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<Callee> {
        let tree = &self.units[unit].tree;
        if block < tree.main_start {
            self.error(
                unit,
                span,
                format!("LL {name}: local subroutines are called from the main program only"),
                diags,
            );
            return None;
        }
        let upper = name.to_ascii_uppercase();
        match tree.subs.iter().find(|s| s.name == upper) {
            Some(sub) => Some(Callee {
                unit: unit as u32,
                start: sub.blocks.start,
                end: sub.blocks.end,
            }),
            None => {
                let known: Vec<&str> = tree.subs.iter().map(|s| s.name.as_str()).collect();
                self.error(
                    unit,
                    span,
                    format!(
                        "LL {name}: no local subroutine \"%L {upper}\" in this file (defined: {})",
                        if known.is_empty() {
                            "none".to_string()
                        } else {
                            known.join(", ")
                        }
                    ),
                    diags,
                );
                None
            }
        }
    }

    #[allow(clippy::too_many_arguments)]
    fn global_callee(
        &mut self,
        unit: usize,
        name: &str,
        span: Span,
        dirs: &[Option<PathBuf>],
        paths: &mut Vec<Option<PathBuf>>,
        search: &SearchPath,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<u32> {
        let relative = Path::new(name);
        let candidates: Vec<PathBuf> = if relative.is_absolute() {
            vec![relative.to_path_buf()]
        } else {
            dirs[unit]
                .iter()
                .chain(search.0.iter())
                .map(|d| d.join(relative))
                .chain(dirs[unit].is_none().then(|| relative.to_path_buf()))
                .collect()
        };
        let Some(found) = candidates.iter().find(|p| p.is_file()) else {
            let looked: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
            self.error(
                unit,
                span,
                format!(
                    "L {name}: subroutine file not found (looked at: {})",
                    looked.join(", ")
                ),
                diags,
            );
            return None;
        };
        let canonical = found.canonicalize().unwrap_or_else(|_| found.clone());
        if let Some(u) = paths.iter().position(|p| p.as_ref() == Some(&canonical)) {
            return Some(u as u32);
        }
        let src = match std::fs::read(found) {
            Ok(bytes) => String::from_utf8_lossy(&bytes).into_owned(),
            Err(e) => {
                self.error(
                    unit,
                    span,
                    format!("L {name}: cannot read {}: {e}", found.display()),
                    diags,
                );
                return None;
            }
        };
        let u = self.add_unit(found.display().to_string(), src, diags);
        paths.push(Some(canonical));
        Some(u)
    }

    /// The unit of the main program.
    pub fn main(&self) -> &Unit {
        &self.units[0]
    }

    /// Number of blocks of all units.
    pub fn block_count(&self) -> usize {
        self.units.iter().map(|u| u.tree.blocks.len()).sum()
    }
}
